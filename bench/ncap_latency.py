"""The pipeline's per-frame latency on car-scale Euro NCAP frames: the declared latency's source.

`monopic ncap` applies the car file's declared latency (scenarios/ncap/car.toml
`latency_ms`) so that its score is a property of the pipeline and not of the host's load.
That figure is the p95 this benchmark prints, rounded up: it runs the runs of
`monopic ncap --quick` (the car file's primary policy, the quick grid and its near misses)
the way the grid runs them (sim.runs.ncap_grid.work on sim.runs.executors' spawned
workers, one per core by default: the workers' environment, one onnxruntime thread each,
the GL context kept), each braking after the pipeline's measured latency, and takes the
pipeline's measured latency of every processed frame (`stage_ms["total"]`, kept per frame
in each run's outcome). Prints p50/p95/p99 and the figure to declare, and appends them
with the machine, its CPU flags and the load average to bench/history.jsonl
(bench/history.py) unless --no-append.

    .venv/bin/python -m bench.ncap_latency [--seeds N] [--workers N] [--no-append]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from bench.recorder import Recorder

HERE = Path(__file__).resolve().parent

TITLE = "Pipeline latency per frame on the Euro NCAP quick grid (the declared latency's source)"
ROUND_TO_MS = 5.0  # the declared figure: p95 rounded up to this step


def declared_figure(p95_ms: float, step: float = ROUND_TO_MS) -> float:
    """The figure to declare: the p95 rounded up to the next multiple of `step` ms."""
    if not (math.isfinite(p95_ms) and p95_ms >= 0):
        raise ValueError(f"p95 must be a finite number >= 0 ms, got {p95_ms}")
    return math.ceil(p95_ms / step - 1e-9) * step


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Percentiles over every processed frame of the result rows, and per run's median."""
    values = np.array([v for r in rows for v in r["outcome"]["latencies_ms"]], dtype=float)
    if values.size == 0:
        raise ValueError("no frame was processed")
    p50, p95, p99 = np.percentile(values, [50, 95, 99])
    return {
        "runs": len(rows),
        "frames": int(values.size),
        "p50_ms": float(p50),
        "p95_ms": float(p95),
        "p99_ms": float(p99),
        "max_ms": float(values.max()),
        "declared_ms": declared_figure(float(p95)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--seeds",
        type=int,
        help="jittered runs per grid point (default: the car's quick_seeds)",
    )
    ap.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    from sim.runs import ncap_grid
    from sim.runs.code_version import code_version
    from sim.runs.executors import local_executor
    from sim.scenario.ncap import CAR_FILE, PROTOCOL_FILE, load_car, load_protocol

    recorder = Recorder("ncap_latency", TITLE)
    protocol = load_protocol(HERE.parent / PROTOCOL_FILE)
    car = load_car(HERE.parent / CAR_FILE)
    measured = ncap_grid.LatencySetting(ncap_grid.MEASURED, None)
    runs = ncap_grid.expand(
        protocol, car, list(protocol.tests), [car.primary], quick=True, seeds=args.seeds,
        latency=measured,
    )  # fmt: skip
    code = code_version()
    runs = [replace(r, code=code) for r in runs]
    workers = args.workers or os.cpu_count() or 1
    rows: list[dict[str, Any]] = []
    local_executor(workers, run=ncap_grid.work)(runs, rows.append)
    errors = [r for r in rows if "error" in r]
    if errors:
        raise SystemExit(f"run {errors[0]['id']} failed:\n{errors[0]['error']}")
    res = summarise(rows)
    res.update(policy=car.primary, workers=workers, seeds=args.seeds or car.quick_seeds)
    lines = [
        f"`monopic ncap --quick --measured-latency`'s runs: {res['runs']} runs of "
        f"{car.primary} ({res['seeds']} jittered + {car.verification_seeds} verification per "
        f"grid point, and the near misses), {res['workers']} workers as the grid runs them "
        "(sim.runs.executors: one onnxruntime thread each); the pipeline's measured latency "
        '(`stage_ms["total"]`) of every processed frame.',
        "",
        "| frames | p50 | p95 | p99 | max | declared (p95 rounded up to 5 ms) |",
        "| ---: | ---: | ---: | ---: | ---: | ---: |",
        f"| {res['frames']} | {res['p50_ms']:.1f} ms | {res['p95_ms']:.1f} ms "
        f"| {res['p99_ms']:.1f} ms | {res['max_ms']:.1f} ms | {res['declared_ms']:g} ms |",
    ]
    table = "\n".join(lines)
    print(table)
    run = recorder.finish(res, table, write=not args.no_append)
    print(
        f"machine: {run.machine.label()} ({run.machine.vector_summary()}), load average "
        f"{run.load_before} before, {run.load_after} after, {run.date}",
        file=sys.stderr,
    )


if __name__ == "__main__":
    main()
