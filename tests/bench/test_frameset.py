"""The frame-set recipes: distinct caches, and the int8 judge's set big enough (issue 21)."""

from __future__ import annotations

from bench.frameset import CALIBRATION, DEFAULT, LARGE, RECIPES, spec_digest

CLIP_FRAMES = 60  # tests/data/walk_clip.mp4


def frames(recipe) -> int:
    clip = CLIP_FRAMES if recipe.clip_frames is None else recipe.clip_frames
    return clip + len(recipe.cases) * len(recipe.distances) * recipe.frames


def test_each_recipe_has_its_own_cache() -> None:
    assert len({spec_digest(r) for r in RECIPES.values()}) == len(RECIPES)


def test_the_judged_set_has_at_least_500_frames_none_of_them_calibration_frames() -> None:
    # The judge leaves out the clip frames the calibration saw.
    assert frames(LARGE) - (CALIBRATION.clip_frames or 0) >= 500
    # Rendered calibration clips never share a seed with the judged ones.
    assert CALIBRATION.seed != LARGE.seed
    assert frames(DEFAULT) == 252  # the compare_reference set as before
