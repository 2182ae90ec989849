"""studies/intent/ceiling.py: the oracle rules read the truth's label; bad input is one line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from monopic.camera import CameraModel
from monopic.features.record import Features, GroundFeatures
from monopic.predict.base import Mode
from monopic.predict.registry import make_predictor
from monopic.tree.intent import START_CROSSING, IntentRules
from studies.ground_replay import ReplayFrame
from studies.intent import ceiling
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.ceiling"]

CAMERA = CameraModel.from_fov(768, 432, vertical_fov_deg=65.0, mount_height=1.2, pitch_deg=5.0)
RULES = IntentRules(hold_back_support=0.5, warn_support=0.5, min_rows=1, start_speed=1.0)


def frame(k: int, position: tuple[float, float], velocity: tuple[float, float]) -> ReplayFrame:
    """A pedestrian 6 m ahead, 3 m to the right, walking toward the robot's path."""
    ground = GroundFeatures(position, velocity, CAMERA, path_offset=position[1])
    f = Features(0.0, (400.0, 200.0), (400.0, 300.0), 100.0, 0.0, 0.0, 0.0, ground)
    return ReplayFrame(k, f, make_predictor("constant-velocity", Mode.GROUND).predict(f, 1.0))


def run(*labels: str | None, future: tuple[float, float] = (6.0, 0.0)) -> SimpleNamespace:
    truth = SimpleNamespace(intent=list(labels), future=[future] * len(labels))
    return SimpleNamespace(scenario=SimpleNamespace(horizon=1.0), truth=truth)


def test_the_oracle_holds_back_on_a_true_stop_and_keeps_constant_velocity_otherwise() -> None:
    row = run("stop", "keep going", None)
    rule = ceiling.oracle_rule(row, RULES, hold=True, earlier=True)
    held = rule(frame(0, (6.0, -3.0), (0.0, 1.4)))
    assert held is not None and held.ground == pytest.approx((6.0, -3.0))  # where it stands
    kept = rule(frame(1, (6.0, -3.0), (0.0, 1.4)))
    assert kept is not None and kept.ground == pytest.approx((6.0, -1.6))  # constant velocity
    assert rule(frame(2, (6.0, -3.0), (0.0, 1.4))) is None  # no label: nothing to say


def test_the_oracle_moves_a_true_start_toward_the_path_only_when_told_to() -> None:
    row = run(START_CROSSING)
    standing = frame(0, (6.0, -3.0), (0.0, 0.0))
    earlier = ceiling.oracle_rule(row, RULES, hold=True, earlier=True)(standing)
    assert earlier is not None and earlier.ground == pytest.approx((6.0, -2.0))  # 1 m/s x 1 s
    plain = ceiling.oracle_rule(row, RULES, hold=True, earlier=False)(standing)
    assert plain is not None and plain.ground == pytest.approx((6.0, -3.0))


def test_the_perfect_point_is_the_true_future() -> None:
    row = run("keep going", future=(5.5, -0.4))
    p = ceiling.perfect_point(row)(frame(0, (6.0, -3.0), (0.0, 1.4)))
    assert p is not None and p.ground == pytest.approx((5.5, -0.4)) and p.case is not None


def test_the_true_velocity_point_extrapolates_the_truths_own_motion_from_the_foot_point() -> None:
    # The truth: 0.1 m nearer and 0.08 m further left over a 0.1 s frame while the robot
    # drives at 1 m/s: the walker's own velocity is (0, 0.8) m/s in the robot's axes.
    truth = SimpleNamespace(
        t=[0.0, 0.1], forward=[6.1, 6.0], lateral=[-3.08, -3.0], robot_speed=[1.0, 1.0]
    )
    row = SimpleNamespace(scenario=SimpleNamespace(horizon=1.0), truth=truth)
    rule = ceiling.true_velocity_point(row)
    assert rule(frame(0, (6.0, -2.9), (0.0, 1.4))) is None  # no frame before: no velocity
    p = rule(frame(1, (6.0, -2.9), (0.0, 1.4)))  # the track says 1.4 m/s: not used
    assert p is not None and p.ground == pytest.approx((6.0, -2.1))  # from the foot point


def test_a_missing_results_file_is_one_line(tmp_path: Path) -> None:
    r = subprocess.run(
        [*TOOL, str(tmp_path / "none.jsonl")],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 1 and r.stdout == ""
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"{tmp_path / 'none.jsonl'}: no such results file")


def test_an_empty_results_file_is_one_line(tmp_path: Path) -> None:
    results = tmp_path / "r.jsonl"
    results.write_text("")
    r = subprocess.run([*TOOL, str(results)], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr.strip() == f"{results}: no result lines"
