"""bench/spin.py refuses a thread count with no pool to spin, in one line."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import ROOT


def test_one_thread_is_refused_before_any_work() -> None:
    r = subprocess.run(
        [sys.executable, "-m", "bench.spin", "--threads", "1", "--no-append"],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 1
    expected = "spin.py: --threads must be 2 or more (one thread has no pool), got 1"
    assert r.stderr.strip() == expected
