"""The loop both benchmark workers share (ours in .venv, MediaPipe's in .venv-reference).

Only numpy and the standard library here: it runs in both environments. A worker pins
itself to its core budget before the models load (threads inherit the mask), warms up
on the first frames, then times one pass over the whole frame set, resetting its tracker
at each sequence start, and prints one JSON line per frame (wall and process CPU time)
and a summary line.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import numpy as np

from bench.frameset import load


class Runner(Protocol):
    """One pipeline: `process` returns (stage ms, landmarks (33, 2) px or None)."""

    def reset(self) -> None: ...

    def process(
        self, image: np.ndarray, timestamp: float, index: int
    ) -> tuple[dict[str, float], np.ndarray | None]: ...


def worker_args(
    description: str, extra: Callable[[argparse.ArgumentParser], None] | None = None
) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=description)
    if extra is not None:
        extra(ap)
    ap.add_argument("--frames", type=Path, required=True, help="frames .npy (truth .npz beside)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--warmup", type=int, default=30, help="frames processed before timing")
    ap.add_argument("--pin", action="store_true", help="restrict to `threads` cores")
    ap.add_argument("--limit", type=int, default=None, help="time only the first frames")
    return ap.parse_args()


def pin(threads: int) -> list[int]:
    """Restrict this process to its first `threads` allowed cores; return them."""
    cores = sorted(os.sched_getaffinity(0))[:threads]
    os.sched_setaffinity(0, cores)
    return cores


def _emit(obj: dict) -> None:
    sys.stdout.write(json.dumps(obj, separators=(",", ":")) + "\n")


def run(
    args: argparse.Namespace, make_runner: Callable[[argparse.Namespace], Runner], name: str
) -> None:
    """Warm up, time one pass over every frame, print per-frame JSON lines and a summary."""
    cores = pin(args.threads) if args.pin else sorted(os.sched_getaffinity(0))
    fs = load(args.frames, args.frames.with_suffix(".npz"))
    t_load = time.perf_counter()
    runner = make_runner(args)
    load_s = time.perf_counter() - t_load
    n = len(fs) if args.limit is None else min(args.limit, len(fs))
    # Warm-up: the first frames as one sequence (models, allocators, caches).
    runner.reset()
    for i in range(min(args.warmup, n)):
        runner.process(np.array(fs.images[i]), float(fs.timestamp[i]), i)
    # Touch every page once so neither side pays the first read from the page cache.
    images = [np.array(fs.images[i]) for i in range(n)]
    cpu0, ru0, wall0 = time.process_time(), resource.getrusage(resource.RUSAGE_SELF), 0.0
    wall_start = time.perf_counter()
    for i in range(n):
        if i == 0 or fs.sequence[i] != fs.sequence[i - 1]:
            runner.reset()
        image = images[i]
        c0, t0 = time.process_time(), time.perf_counter()
        stages, lm = runner.process(image, float(fs.timestamp[i]), i)
        ms = (time.perf_counter() - t0) * 1e3
        cpu_ms = (time.process_time() - c0) * 1e3  # every thread of the process
        wall0 += ms
        _emit(
            {
                "i": i,
                "ms": round(ms, 4),
                "cpu_ms": round(cpu_ms, 4),
                "stages": {k: round(v, 4) for k, v in stages.items()},
                "lm": None if lm is None else np.round(lm, 3).tolist(),
            }
        )
    wall = time.perf_counter() - wall_start
    cpu = time.process_time() - cpu0
    ru1 = resource.getrusage(resource.RUSAGE_SELF)
    _emit(
        {
            "summary": {
                "pipeline": name,
                "threads": args.threads,
                "cores": cores,
                "frames": n,
                "cpu_s": cpu,
                "user_s": ru1.ru_utime - ru0.ru_utime,
                "sys_s": ru1.ru_stime - ru0.ru_stime,
                "wall_s": wall,
                "timed_ms": wall0,
                "os_threads": len(os.listdir("/proc/self/task")),
                "maxrss_mb": ru1.ru_maxrss / 1024,
                "load_s": load_s,
            }
        }
    )
