"""studies/intent/crossfit.py: folds keep families whole, the truth's reading is the walker's own
motion, the hold-back acts on the out-of-fold share only, and bad input is one line."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from monopic.camera import CameraModel
from monopic.features.record import Features, GroundFeatures
from monopic.predict.base import Mode
from monopic.predict.registry import make_predictor
from studies.ground_replay import MAX_GAP, ReplayFrame
from studies.intent import crossfit
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.crossfit"]

CAMERA = CameraModel.from_fov(768, 432, vertical_fov_deg=65.0, mount_height=1.2, pitch_deg=5.0)
DT = 1 / 15


def walker(lateral_speeds: list[float], robot_speed: float = 1.0, start_left: float = -3.0):
    """A walker 6 m ahead stepping left (toward the path) at the given speeds, one per
    frame, while the robot drives straight at `robot_speed`: its truth columns."""
    t, fwd, lat = [0.0], [6.0], [start_left]
    for v in lateral_speeds:
        t.append(t[-1] + DT)
        fwd.append(fwd[-1] - robot_speed * DT)
        lat.append(lat[-1] + v * DT)
    n = len(t)
    truth = SimpleNamespace(
        t=t, forward=fwd, lateral=lat, robot_speed=[robot_speed] * n, phi=[90.0] * n,
        head_yaw=[10.0] * n,
    )  # fmt: skip
    return SimpleNamespace(truth=truth, scenario=SimpleNamespace(robot_width=0.6, horizon=1.0))


def test_the_truths_reading_is_the_walkers_own_motion_without_the_robots() -> None:
    row = walker([1.2] * 10)
    v = crossfit.truth_values(row, 10)
    assert v["forward"] == pytest.approx(0.0, abs=1e-9)  # the robot's travel taken out
    assert v["left"] == pytest.approx(1.2) and v["speed"] == pytest.approx(1.2)
    assert v["acceleration"] == pytest.approx(0.0, abs=1e-9)
    assert v["heading_rate"] == pytest.approx(0.0, abs=1e-9)
    assert v["path_offset"] == pytest.approx(-3.0 + 1.2 * 10 * DT)
    assert v["path_distance"] == pytest.approx(3.0 - 1.2 * 10 * DT - 0.3)
    assert v["phi"] == 90.0 and v["phi_rate"] == pytest.approx(0.0) and v["head_yaw"] == 10.0


def test_a_slowing_walker_reads_a_negative_acceleration_and_a_late_reading_misses_it() -> None:
    speeds = [1.2] * 10 + [1.2 - 0.15 * i for i in range(1, 6)]  # -2.25 m/s^2 at the end
    row = walker(speeds)
    now = crossfit.truth_values(row, 15)
    assert now["acceleration"] == pytest.approx(-0.15 / DT, rel=1e-6)
    assert now["speed"] == pytest.approx(1.2 - 0.75)
    late = crossfit.truth_values(row, crossfit.delayed(row, 15, 0.4))
    assert crossfit.delayed(row, 15, 0.4) == 9  # 6 frames of 1/15 s
    assert late["acceleration"] == pytest.approx(0.0, abs=1e-9)
    assert crossfit.delayed(row, 15, 0.0) == 15


def test_an_early_reading_sees_the_slowing_before_it_happens() -> None:
    speeds = [1.2] * 10 + [1.2 - 0.15 * i for i in range(1, 6)]  # slows from frame 11
    row = walker(speeds)
    assert crossfit.shifted(row, 5, -0.4) == 11  # 6 frames of 1/15 s later
    assert crossfit.truth_values(row, crossfit.shifted(row, 5, -0.4))["acceleration"] < -0.5
    assert crossfit.truth_values(row, crossfit.shifted(row, 5, 0.0))["acceleration"] == (
        pytest.approx(0.0, abs=1e-9)
    )
    assert crossfit.shifted(row, 9, 0.4) == crossfit.delayed(row, 9, 0.4) == 3
    assert crossfit.shifted(row, 13, -1.0) == 15  # no truth beyond the run: its last frame
    row.truth.t[14] = None  # a frame without truth is skipped, not read
    assert crossfit.ahead(row, 13, 1 / 15) == 15


def test_the_truths_window_is_the_same_three_frames_on_every_frame() -> None:
    # Speeds alternate frame by frame: a window of 3 frames reads +-0.1 m/s over 0.2 s,
    # one of 4 would read nothing. Times accumulate in floats, as the simulator's do.
    row = walker([1.0 + 0.1 * (j % 2) for j in range(60)])
    for k in range(4, 61):
        assert abs(crossfit.truth_values(row, k)["acceleration"]) == pytest.approx(0.5, rel=1e-6)


def test_no_frame_before_means_no_motion() -> None:
    v = crossfit.truth_values(walker([1.0] * 3), 0)
    assert all(math.isnan(x) for x in v.values() if x is not None)


def test_every_family_lands_in_every_fold_and_the_deal_is_stable() -> None:
    rows = [SimpleNamespace(id=f"{fam}-{i}", family=fam) for fam in "abc" for i in range(7)]
    folds = crossfit.deal_folds(rows, 3)
    for fam in "abc":
        got = [f for r, f in zip(rows, folds, strict=True) if r.family == fam]
        assert sorted(set(got)) == [0, 1, 2] and max(got.count(k) for k in range(3)) == 3
    assert crossfit.deal_folds(list(reversed(rows)), 3) == list(reversed(folds))


def frame(k: int) -> ReplayFrame:
    ground = GroundFeatures((6.0, -3.0), (0.0, 1.4), CAMERA, path_offset=-3.0, path_distance=2.7)
    f = Features(0.0, (400.0, 200.0), (400.0, 300.0), 100.0, 0.0, 0.0, 0.0, ground)
    return ReplayFrame(k, f, make_predictor("constant-velocity", Mode.GROUND).predict(f, 1.0))


def test_the_hold_back_acts_only_where_the_out_of_fold_share_reaches_the_threshold() -> None:
    row = SimpleNamespace(scenario=SimpleNamespace(horizon=1.0))
    shares = {(0, 0): (0.4, "stop"), (0, 1): (0.1, "stop"), (0, 2): (0.5, "turn away")}
    rule = crossfit.hold_rule(row, 0, shares, 0.3)
    held = rule(frame(0))
    assert held is not None and held.ground == pytest.approx((6.0, -3.0))  # where it stands
    assert rule(frame(1)) is None  # below the threshold: constant velocity's point
    turned = rule(frame(2))
    assert turned is not None and turned.ground == pytest.approx((6.0, -3.0))  # no step in
    assert rule(frame(3)) is None  # a frame without a share (no ground point) is not held


def test_a_reading_names_its_source_its_delay_and_what_it_leaves_out() -> None:
    motion = crossfit.Reading.parse("truth-motion@0.2")
    assert motion.truth and motion.delay == pytest.approx(0.2)
    assert crossfit.Reading.parse("truth-motion@-0.6").delay == pytest.approx(-0.6)
    assert set(motion.without) == {"phi", "phi_rate", "head_yaw"}
    assert crossfit.Reading.parse("pipeline") == crossfit.Reading("pipeline", False, 0.0, ())
    recent = crossfit.Reading.parse("pipeline-recent")
    assert recent.recent and not recent.truth and not recent.without


def test_a_later_file_replaces_an_earlier_files_runs_of_the_same_family(monkeypatch) -> None:
    def run(id: str, family: str, labelled: bool = True) -> SimpleNamespace:
        return SimpleNamespace(id=id, family=family, truth=SimpleNamespace(intent=[
            "stop" if labelled else None]))  # fmt: skip

    files = {
        "judged.jsonl": [run("a1", "cross"), run("b1", "stop"), run("b2", "stop")],
        "redraw.jsonl": [run("b3", "stop"), run("c1", "look", labelled=False)],
    }
    monkeypatch.setattr(crossfit, "read_results", lambda path: files[path.name])
    got = crossfit.combined([Path("judged.jsonl"), Path("redraw.jsonl")])
    assert [r.id for r in got] == ["a1", "b3"]  # the redraw's stops; unlabelled runs dropped


def test_the_recent_velocity_is_the_measured_foot_points_own_over_the_last_window() -> None:
    from monopic.features.ground import GroundMotion
    from monopic.features.window import SlidingWindow

    n = 10
    row = SimpleNamespace(truth=SimpleNamespace(robot_speed=[0.0] * n))
    motion, window = GroundMotion(), SlidingWindow(crossfit.RECENT_WINDOW)
    got = []
    for k in range(n):  # 6 m ahead, stepping left at 1.2 m/s; the robot standing
        t = k * DT
        foot = CAMERA.project(np.array([6.0, -3.0 + 1.2 * t, 0.0]))
        f = Features(t, tuple(foot), tuple(foot), 100.0, 0.0, 0.0, 0.0, None)
        got.append(crossfit.recent_velocity(row, ReplayFrame(k, f, None), CAMERA, motion, window))
    assert math.isnan(got[2]["left_recent"])  # three points: not yet
    assert got[-1]["left_recent"] == pytest.approx(1.2, abs=1e-6)
    assert got[-1]["forward_recent"] == pytest.approx(0.0, abs=1e-6)


def test_the_column_reading_has_its_own_track_with_the_columns_noise() -> None:
    from monopic.features.ground import GroundMotion
    from monopic.frame import EgoState

    assert crossfit.Reading.parse("pipeline-column").column
    assert crossfit.COLUMN_TRACK.column_pixel_noise is not None
    frames = [*range(8), *range(20, 26)]  # a gap of 0.8 s: beyond MAX_GAP, a restart
    n = 26
    feet = [
        tuple(CAMERA.project(np.array([7.0 - 0.5 * k * DT, -3.0 + 1.3 * k * DT, 0.0])))
        if k in frames
        else None
        for k in range(n)
    ]
    cam = SimpleNamespace(width=768, height=432, vertical_fov_deg=65.0, mount_height=1.2,
                          pitch_deg=5.0)  # fmt: skip  # CAMERA's
    row = SimpleNamespace(
        scale="small",
        truth=SimpleNamespace(t=[k * DT for k in range(n)], robot_speed=[0.5] * n),
        pipelines={crossfit.MAIN: SimpleNamespace(
            found=[int(f is not None) for f in feet], foot=feet, height=[90.0] * n)},
        scenario=SimpleNamespace(robot_width=0.6, robot_length=0.8, horizon=1.5, camera=cam),
    )  # fmt: skip
    got = crossfit.column_motion(row)
    assert sorted(got) == frames
    alone, prev = GroundMotion(crossfit.COLUMN_TRACK), None
    for k in range(n):
        t = k * DT
        alone.observe_ego(t, EgoState(CAMERA, 0.5, 0.0))
        if feet[k] is None:
            continue
        if prev is not None and t - prev > MAX_GAP:
            alone.reset_track()
        prev = t
        want = alone.update(t, EgoState(CAMERA, 0.5, 0.0), feet[k], 90.0)
        assert want is not None
        g, _ = got[k]
        assert g.velocity == pytest.approx(want[1]) and g.position == pytest.approx(want[0])
    assert alone._track.starts == 2  # restarted after the gap
    assert got[25][0].velocity == pytest.approx((0.0, 1.3), abs=0.15)  # the walker's own


def run_tool(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*TOOL, *args], capture_output=True, text=True, cwd=ROOT)


def test_bad_input_is_one_line(tmp_path: Path) -> None:
    missing = run_tool(str(tmp_path / "none.jsonl"))
    assert missing.returncode == 1 and "no such results file" in missing.stderr
    assert len(missing.stderr.strip().splitlines()) == 1
    empty = tmp_path / "empty.jsonl"
    empty.write_text("")
    late = run_tool(str(empty), "--reading", "pipeline@0.2")
    assert late.returncode == 1 and "only the truth's reading can be made late" in late.stderr
    for bad in ("eyes", "truth@soon", "truth@inf", "pipeline@-0.2"):
        got = run_tool(str(empty), "--reading", bad)
        assert got.returncode == 1 and got.stderr.startswith("--reading: ")
        assert len(got.stderr.strip().splitlines()) == 1
    unknown = run_tool(str(empty), "--without", "nose")
    assert unknown.returncode == 1 and "no attribute 'nose'" in unknown.stderr
