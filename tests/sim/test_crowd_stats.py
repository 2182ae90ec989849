"""Crowd statistics (sim.analysis.crowd_stats): known answers on small rows, the reader,
the real scenes when present, every person's track as the world has it, and the command."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from sim.analysis.crowd_stats import (
    CROWD_STATISTICS,
    MIN_STEPS,
    crowd_summary,
    group_pairs,
    judge_crowd,
    nearest_distances,
    speed_spreads,
    walked_area,
)
from sim.analysis.realism import FRAME_STEP, STEP, read_rows, read_tracks, tracks_text
from sim.analysis.tracks import run_rows
from sim.runs.run_spec import RunSpec
from sim.scenario.motion import people_tracks
from sim.scenario.spec import PedestrianSpec, RobotSpec, Scenario
from sim.scenario.walkers import HumanWalker
from tests.paths import ROOT, SHARED_DATA

REAL = SHARED_DATA / "eth-ucy-calibration"
REAL_FILES = sorted(REAL.glob("*.txt"))
needs_real_tracks = pytest.mark.skipif(
    not REAL_FILES, reason=f"the ETH/UCY tracks are not at {REAL} (set MONOPIC_SHARED_DATA)"
)


def rows_of(*tracks: np.ndarray, first_frame: int = 0) -> np.ndarray:
    """Rows (frame, person, x, y) of tracks starting together, person ids from 1."""
    return np.concatenate([
        np.column_stack([first_frame + np.arange(len(t)) * FRAME_STEP, np.full(len(t), i + 1), t])
        for i, t in enumerate(tracks)
    ])  # fmt: skip


def line(start: tuple[float, float], velocity: tuple[float, float], steps: int) -> np.ndarray:
    """Positions every STEP seconds from `start` at constant `velocity` (m/s)."""
    k = np.arange(steps + 1)[:, None]
    return np.asarray(start) + k * STEP * np.asarray(velocity)


def test_two_people_a_metre_apart_are_a_metre_from_their_nearest() -> None:
    rows = rows_of(line((0.0, 0.0), (0.0, 0.0), 4), line((0.6, 0.8), (0.0, 0.0), 4))
    d = nearest_distances(rows)
    assert len(d) == 10  # both people in all five frames
    assert np.percentile(d, 50) == pytest.approx(1.0)
    s = crowd_summary("two", [rows])
    assert s.values["nn_p10"] == pytest.approx(1.0)
    assert s.values["nn_p50"] == pytest.approx(1.0)


def test_a_person_alone_in_a_frame_has_no_nearest_distance() -> None:
    rows = rows_of(line((0.0, 0.0), (1.0, 0.0), 3))
    assert len(nearest_distances(rows)) == 0
    assert math.isnan(crowd_summary("alone", [rows]).values["nn_p50"])


def test_a_pair_walking_together_is_a_group() -> None:
    a = line((0.0, 0.0), (1.2, 0.0), 10)
    b = line((0.0, 0.8), (1.3, 0.0), 10)  # 0.1 m/s faster, 0.8 m beside, 4 s
    pairs = group_pairs(rows_of(a, b))
    assert len(pairs) == 1
    assert (pairs[0].a, pairs[0].b) == (1, 2)
    assert len(pairs[0].frames) == 10
    assert pairs[0].speed_difference == pytest.approx(np.full(10, 0.1))
    s = crowd_summary("pair", [rows_of(a, b)])
    assert s.values["group_share"] == 1.0
    assert s.values["group_speed_difference"] == pytest.approx(0.1)


def test_walking_together_for_less_than_two_seconds_is_no_group() -> None:
    short = MIN_STEPS - 1
    a, b = line((0.0, 0.0), (1.2, 0.0), short), line((0.0, 1.0), (1.2, 0.0), short)
    assert group_pairs(rows_of(a, b)) == []
    a, b = line((0.0, 0.0), (1.2, 0.0), MIN_STEPS), line((0.0, 1.0), (1.2, 0.0), MIN_STEPS)
    assert len(group_pairs(rows_of(a, b))) == 1


def test_crossing_strangers_are_no_group() -> None:
    # They cross at (3, 3) at the same moment and are within 1.5 m for about 2 s, but walk
    # at right angles.
    a = line((0.0, 3.0), (1.2, 0.0), 10)
    b = line((3.0, 0.0), (0.0, 1.2), 10)
    rows = rows_of(a, b)
    assert np.min(nearest_distances(rows)) < 1.0
    assert group_pairs(rows) == []
    s = crowd_summary("crossing", [rows])
    assert s.values["group_share"] == 0.0
    assert math.isnan(s.values["group_speed_difference"])


def test_standing_together_is_no_walking_group() -> None:
    rows = rows_of(line((0.0, 0.0), (0.0, 0.0), 10), line((0.5, 0.0), (0.0, 0.0), 10))
    assert group_pairs(rows) == []
    assert math.isnan(crowd_summary("standing", [rows]).values["group_share"])


def test_density_of_people_over_the_ground_they_walk() -> None:
    # Three people walk along x, 3 m apart, over the 1 m squares 0..9 of their rows; the
    # region is 3 x 10 squares, each frame has all three.
    walkers = [line((0.5, 0.5 + 3 * k), (1.25, 0.0), 18) for k in range(3)]
    rows = rows_of(*walkers)
    assert walked_area(rows) == pytest.approx(30.0)
    s = crowd_summary("three", [rows])
    assert s.area == pytest.approx(30.0)
    assert s.values["density"] == pytest.approx(3 / 30)
    assert s.values["nn_p50"] == pytest.approx(3.0)


def test_a_fast_step_covers_every_square_it_crosses() -> None:
    rows = rows_of(line((0.5, 0.5), (5.0, 0.0), 4))  # 2 m steps from x 0.5 to 8.5
    assert walked_area(rows) == pytest.approx(9.0)


def test_a_gap_in_a_track_is_not_a_step() -> None:
    track = line((0.5, 0.5), (5.0, 0.0), 4)
    rows = rows_of(track)
    rows = rows[rows[:, 0] != 2 * FRAME_STEP]  # frame 20 unseen: no steps 10-20, 20-30
    assert walked_area(rows) == pytest.approx(6.0)  # squares 0-2 and 6-8: 3-5 never crossed


def test_runs_of_one_street_share_one_walked_region() -> None:
    first = rows_of(line((0.5, 0.5), (1.25, 0.0), 8), line((0.5, 2.5), (1.25, 0.0), 8))
    second = first.copy()
    s = crowd_summary("twice", [first, second])
    assert s.area == pytest.approx(walked_area(first))
    assert s.recordings == 2 and s.people == 4 and s.frames == 18
    assert s.values["density"] == pytest.approx(2 / walked_area(first))


def test_speed_spread_in_a_frame() -> None:
    rows = rows_of(*(line((0.0, 4.0 * k), (v, 0.0), 3) for k, v in enumerate((1.0, 1.5, 2.0))))
    assert speed_spreads(rows) == pytest.approx(np.full(3, 0.8))  # p90 - p10 of 1, 1.5, 2
    slow = rows_of(line((0.0, 0.0), (1.0, 0.0), 3), line((0.0, 4.0), (0.2, 0.0), 3))
    assert len(speed_spreads(slow)) == 0  # one walker a frame: no spread


def test_a_person_twice_in_a_frame_is_refused() -> None:
    rows = rows_of(line((0.0, 0.0), (1.0, 0.0), 2))
    with pytest.raises(ValueError, match="twice in one frame"):
        nearest_distances(np.concatenate([rows, rows[:1]]))


def test_the_verdicts_hold_a_crowd_to_the_real_span() -> None:
    pair = rows_of(line((0.0, 0.0), (1.2, 0.0), 10), line((0.0, 0.8), (1.3, 0.0), 10))
    wider = rows_of(line((0.0, 0.0), (1.2, 0.0), 10), line((0.0, 1.2), (1.25, 0.0), 10))
    real = [crowd_summary("a", [pair]), crowd_summary("b", [wider])]
    verdicts = judge_crowd(real, real[0])
    assert [v.stat for v in verdicts] == [k for k, _, _ in CROWD_STATISTICS]
    assert all(math.isfinite(v.value) and v.inside for v in verdicts)
    far = crowd_summary("far", [rows_of(line((0, 0), (1.2, 0), 10), line((0, 9), (1.2, 0), 10))])
    outside = {v.stat for v in judge_crowd(real, far) if not v.inside}
    assert {"nn_p10", "nn_p50", "group_share", "group_speed_difference"} <= outside


def test_read_rows_keeps_frames_and_ids(tmp_path: Path) -> None:
    path = tmp_path / "scene.txt"
    path.write_text("0\t7.0\t1.0\t2.0\n10\t7.0\t1.5\t2.0\n10.0\t3.0\t-1.0\t0.5\n")
    rows = read_rows(path)
    assert rows.tolist() == [[0, 7, 1.0, 2.0], [10, 7, 1.5, 2.0], [10, 3, -1.0, 0.5]]
    assert len(read_tracks(path).tracks) == 1  # person 3 has one position: no track


@pytest.mark.parametrize(
    "text, says",
    [("", "no rows"), ("0 1 2\n", "3 columns"), ("0 1 x 2\n", "not a track file"),
     ("0 1 nan 2\n", "row 1 is not finite")],
)  # fmt: skip
def test_read_rows_says_what_is_wrong_in_one_line(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(UserError, match=says) as err:
        read_rows(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


@needs_real_tracks
@pytest.mark.parametrize("path", REAL_FILES, ids=lambda p: p.stem)
def test_the_real_scenes_give_plausible_crowd_statistics(path: Path) -> None:
    s = crowd_summary(path.stem, [read_rows(path)])
    assert all(math.isfinite(v) for v in s.values.values()), s.values
    assert 0.5 < s.values["nn_p50"] < 5.0
    assert 0.0 < s.values["nn_p10"] < s.values["nn_p50"]
    assert 0.001 < s.values["density"] < 1.0  # people per m2 of a street seen from above
    assert 0.0 < s.values["group_share"] < 1.0
    assert 0.0 < s.values["group_speed_difference"] < 0.5  # the criterion's bound
    assert 0.0 < s.values["speed_spread"] < 2.0


# -- simulated people -------------------------------------------------------------------

WANDERER = PedestrianSpec(x=8.0, y=3.0, heading_deg=180.0, speed=1.3, behaviour=HumanWalker())


def two_people(seed: int = 5) -> Scenario:
    return Scenario(
        name="crowd", pedestrian=WANDERER, robot=RobotSpec(speed=0.0), duration=2.0, seed=seed,
        bystanders=(PedestrianSpec(x=8.0, y=-3.0, heading_deg=180.0, speed=1.3,
                                   behaviour=HumanWalker(), name="other"),),
    )  # fmt: skip


def test_people_tracks_are_where_the_world_has_everyone() -> None:
    """Every person, the bystander's own wander included, as the world's truth has them."""
    from sim.world.world import World

    scenario = two_people()
    tracks = people_tracks(scenario, scenario.seed, scenario.duration)
    assert list(tracks) == ["ped", "other"]
    with World(scenario, render=False) as world:
        step = world.reset()
        for _ in range(5):
            for person in step.truth.people:
                want = tracks[person.name].state(step.time).position
                assert person.position_world == pytest.approx(want, abs=1e-9)
            step = world.step()


def test_run_rows_hold_every_person_of_the_run() -> None:
    rows = run_rows(RunSpec(id="crowd/0", scenario=two_people()))
    frames = np.arange(6) * FRAME_STEP  # 0 to 2 s every 0.4 s
    assert rows[:, 0].tolist() == [*frames, *frames]
    assert rows[:, 1].tolist() == [1] * 6 + [2] * 6
    assert rows[0, 2:] == pytest.approx([8.0, 3.0], abs=0.05)  # a human walker's wander
    assert rows[6, 2:] == pytest.approx([8.0, -3.0], abs=0.05)


# -- the command ------------------------------------------------------------------------


def test_realism_with_crowds_writes_the_crowd_section(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    spec = tmp_path / "small-crowd.toml"
    families = ROOT / "scenarios" / "families" / "small"
    people = ROOT / "scenarios" / "people"
    spec.write_text(
        'name = "small-crowd"\ndescription = "two runs with bystanders"\n\n[[include]]\n'
        f'files = ["{families / "cpna25.toml"}"]\nsampling = "random"\nruns = 2\nseed = 3\n'
        f'[include.parameters]\npeople = ["{people / "pavement_three.toml"}"]\n'
    )
    real = tmp_path / "pair.txt"  # a pair walking together and a stranger across
    walk = [line((0.0, 0.0), (1.2, 0.0), 12), line((0.0, 0.8), (1.25, 0.0), 12),
            line((6.0, -4.0), (0.0, 1.1), 12)]  # fmt: skip
    real.write_text(tracks_text(walk))
    out = tmp_path / "report"
    assert main(["realism", "--crowds", str(spec), "--real", str(real), "--out", str(out)]) == 0
    text = (out / "report.md").read_text()
    assert "## Crowds" in text
    assert "| pair | 3 | 13 |" in text  # the real scene's density row: people, frames
    assert "### `small-crowd` against the real scenes' span" in text
    assert "| small-crowd (simulated) | 8 |" in text  # two runs of the scripted person and 3
    assert (out / "crowds.png").stat().st_size > 0
    said = capsys.readouterr().out
    assert "pair: density" in said and "small-crowd (crowd): density" in said


def test_realism_needs_a_spec_or_crowds(tmp_path: Path) -> None:
    real = tmp_path / "pair.txt"
    real.write_text(tracks_text([line((0.0, 0.0), (1.2, 0.0), 3)]))
    assert main(["realism", "--real", str(real), "--out", str(tmp_path / "r")]) == 2
