"""The replay-loop study (studies/crowd/replay_loop.py): its scoring on hand-made frames with
known answers (an exact track scores 0, constant velocity on a straight walk scores 0,
tracks match people by box overlap one to one), its report's figures, and a short real run
of the zara family through the people pipeline (skipped without the shared data)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from monopic.predict.base import Mode
from sim.geometry.frames import Pose2D
from sim.scenario.files import load
from studies.crowd.replay_loop import (
    CV_LOOKBACK,
    FAMILIES,
    HORIZON,
    RESULTS,
    Scorer,
    constant_velocity,
    main,
    match_boxes,
    percentiles,
    read_results,
    report,
    robot_to_world,
)
from tests.paths import needs_eth_ucy

RULES = f"rules/{Mode.GROUND}"


def test_boxes_match_one_to_one_by_overlap() -> None:
    people = [(0.0, 0.0, 10.0, 20.0), (100.0, 0.0, 110.0, 20.0)]
    # Listed in the other order, and one box far from anyone.
    tracks = [(101.0, 1.0, 111.0, 21.0), (1.0, 0.0, 11.0, 20.0), (50.0, 0.0, 60.0, 20.0)]
    assert sorted(match_boxes(tracks, people)) == [(0, 1), (1, 0)]
    # IoU of (0, 0, 10, 20) with (6, 0, 16, 20): 80 / 320 = 0.25 < 0.3: no match.
    assert match_boxes([(6.0, 0.0, 16.0, 20.0)], people[:1]) == []
    assert match_boxes([(5.0, 0.0, 15.0, 20.0)], people[:1]) == [(0, 0)]  # 100/300
    assert match_boxes([], people) == [] and match_boxes(tracks, []) == []


def test_matching_maximises_the_total_overlap_not_the_first_best() -> None:
    # Track 0 overlaps person 0 best (IoU 0.82, person 1: 0.54), but track 1 is exactly
    # person 0 (1.0, person 1: 0.43): taking the tracks in turn would give 0.82 + 0.43,
    # the assignment gives 1.0 + 0.54.
    people = [(0.0, 0.0, 10.0, 20.0), (4.0, 0.0, 14.0, 20.0)]
    tracks = [(1.0, 0.0, 11.0, 20.0), (0.0, 0.0, 10.0, 20.0)]
    assert sorted(match_boxes(tracks, people)) == [(0, 1), (1, 0)]


def test_robot_frame_points_reach_the_world_by_the_robots_pose() -> None:
    robot = Pose2D(10.0, 2.0, math.pi / 2)  # facing north
    assert np.allclose(robot_to_world((1.0, 0.0), robot), [10.0, 3.0])
    assert np.allclose(robot_to_world((0.0, 1.0), robot), [9.0, 2.0])  # left is west


def test_constant_velocity_on_a_straight_walk_is_exact() -> None:
    walk = lambda t: np.array([3.0 - 1.2 * t, 1.0 + 0.5 * t])  # noqa: E731
    assert np.allclose(constant_velocity(walk(2.0), walk(1.6), 0.4, 1.0), walk(3.0))
    assert np.allclose(constant_velocity(walk(2.0), walk(2.0 - 0.4), 0.4, 0.0), walk(2.0))


def test_percentiles() -> None:
    assert percentiles(range(11)) == (5.0, 9.0)
    assert all(math.isnan(v) for v in percentiles([]))


# -- the scorer on hand-made frames -------------------------------------------------------

FPS = 15.0
LOOKBACK = round(CV_LOOKBACK * FPS)
BOX = (100.0, 50.0, 140.0, 150.0)


def walker(t: float) -> np.ndarray:
    """A person walking straight across at 1.3 m/s."""
    return np.array([12.0, -3.0 + 1.3 * t])


def robot(t: float) -> Pose2D:
    return Pose2D(2.0 * t, 0.0, 0.1)  # driving at 2 m/s, heading a little left of east


def to_robot(point: np.ndarray, pose: Pose2D) -> tuple[float, float]:
    local = pose.to_local(np.array([point[0], point[1], 0.0]))
    return float(local[0]), float(local[1])


def loop_frame(k: int, offset: float, fresh: bool = True, box=BOX) -> SimpleNamespace:
    """Frame k: the walker in view; one track on them whose ground prediction is the true
    position 1 s later moved `offset` m forward in the robot's frame."""
    t = k / FPS
    pose = robot(t)
    future = walker(t + HORIZON)
    predicted = to_robot(future, pose)
    decision = SimpleNamespace(
        predictor=RULES, mode=Mode.GROUND,
        prediction=SimpleNamespace(ground=(predicted[0] + offset, predicted[1])),
    )  # fmt: skip
    track = SimpleNamespace(
        person_id=7, box=box, fresh=fresh, decisions=(decision,),
        features=SimpleNamespace(ground=SimpleNamespace(position=to_robot(walker(t), pose))),
    )  # fmt: skip
    person = SimpleNamespace(
        name="p1", position_world=walker(t), future_position_world=future, in_frame=True,
        occluded=False, box=BOX, visibility=SimpleNamespace(visible=0.9),
    )  # fmt: skip
    truth = SimpleNamespace(time=t, people=(person,), robot=SimpleNamespace(pose=pose))
    return SimpleNamespace(truth=truth, results={"people": SimpleNamespace(people=(track,))})


