"""studies/intent/paired_power.py: the family size the per-family recall test needs; bad input."""

from __future__ import annotations

import subprocess
import sys

import pytest

from sim.analysis.metrics import paired_difference
from studies.intent import paired_power
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.paired_power"]


def test_no_run_lost_in_96_still_fails_the_minus_3_bound() -> None:
    # The judged draws' CPNA-25 family: 96 collision runs, constant velocity warning 80-95 %
    # in time. A predictor that loses none and gains none still cannot pass.
    for share in (0.8, 0.85, 0.9, 0.95):
        assert paired_power.lower_bound(96, share, 0) < -3


def test_the_bound_is_newcombes_on_the_cells_by_hand() -> None:
    # 128 runs, 115 warned by constant velocity (0.9 of 128 rounds to 115), 1 of them lost.
    _, low, _ = paired_difference(114, 0, 1, 13)
    assert paired_power.lower_bound(128, 0.9, 1) == pytest.approx(100 * low)


@pytest.mark.parametrize("share", [0.8, 0.9])
@pytest.mark.parametrize("lost", [0, 1, 2])
def test_runs_needed_is_the_first_size_that_passes(share: float, lost: int) -> None:
    n = paired_power.runs_needed(share, lost, -3.0)
    assert n is not None
    assert paired_power.lower_bound(n, share, lost) >= -3.0
    assert all(paired_power.lower_bound(m, share, lost) < -3.0 for m in range(max(lost, 1), n))


def test_each_lost_run_asks_for_more_runs() -> None:
    needs = [paired_power.runs_needed(0.85, lost, -3.0) for lost in (0, 1, 2)]
    assert needs[0] < needs[1] < needs[2]  # type: ignore[operator]


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--share", "1.5"], "--share: 1.5"),
        (["--lost", "-1"], "--lost: -1"),
        (["--runs", "2", "--lost", "3"], "--runs: 2"),
        (["--bound", "3"], "--bound: 3.0"),
    ],
)
def test_bad_input_is_one_line_naming_the_option(args: list[str], named: str) -> None:
    out = subprocess.run([*TOOL, *args], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 2
    assert named in out.stderr and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1
