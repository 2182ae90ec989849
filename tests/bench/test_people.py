"""bench/people.py's choice of frames, its composition and its figures, on made-up inputs
(nothing is timed here), and the goal it feeds."""

from __future__ import annotations

import numpy as np
import pytest

from bench.compare_reference import OURS, PEOPLE, REF, Collected, Run, people_table
from bench.goals import PEOPLE_FPS_GOAL, people_fps
from bench.people import (
    BUDGET,
    FrameRun,
    goal_of,
    half_pairs,
    runs_with,
    segments,
    side_by_side,
    summarise,
)


def test_runs_are_the_consecutive_frames_with_exactly_that_count_longest_first() -> None:
    counts = dict(enumerate([3, 3, 3, 4, 3, 3, 3, 3, 5, 3, 3, 3], start=1))
    assert runs_with(counts, 3, min_frames=1) == [
        FrameRun(5, 8), FrameRun(1, 3), FrameRun(10, 12)
    ]  # fmt: skip
    # A tie keeps the earlier run first; shorter runs than asked are left out.
    assert runs_with(counts, 3, min_frames=3) == [FrameRun(5, 8), FrameRun(1, 3), FrameRun(10, 12)]
    assert runs_with(counts, 3, min_frames=4) == [FrameRun(5, 8)]
    assert runs_with(counts, 5, min_frames=1) == [FrameRun(9, 9)]
    assert runs_with(counts, 7, min_frames=1) == []


def test_a_missing_frame_number_ends_a_run() -> None:
    counts = {1: 3, 2: 3, 4: 3, 5: 3, 6: 3}
    assert runs_with(counts, 3, min_frames=1) == [FrameRun(4, 6), FrameRun(1, 2)]


def test_the_pets_runs_the_docstring_names() -> None:
    # PETS09-S2L1's scored people per frame over its first 40 frames, as gt.txt has them.
    counts = dict(enumerate([3] * 16 + [4] * 5 + [5] * 19, start=1))
    assert runs_with(counts, 3) == [FrameRun(1, 16)]
    assert runs_with(counts, 5) == [FrameRun(22, 40)]
    assert str(FrameRun(154, 206)) == "154-206" and FrameRun(154, 206).frames == 53


def test_half_pairs_step_together_half_a_run_apart() -> None:
    pairs = half_pairs(FrameRun(154, 206))  # 53 frames: shift 26
    assert pairs[0] == (154, 180) and pairs[-1] == (180, 206) and len(pairs) == 27
    assert all(b - a == 26 for a, b in pairs)
    assert [a for a, _ in pairs] == list(range(154, 181))
    assert half_pairs(FrameRun(1, 4)) == [(1, 3), (2, 4)]


def test_side_by_side_puts_left_then_right_at_full_size() -> None:
    left = np.zeros((4, 3, 3), np.uint8)
    right = np.full((4, 5, 3), 7, np.uint8)
    both = side_by_side(left, right)
    assert both.shape == (4, 8, 3) and both.dtype == np.uint8 and both.flags.c_contiguous
    assert (both[:, :3] == 0).all() and (both[:, 3:] == 7).all()
    with pytest.raises(ValueError, match="different heights"):
        side_by_side(left, np.zeros((5, 3, 3), np.uint8))


def test_segments_spread_over_the_clip_from_its_start_to_its_end() -> None:
    assert segments(735, 48, 3) == [range(0, 48), range(344, 392), range(687, 735)]
    assert segments(100, 40, 3) == [range(0, 40), range(60, 100)]  # three would overlap
    assert segments(30, 48, 3) == [range(30)]
    assert segments(100, 10, 1) == [range(10)]


def test_fps_is_frames_over_their_summed_time_not_the_median() -> None:
    s = summarise([50.0] * 9 + [150.0])
    assert s["p50_ms"] == 50.0 and s["mean_ms"] == 60.0
    assert s["fps"] == pytest.approx(1e3 / 60.0)
    assert np.isnan(summarise([])["fps"])


def row(view: str, tracker: str, threads: int, fps: float) -> dict:
    return {"view": view, "tracker": tracker, "threads": threads, "fps": fps,
            "p50_ms": 1e3 / fps, "p95_ms": 2e3 / fps, "landmark_runs_per_frame": 3.0,
            "people_per_frame": 7.5}  # fmt: skip


def test_the_goal_reads_10_people_budget_3_2_threads() -> None:
    rows = [row("10", BUDGET, 1, 9.0), row("10", BUDGET, 2, 16.0), row("5", BUDGET, 2, 30.0)]
    goal, line = goal_of(rows)
    assert goal is not None and goal["fps"] == 16.0 and goal["met"]
    assert line.endswith(": met.") and "16.0 fps" in line
    standing = people_fps({"rows": rows, "goal": goal})
    assert standing is not None and standing.met and standing.measured.startswith("16.0 fps")
    rows[1] = row("10", BUDGET, 2, PEOPLE_FPS_GOAL - 0.1)
    goal, line = goal_of(rows)
    assert goal is not None and not goal["met"] and line.endswith(": missed.")
    assert goal_of([row("5", BUDGET, 2, 30.0)])[0] is None
    assert people_fps({"rows": [], "goal": None}) is None


def fake_run(side: str, threads: int, ms: list[float], cpu_s: float) -> Run:
    rows = [{"i": i, "ms": m} for i, m in enumerate(ms)]
    summary = {"cpu_s": cpu_s, "frames": len(ms)}
    return Run(side, threads, rows, summary, 0.0, 0.0)


def test_the_people_table_gives_both_ratios_to_the_reference_and_their_quotient() -> None:
    col = Collected(
        [
            fake_run(OURS, 1, [10.0, 10.0, 30.0], 0.03),
            fake_run(PEOPLE, 1, [11.0, 11.0, 90.0], 0.06),
            fake_run(REF, 1, [20.0, 20.0, 20.0], 0.06),
        ]
    )
    rows: list = []
    lines = people_table(col, [1], np.array([True, True, False]), rows)
    found = next(r for r in rows if r["figure"] == "p50, frames all found")
    assert found["ours_to_reference_x"] == pytest.approx(0.5)
    assert found["people_to_reference_x"] == pytest.approx(0.55)
    assert found["people_to_ours_x"] == pytest.approx(1.1)
    cpu = next(r for r in rows if r["figure"] == "CPU-s per frame")
    assert cpu["people_to_ours_x"] == pytest.approx(2.0)
    assert "| 1 | p50, frames all found | 0.50 | 0.55 | 1.10 |" in lines
