"""bench/cold_paths.py: every step timed both ways in a short run; bad counts in one line."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import ROOT

SCRIPT = ["-m", "bench.cold_paths"]


def test_a_short_run_times_every_step_after_a_model_run_and_warm() -> None:
    r = subprocess.run(
        [sys.executable, *SCRIPT, "--rounds", "3", "--no-append"],
        capture_output=True, text=True, timeout=300, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    rows = [line for line in r.stdout.splitlines() if line.startswith("| ") and "x |" in line]
    assert len(rows) == 7 and all(line.count("|") == 5 for line in rows), r.stdout


def test_zero_rounds_is_refused_in_one_line() -> None:
    r = subprocess.run(
        [sys.executable, *SCRIPT, "--rounds", "0", "--no-append"],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 1
    assert r.stderr.strip() == "cold_paths: --rounds and --threads must be 1 or more, got 0 and 1"
