"""bench/goal_runs.py: issue 21's goals over many runs, judged on the interval's upper end."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from bench.goal_runs import summarise, t975
from bench.history import append
from tests.bench.test_history import bench_run, comparison
from tests.paths import ROOT

SCRIPT = ["-m", "bench.goal_runs"]


def test_t_quantiles_come_from_the_table_and_the_expansion_joins_it() -> None:
    assert t975(1) == 12.706 and t975(30) == 2.042
    assert abs(t975(31) - 2.0395) < 2e-4  # the exact value, 2.03951
    assert abs(t975(120) - 1.9799) < 2e-4
    with pytest.raises(ValueError, match="1 or more, got 0"):
        t975(0)


def test_the_interval_decides_met_the_mean_alone_does_not() -> None:
    s = summarise([0.4, 0.5, 0.6])
    assert s.mean == pytest.approx(0.5) and s.runs == 3 and s.met == 2
    assert s.high - s.mean == pytest.approx(4.303 * 0.1 / 3**0.5)
    assert s.verdict == "met on the mean, within the noise"
    assert summarise([0.45, 0.46, 0.47, 0.46]).verdict == "met"
    assert summarise([0.52, 0.55]).verdict == "missed"
    with pytest.raises(ValueError, match="two runs or more, got 1"):
        summarise([0.4])


def _history(tmp_path: Path) -> Path:
    path = tmp_path / "history.jsonl"
    setting = {"model": "full-int8", "window_detector": "int8", "spin": True}
    for k, (two_ours, date) in enumerate(((4.6, "2026-12-04T21:00:00Z"),
                                          (4.9, "2026-12-04T21:02:00Z"),
                                          (4.7, "2026-12-04T21:04:00Z"))):  # fmt: skip
        results = {**comparison((7.2, 16.0), (two_ours, 10.0), []), **setting}
        append(
            path, replace(bench_run("compare_reference", date, results, "t"), load_after=1.0 + k)
        )
    # Another setting and an earlier run: both left out.
    other = {**comparison((7.0, 16.0), (9.0, 10.0), []), "model": "full"}
    append(path, bench_run("compare_reference", "2026-12-04T21:06:00Z", other, "t"))
    early = {**comparison((7.0, 16.0), (9.0, 10.0), []), **setting}
    append(path, bench_run("compare_reference", "2026-12-04T20:00:00Z", early, "t"))
    return path


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, *SCRIPT, *args, "--no-append"],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)  # fmt: skip


def test_the_runs_of_one_setting_are_summarised_per_goal(tmp_path: Path) -> None:
    history = _history(tmp_path)
    r = _run("--history", str(history), "--spin", "--since", "2026-12-04T20:30:00Z")
    assert r.returncode == 0, r.stderr
    rows = {line.split(" | ")[0].lstrip("| "): line for line in r.stdout.splitlines()
            if line.startswith("| per frame") or line.startswith("| CPU")}  # fmt: skip
    assert len(rows) == 4
    assert "| 3 | 3 | 0.450 [0.450, 0.450]" in rows["per frame, 1 thread"]
    assert rows["per frame, 1 thread"].endswith("| met |")
    assert "| 3 | 3 | 0.473 [" in rows["per frame, 2 threads"]  # 0.46, 0.49, 0.47
    assert rows["per frame, 2 threads"].endswith("| met on the mean, within the noise |")
    # The busiest run left out: two remain.
    r = _run("--history", str(history), "--spin", "--since", "2026-12-04T20:30:00Z",
             "--max-load", "2.5")  # fmt: skip
    assert r.returncode == 0 and "| per frame, 2 threads | 2 |" in r.stdout, r.stdout


def test_too_few_matching_runs_is_said_in_one_line(tmp_path: Path) -> None:
    r = _run("--history", str(_history(tmp_path)), "--since", "2026-12-04T20:30:00Z")
    assert r.returncode == 1
    assert r.stderr.strip().endswith("0 compare_reference run(s) in "
                                     f"{tmp_path / 'history.jsonl'} match; an interval needs "
                                     "two or more")  # fmt: skip
