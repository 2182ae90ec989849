"""tools.night_calibration: the night's render keeps to its photometry where it can, the
light budget never asks the renderer for more lights than it has, a dark lamp is dark, and
the exact image the budget is measured against is the renderer's own within rounding."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from sim.world.render import SceneRenderer
from tools import night_calibration as nc

LAMP = nc.SOURCES[2]


def test_the_lamp_on_the_board_renders_what_the_photometry_predicts() -> None:
    # At 10 m the lamp puts about 22 lux on the board: 57 of 255 steps, far from both
    # white and the few steps where rounding dominates.
    row = nc.measure_board(10.0, LAMP)
    assert 15.0 < row.predicted_lux < 30.0
    assert row.clipped == 0.0
    assert abs(row.rendered_lux - row.predicted_lux) < 0.08 * row.predicted_lux
    assert row.error < 4.0  # mean per-pixel difference, 8-bit steps
    assert row.camera.exposure_ms <= nc.IMX273.max_exposure_ms


def test_a_lamp_that_is_off_gives_no_light() -> None:
    dark = nc.Source("street lamp, off", lamp=True, lamp_on=False)
    values = []
    for source in (dark, nc.SOURCES[0]):  # the dark lamp, then no lamp at all
        scene, board = nc.board_scene(10.0, source)
        with SceneRenderer(scene) as renderer:
            image = renderer.render()
            inside = nc.interior(renderer.mask(scene.geoms_of(board)))
        values.append(image[inside])
    assert np.array_equal(values[0], values[1])
    assert nc.predicted_lux(scene, board.x, dark).max() == nc.NIGHT_AMBIENT_LUX


def test_the_budget_never_lights_more_than_the_renderer_has() -> None:
    scene, street, _ = nc.ncap_scene()
    for before in (80.0, *nc.CAR_BEFORE_IMPACT, 0.0):
        scene.set_camera_pose(nc.IMPACT_X - before - nc.FRONT, 0.0, 0.0)
        assert nc.active_lights(scene.model) <= nc.MAX_LIGHTS
        seen = int(np.sum(street.score(nc.Moment(0.0, scene.robot_pose)) > 0))
        assert len(street.shining) == min(seen, street.slots)  # every slot used when needed


def test_the_sum_of_passes_is_one_render_within_rounding() -> None:
    scene, _, _ = nc.ncap_scene()
    scene.set_camera_pose(nc.IMPACT_X - 20.0 - nc.FRONT, 0.0, 0.0)
    with SceneRenderer(scene) as renderer:
        one = renderer.render().astype(float)
        summed = nc.exact_render(scene, renderer, only_active=True, per_pass=3)
        after = renderer.render()
    assert np.abs(one - np.minimum(summed, 255.0)).mean() < 0.5
    assert np.array_equal(after, one)  # the lights are as the budget left them


@pytest.mark.slow
def test_the_table_is_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "argv", ["night_calibration", "--out", str(tmp_path)])
    nc.main()
    text = (tmp_path / "calibration.md").read_text()
    assert text.startswith("# The night's render")
    assert nc.COMMAND in text
    assert text.count("| low beam |") == 2 * len(nc.DISTANCES)
    assert list(tmp_path.iterdir()) == [tmp_path / "calibration.md"]
