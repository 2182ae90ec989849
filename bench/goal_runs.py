"""The reference goals over many runs of bench/compare_reference.py: mean and 95 % interval.

On this shared host one run's ratio moves by 15-25 % with the minute-to-minute speed
(docs/benchmarks.md), so a goal near its bound is judged on the runs of one
setting: the mean over runs with its 95 % t-interval. A goal is met when the interval's
upper end is within the bound; when only the mean is, it is met on the mean, within the
noise, which does not close it.

    .venv/bin/python -m bench.goal_runs [--since 2026-12-04T21:00:00Z] [--until ...]
        [--commit e722539] [--model full-int8] [--detector float] [--window-detector int8] [--spin]
        [--max-load 2.5] [--no-append]
"""

from __future__ import annotations

import argparse
import math
import statistics
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bench.goals import RATIO_GOAL, cpu_ratio, p50_ratio
from bench.history import HISTORY, BenchRun, read
from bench.recorder import Recorder

TITLE = "The reference goals over many compare_reference runs: mean and 95 % interval"
# Student's t 97.5 % quantiles, 1 to 30 degrees of freedom (two-sided 95 %).
T975 = (12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
        2.201, 2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
        2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042)  # fmt: skip
Z975 = 1.959964


def t975(df: int) -> float:
    """Student's t 97.5 % quantile; beyond the table, the Cornish-Fisher expansion in 1/df
    (within 2e-4 of the exact value from 30 degrees of freedom on)."""
    if df < 1:
        raise ValueError(f"degrees of freedom must be 1 or more, got {df}")
    if df <= len(T975):
        return T975[df - 1]
    z = Z975
    return z + (z**3 + z) / (4 * df) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * df**2)


@dataclass(frozen=True)
class Summary:
    """One goal's figure over runs: mean and 95 % t-interval, the spread, runs met."""

    runs: int
    met: int
    mean: float
    low: float
    high: float
    smallest: float
    largest: float

    @property
    def verdict(self) -> str:
        if self.high <= RATIO_GOAL:
            return "met"
        if self.mean <= RATIO_GOAL:
            return "met on the mean, within the noise"
        return "missed"


def summarise(values: list[float]) -> Summary:
    """Mean and 95 % t-interval of one figure over runs (two runs at least)."""
    n = len(values)
    if n < 2:
        raise ValueError(f"an interval needs two runs or more, got {n}")
    mean = statistics.fmean(values)
    half = t975(n - 1) * statistics.stdev(values) / math.sqrt(n)
    met = sum(v <= RATIO_GOAL for v in values)
    return Summary(n, met, mean, mean - half, mean + half, min(values), max(values))


FIGURES: dict[str, Callable[[dict[str, Any]], float | None]] = {
    "per frame, 1 thread": lambda r: p50_ratio(r, 1),
    "per frame, 2 threads": lambda r: p50_ratio(r, 2),
    "CPU-seconds per frame, 1 thread": lambda r: cpu_ratio(r, 1),
    "CPU-seconds per frame, 2 threads": lambda r: cpu_ratio(r, 2),
}


def chosen(runs: list[BenchRun], args: argparse.Namespace) -> list[BenchRun]:
    """The compare_reference runs of the asked setting, code and time, and load."""
    setting = {
        "model": args.model,
        "detector": args.detector,
        "window_detector": args.window_detector,
        "spin": args.spin,
        "runtime": "cpu",
        "search": "tiles",
        # A run with the people side (--people): its "both found" frames are those all
        # three sides found, not the two the goals are judged on.
        "people": False,
    }
    defaults = {"model": "full", "detector": "float", "spin": False, "runtime": "cpu",
                "search": "tiles", "window_detector": None, "people": False}  # fmt: skip
    out = []
    for run in runs:
        r = run.results
        if run.benchmark != "compare_reference" or not args.since <= run.date <= args.until:
            continue
        if args.commit and not (run.commit or "").startswith(args.commit):
            continue
        if any(r.get(k, defaults[k]) != v for k, v in setting.items()):
            continue
        loads = [x for x in (run.load_before, run.load_after) if x is not None]
        if args.max_load is not None and loads and max(loads) > args.max_load:
            continue
        out.append(run)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--since", default="", help="UTC start, ISO 8601 (runs from then on)")
    ap.add_argument("--until", default="9999", help="UTC end, ISO 8601 (runs started by then)")
    ap.add_argument("--commit", default="", help="only runs of this commit (a prefix)")
    ap.add_argument("--model", default="full-int8")
    ap.add_argument("--detector", default="float")
    ap.add_argument("--window-detector", default="int8")
    ap.add_argument("--spin", action="store_true")
    ap.add_argument("--max-load", type=float, default=None, help="leave out busier runs")
    ap.add_argument("--history", type=Path, default=HISTORY)
    ap.add_argument("--no-append", action="store_true")
    args = ap.parse_args()
    recorder = Recorder("goal_runs", TITLE)
    runs = chosen(read(args.history), args)
    if len(runs) < 2:
        raise SystemExit(f"goal_runs: {len(runs)} compare_reference run(s) in {args.history} "
                         "match; an interval needs two or more")  # fmt: skip
    rows = []
    for name, figure in FIGURES.items():
        values = [v for v in (figure(run.results) for run in runs) if v is not None]
        if len(values) >= 2:
            summary = summarise(values)
            rows.append({"figure": name, **vars(summary), "verdict": summary.verdict})
    commits = sorted({(run.commit or "?")[:7] for run in runs})
    lines = [
        f"{len(runs)} runs of bench/compare_reference.py ({runs[0].date} to {runs[-1].date}; "
        f"commit {', '.join(commits)}), --model {args.model} --detector {args.detector} "
        f"--window-detector {args.window_detector}{' --spin' if args.spin else ''}; "
        f"ours / reference, goal <= {RATIO_GOAL}.",
        "",
        "| figure | runs | met in | mean [95 % interval] | smallest - largest | verdict |",
        "| --- | ---: | ---: | ---: | ---: | --- |",
        *(
            f"| {r['figure']} | {r['runs']} | {r['met']} | {r['mean']:.3f} "
            f"[{r['low']:.3f}, {r['high']:.3f}] | {r['smallest']:.2f} - {r['largest']:.2f} | "
            f"{r['verdict']} |"
            for r in rows
        ),
    ]
    table = "\n".join(lines)
    print(table)
    recorder.finish(
        {"since": args.since, "until": args.until, "commit": args.commit,
         "runs": [run.date for run in runs], "figures": rows},
        table,
        write=not args.no_append,
    )  # fmt: skip


if __name__ == "__main__":
    main()
