"""compare_reference's energy proxy: every frame, and the frames both sides found beside."""

from __future__ import annotations

import numpy as np

from bench.compare_reference import OURS, REF, Collected, Run, cpu_table


def run(side: str, cpu_ms: list[float], found: list[bool]) -> Run:
    rows = [
        {"i": i, "ms": ms, "cpu_ms": ms, "lm": [[0.0, 0.0]] if f else None}
        for i, (ms, f) in enumerate(zip(cpu_ms, found, strict=True))
    ]
    summary = {"cpu_s": sum(cpu_ms) / 1e3, "wall_s": sum(cpu_ms) / 1e3, "frames": len(rows),
               "maxrss_mb": 100.0, "os_threads": 2}  # fmt: skip
    return Run(side, 1, rows, summary, 0.5, 0.5)


def test_search_frames_count_in_the_proxy_and_not_in_the_same_work_column() -> None:
    # Ours searches three frames with tiles (40 ms) and then tracks (8 ms); the reference
    # runs its detector on the first three and finds no one, then tracks (16 ms).
    ours = run(OURS, [40.0, 40.0, 40.0, 8.0, 8.0], [False, False, True, True, True])
    ref = run(REF, [12.0, 12.0, 12.0, 16.0, 16.0], [False, False, False, True, True])
    rows: list[dict] = []
    lines = cpu_table(Collected([ours, ref]), [1], 5, rows)
    by_side = {r["side"]: r for r in rows}
    assert np.isclose(by_side[OURS]["cpu_ms_per_frame"], 136 / 5)
    assert np.isclose(by_side[REF]["cpu_ms_per_frame"], 68 / 5)
    assert by_side[OURS]["cpu_ms_per_both_found_frame"] == 8.0  # frames 3 and 4 only
    assert by_side[REF]["cpu_ms_per_both_found_frame"] == 16.0
    assert "| 1 | ours | 27.2 ms | 8.00 ms |" in "\n".join(lines)


def test_no_frame_both_found_leaves_the_same_work_column_empty() -> None:
    ours = run(OURS, [8.0, 8.0], [True, True])
    ref = run(REF, [12.0, 12.0], [False, False])
    rows: list[dict] = []
    lines = cpu_table(Collected([ours, ref]), [1], 2, rows)
    assert all(r["cpu_ms_per_both_found_frame"] is None for r in rows)
    assert "| 1 | reference | 12.0 ms | - |" in "\n".join(lines)
