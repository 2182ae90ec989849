"""bench/crop_warp.py: bad input gets one line (the timing itself is a benchmark)."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import ROOT


def test_too_few_rounds_is_named_in_one_line() -> None:
    cmd = [sys.executable, "-m", "bench.crop_warp", "--rounds", "1", "--no-append"]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    assert r.returncode != 0
    assert r.stderr.strip() == "crop_warp: --rounds must be at least 2, got 1"
