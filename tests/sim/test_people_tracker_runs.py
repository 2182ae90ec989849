"""Sweeps whose pipeline follows everyone in view: the spec's `tracker`, what a run's line
holds (every track, whom each predictor warned for, every person's truth) and how its
results are kept apart from the one-pedestrian tracker's."""

from __future__ import annotations

from pathlib import Path

import pytest

from monopic.cli.main import main
from sim.runs.code_version import code_version
from sim.runs.run_spec import EVERYONE, ONE
from sim.runs.runner import run
from sim.runs.sweep import PEOPLE_TAG, TREE_TAG, expand_spec, load_spec, sweep_code

ROOT = Path(__file__).parents[2]
CHILD = ROOT / "scenarios" / "families" / "small" / "people" / "child_beside_adult.toml"


GROUND_TREE = ROOT / "monopic" / "tree" / "ground_tree.json"


def spec_file(folder: Path, tracker_line: str) -> Path:
    path = folder / "spec.toml"
    path.write_text(
        f'name = "everyone"\n{tracker_line}\nablation = false\n'
        f'intent_tree = "{GROUND_TREE}"\n[[include]]\n'
        f'files = ["{CHILD}"]\nsampling = "random"\nruns = 1\nseed = 5\n'
    )
    return path


def test_the_spec_says_whom_the_pipeline_follows_and_its_results_are_other_code(
    tmp_path: Path,
) -> None:
    default = load_spec(spec_file(tmp_path, ""))
    assert default.tracker == ONE
    assert sweep_code(default).partition(TREE_TAG)[0] == code_version()
    spec = load_spec(spec_file(tmp_path, 'tracker = "everyone"'))
    assert spec.tracker == EVERYONE  # never resumed as "one"'s results:
    assert sweep_code(spec).partition(TREE_TAG)[0] == code_version() + PEOPLE_TAG
    assert {r.tracker for r in expand_spec(spec)} == {EVERYONE}


def test_an_unknown_tracker_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = spec_file(tmp_path, 'tracker = "all"')
    assert main(["sweep", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(path) in err and "tracker" in err and "everyone" in err, err


@pytest.mark.slow
def test_a_run_with_the_people_tracker_says_whom_each_predictor_warned_for(
    tmp_path: Path,
) -> None:
    (spec,) = expand_spec(load_spec(spec_file(tmp_path, 'tracker = "everyone"')))
    row = run(spec)
    assert row.tracker == EVERYONE and set(row.tracks) == {"main"}
    tracks = row.tracks["main"]
    assert len(tracks.boxes) == row.frames
    assert [p.name for p in row.people] == ["child", "adult"]
    assert max(len(frame) for frame in tracks.boxes) >= 2  # both people were followed
    decisions = row.pipelines["main"].decisions
    assert set(tracks.warned_for) == set(decisions)
    assert "intent-tree/ground" in decisions  # the intent tree runs per person like the rest
    for key, whom in tracks.warned_for.items():
        assert len(whom) == row.frames
        for k, (pid, warn) in enumerate(zip(whom, decisions[key].warn, strict=True)):
            # a warning is the robot's when it is some tracked person's, and only then
            assert (pid is not None) == bool(warn), (key, k)
            if pid is not None:
                assert pid in {box[0] for box in tracks.boxes[k]}
    assert any(any(w is not None for w in whom) for whom in tracks.warned_for.values())
    back = type(row).from_json(row.to_json())
    assert back.tracks == row.tracks and back.tracker == EVERYONE