@pytest.mark.parametrize("offset", [0.0, 0.8])
def test_an_exact_track_scores_zero_and_an_offset_one_its_offset(offset: float) -> None:
    scorer = Scorer("people", LOOKBACK)
    frames = 20
    for k in range(frames):
        scorer.frame(loop_frame(k, offset))  # type: ignore[arg-type]
    # Scored once the lookback has a true position behind it.
    assert len(scorer.scored) == frames - LOOKBACK
    for s in scorer.scored:
        assert s.errors[RULES] == pytest.approx(offset, abs=1e-9)
        assert s.cv_truth == pytest.approx(0.0, abs=1e-9)  # a straight walk
        assert s.located == pytest.approx(0.0, abs=1e-9)
        assert s.person == "p1" and s.track == 7
    assert scorer.in_view == {"p1": frames} and scorer.matched == {"p1": frames}


def test_carried_decisions_and_unmatched_tracks_are_not_scored() -> None:
    scorer = Scorer("people", LOOKBACK)
    for k in range(10):
        scorer.frame(loop_frame(k, 0.0, fresh=False))  # type: ignore[arg-type]
    far = (300.0, 50.0, 340.0, 150.0)
    for k in range(10, 20):
        scorer.frame(loop_frame(k, 0.0, box=far))  # type: ignore[arg-type]
    assert scorer.scored == []
    # Carried decisions still mean a matched track (coverage), a track elsewhere does not.
    assert scorer.in_view == {"p1": 20} and scorer.matched == {"p1": 10}


# -- results and report --------------------------------------------------------------------


def result_line(key: str, family: str, speed: float, errors: list[float]) -> dict:
    return {
        "key": key, "family": family, "speed": speed, "frames": None, "frames_run": 10,
        "people": 2, "wall_s": 1.0, "in_view": {"p1": 8, "p2": 2}, "matched": {"p1": 6},
        "scored": [
            {"person": "p1", "time": 0.1 * k, "track": 1, "errors": {RULES: e},
             "cv_truth": 0.1, "located": 0.2}
            for k, e in enumerate(errors)
        ],
    }  # fmt: skip


def test_the_report_pools_runs_per_scene_family_and_person() -> None:
    lines = [
        result_line("zara/1/all", "zara", 1.0, [0.0, 1.0, 2.0]),
        result_line("zara/2/all", "zara", 2.0, [3.0]),
    ]
    text = report(lines, "the command")
    rows = {r.split(" | ")[0].lstrip("| "): r for r in text.splitlines() if r.startswith("| ")}
    # 3 scored; p50 of (0, 1, 2) = 1, p90 = 1.8; constant-velocity/ground never scored.
    assert rows["zara, robot 1 m/s"].startswith("| zara, robot 1 m/s | 3 | 1.00 / 1.80 | - |")
    assert "0.60 (6/10)" in rows["zara, robot 1 m/s"]
    assert rows["zara, all runs"].startswith("| zara, all runs | 4 | 1.50 / 2.70 |")
    assert "0.60 (12/20)" in rows["zara, all runs"]
    assert rows["zara, p1"].startswith("| zara, p1 | 4 |") and "0.75 (12/16)" in rows["zara, p1"]
    assert "0.00 (0/4)" in rows["zara, p2"]
    assert "the command" in text


def test_a_line_cut_short_by_a_crash_is_run_again(tmp_path: Path) -> None:
    path = tmp_path / RESULTS
    whole = result_line("hotel/2/all", "hotel", 2.0, [0.5])
    path.write_text(json.dumps(whole) + "\n" + json.dumps(whole)[:40])
    assert [line["key"] for line in read_results(path)] == ["hotel/2/all"]


def test_bad_options_are_one_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    with pytest.raises(SystemExit) as err:
        main(["--out", str(tmp_path), "--speeds", "9"])
    assert err.value.code == 2
    assert "--speeds 9: must lie in [0, 5] m/s" in capsys.readouterr().err


# -- a short real run ----------------------------------------------------------------------


@needs_eth_ucy
@pytest.mark.slow
def test_a_short_zara_run_scores_the_tracked_people_and_resumes(tmp_path: Path) -> None:
    argv = ["--out", str(tmp_path), "--families", "zara", "--speeds", "2", "--frames", "14"]
    main(argv)
    (line,) = read_results(tmp_path / RESULTS)
    assert line["key"] == "zara/2/14" and line["frames_run"] == 14 and line["people"] == 18
    assert sum(line["in_view"].values()) > 0 and sum(line["matched"].values()) > 0
    scored = line["scored"]
    assert scored, "some tracked person should have a scored 1 s prediction in 14 frames"
    names = {p.name for p in load(FAMILIES["zara"]).base.people}
    for s in scored:
        assert s["person"] in names
        assert all(math.isfinite(v) and v >= 0 for v in s["errors"].values())
        assert math.isfinite(s["cv_truth"]) and s["cv_truth"] < 1.0  # real walks, 1 s
    main(argv)  # done: the rerun appends nothing
    assert len(read_results(tmp_path / RESULTS)) == 1
    assert "| zara, robot 2 m/s |" in (tmp_path / "replay_loop.md").read_text()
