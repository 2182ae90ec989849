"""studies/intent/stop_timing.py: the stop detector on hand-made tracks; the report; bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sim.analysis.realism import tracks_text
from studies.intent import stop_timing
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.stop_timing"]

STEP = 0.4


def walk(knots: list[tuple[float, float]], heading_deg: float = 30.0) -> np.ndarray:
    """Positions every STEP s of a walker whose speed is piecewise linear through the
    (time, speed) knots, along a straight line (exact: the knots lie on the fine grid)."""
    dt = 0.001
    t = np.arange(0.0, knots[-1][0] + dt / 2, dt)
    v = np.interp(t, [k[0] for k in knots], [k[1] for k in knots])
    s = np.concatenate([[0.0], np.cumsum((v[1:] + v[:-1]) / 2 * dt)])
    s = s[:: round(STEP / dt)]
    a = np.radians(heading_deg)
    return np.column_stack([2.0 + s * np.cos(a), -1.0 + s * np.sin(a)])


@pytest.mark.parametrize("slowing", [2.8, 4.0])
def test_a_linear_slowing_to_a_standstill_is_one_event_with_the_onsets_by_hand(
    slowing: float,
) -> None:
    # 1.4 m/s until 4 s, then down to 0 over `slowing` seconds, then standing 2 s. A step's
    # speed is its mean, exact at its middle on a linear stretch; the crossings of 0.15,
    # 0.9 x 1.4 and 0.7 x 1.4 m/s all lie between step middles on the ramp.
    a = 1.4 / slowing  # m/s2
    track = walk([(0.0, 1.4), (4.0, 1.4), (4.0 + slowing, 0.0), (6.0 + slowing, 0.0)])
    (event,) = stop_timing.find_stops(track, STEP)
    assert event.cruise == pytest.approx(1.4)
    assert event.t0 == pytest.approx(4.0 + (1.4 - 0.15) / a)
    assert event.onsets == pytest.approx(((1.26 - 0.15) / a, (0.98 - 0.15) / a))
    # The profile: at cruise until the slowing, 0.15 / 1.4 at standstill, 0 after.
    cruising = event.ratio[event.times < -event.onsets[0] - STEP]
    assert len(cruising) >= 2 and cruising == pytest.approx(1.0)
    assert np.interp(0.0, event.times, event.ratio) == pytest.approx(0.15 / 1.4)
    assert event.ratio[-1] == 0.0


def test_a_walker_who_never_stops_has_no_stop() -> None:
    assert stop_timing.find_stops(walk([(0.0, 1.4), (10.0, 1.4)]), STEP) == []
    # Slowing to a shuffle is not a stop either.
    assert (
        stop_timing.find_stops(walk([(0.0, 1.4), (4.0, 1.4), (5.0, 0.3), (9.0, 0.3)]), STEP) == []
    )


def test_a_stop_too_brief_is_no_stop_and_a_long_enough_one_is() -> None:
    slow = [(0.0, 1.4), (4.0, 1.4), (6.8, 0.0)]
    touch = walk([*slow, (7.2, 1.4), (10.0, 1.4)])  # at 0 for an instant: one step under
    assert stop_timing.find_stops(touch, STEP) == []
    pause = walk([*slow, (8.0, 0.0), (8.4, 1.4), (11.0, 1.4)])  # 1.2 s standing
    (event,) = stop_timing.find_stops(pause, STEP)
    assert event.t0 == pytest.approx(6.5)


def test_the_cruise_is_the_pace_before_a_gentle_slowing_not_the_slowing_itself() -> None:
    # 0.25 m/s2 from 1.4 m/s: every step is a little slower than the last. A cruise read
    # off the last few steps would be ~1.2 m/s and the onset late.
    track = walk([(0.0, 1.4), (4.0, 1.4), (9.6, 0.0), (12.0, 0.0)])
    (event,) = stop_timing.find_stops(track, STEP)
    assert event.cruise == pytest.approx(1.4)
    assert event.onsets[0] == pytest.approx((1.26 - 0.15) / 0.25, abs=1e-6)


def test_the_kerb_stop_walkers_with_a_run_up_stop_once_each() -> None:
    group = stop_timing.simulated_group("run-up", stop_timing.RUN_UP, 3, STEP)
    assert len(group.tracks) == 3 and "intent-runup-probe-7m.toml" in group.notes
    found = stop_timing.stop_set(group, stop_timing.Settings())
    assert len(found.events) == 3
    for e in found.events:
        assert 1.0 < e.cruise < 1.7 and 0.5 < e.onsets[0] < 3.0 and e.onsets[1] < e.onsets[0]


def test_the_report_and_the_plot_are_written(tmp_path: Path) -> None:
    stops = walk([(0.0, 1.4), (4.0, 1.4), (6.8, 0.0), (9.0, 0.0)])
    walker = walk([(0.0, 1.2), (8.0, 1.2)])
    real = tmp_path / "scene.txt"
    real.write_text(tracks_text([stops, walker]))
    out, plot = tmp_path / "doc" / "stop.md", tmp_path / "img" / "stop.png"
    argv = ["--real", str(real), "--walkers", "2", "--out", str(out), "--plot", str(plot)]
    assert stop_timing.main(argv) == 0
    text = out.read_text()
    assert "| scene (real) | 0.4 | 2 | 1 | 1.40 | 2.22 / 2.22 / 2.22 | 1.66 / 1.66 / 1.66 |" in text
    assert "--walkers 2" in text.splitlines()[2]
    assert "](../img/stop.png)" in text
    assert plot.read_bytes()[:4] == b"\x89PNG"


def run_tool(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*TOOL, *args], capture_output=True, text=True, timeout=120, cwd=ROOT)


def test_a_missing_track_file_is_one_line(tmp_path: Path) -> None:
    missing = tmp_path / "none.txt"
    r = run_tool("--real", str(missing), "--out", str(tmp_path / "o.md"))
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr.strip() == f"{missing}: no such track file"
    assert not (tmp_path / "o.md").exists()


def test_a_malformed_line_is_one_line_naming_the_file_and_value(tmp_path: Path) -> None:
    bad = tmp_path / "bad.txt"
    bad.write_text("0 1 1.0 2.0\n10 1 1.5 abc\n")
    r = run_tool("--real", str(bad), "--out", str(tmp_path / "o.md"))
    assert r.returncode == 1 and r.stdout == ""
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"{bad}: ") and "abc" in line
