"""studies/intent/foot_noise.py: the spreads it reports are the noise put into the foot points,
split into column and row, and across and along the line of sight; bad input is one line."""

from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from studies.ground_replay import camera
from studies.intent import foot_noise
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.foot_noise"]

MAIN = foot_noise.MAIN


def noisy_run(column_px: float, row_px: float, seed: int, n: int = 90) -> SimpleNamespace:
    """A walker crossing 7 m ahead of a small robot driving at 1 m/s, its foot points the
    truth projected plus Gaussian pixel noise of the given spreads."""
    cam_spec = SimpleNamespace(width=768, height=432, vertical_fov_deg=65.0, mount_height=0.6,
                               pitch_deg=5.0)  # fmt: skip
    row = SimpleNamespace(scale="small", scenario=SimpleNamespace(camera=cam_spec))
    cam = camera(row)
    rng = np.random.default_rng(seed)
    t = [k / 15 for k in range(n)]
    fwd = [10.0 - 1.0 * s for s in t]  # the robot closes in
    lat = [-3.0 + 1.3 * s for s in t]
    feet = []
    for x, y in zip(fwd, lat, strict=True):
        p = cam.project(np.array([[x, y, 0.0]]))[0]
        feet.append([p[0] + rng.normal(0, column_px), p[1] + rng.normal(0, row_px)])
    row.truth = SimpleNamespace(t=t, forward=fwd, lateral=lat, robot_speed=[1.0] * n)
    row.pipelines = {MAIN: SimpleNamespace(found=[1] * n, foot=feet, height=[80.0] * n)}
    return row


def test_the_spreads_are_the_noise_put_in() -> None:
    pixels, velocities = [], []
    for seed in range(6):
        p, v = foot_noise.run_samples(noisy_run(0.5, 2.0, seed))
        pixels += p
        velocities += v
    column = foot_noise.robust_spread(np.array([s.column for s in pixels]))
    row = foot_noise.robust_spread(np.array([s.row for s in pixels]))
    assert column == pytest.approx(0.5, rel=0.15) and row == pytest.approx(2.0, rel=0.15)
    across = foot_noise.robust_spread(np.array([s.across for s in velocities]))
    along = foot_noise.robust_spread(np.array([s.along for s in velocities]))
    assert along > 5 * across  # the row's depth is the noisy direction


def test_noiseless_foot_points_give_no_spread() -> None:
    pixels, velocities = foot_noise.run_samples(noisy_run(0.0, 0.0, 0))
    assert max(abs(s.column) + abs(s.row) for s in pixels) < 1e-6
    assert max(abs(s.across) + abs(s.along) for s in velocities) < 1e-6


def test_bad_input_is_one_line(tmp_path) -> None:
    got = subprocess.run([*TOOL, str(tmp_path / "none.jsonl")],
                         capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert got.returncode == 1 and "no such results file" in got.stderr
    assert len(got.stderr.strip().splitlines()) == 1
