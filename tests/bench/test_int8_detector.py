"""bench/int8_detector.py: it judges every window the tracker's search visits; bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from bench import int8_detector
from monopic.pose.search import search_windows
from monopic.pose.tracker import TrackerConfig
from tests.paths import ROOT


def test_the_judged_windows_are_the_whole_frame_and_the_whole_cascade() -> None:
    wins = int8_detector.all_windows(768, 432)
    cfg = TrackerConfig()
    levels = search_windows(768, 432, cfg.acquire_tiles, cfg.far_tiles, cfg.tile_overlap, None)
    assert len(wins) == 1 + sum(len(level) for level in levels)
    assert (wins[0].x, wins[0].y, wins[0].width, wins[0].height) == (0, 0, 768, 432)


def test_a_missing_candidate_is_one_line(tmp_path: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "bench.int8_detector", "judge", str(tmp_path / "x")],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 1
    assert r.stderr.strip() == f"int8_detector: {tmp_path / 'x'}: no such file"
