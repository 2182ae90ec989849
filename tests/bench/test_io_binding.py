"""bench/io_binding.py: both runs timed at each thread count; bad counts in one line."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import ROOT

SCRIPT = ["-m", "bench.io_binding"]


def test_a_short_run_times_both_ways_at_each_thread_count() -> None:
    r = subprocess.run(
        [sys.executable, *SCRIPT, "--rounds", "3", "--threads", "1", "2", "--no-append"],
        capture_output=True, text=True, timeout=300, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    rows = [line for line in r.stdout.splitlines() if line.startswith(("| 1 |", "| 2 |"))]
    assert len(rows) == 2 and all(line.count("|") == 6 for line in rows), r.stdout


def test_zero_rounds_is_refused_in_one_line() -> None:
    r = subprocess.run(
        [sys.executable, *SCRIPT, "--rounds", "0", "--no-append"],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 1
    assert (
        r.stderr.strip() == "io_binding: --rounds and --threads must be 1 or more, got 0 and [1, 2]"
    )
