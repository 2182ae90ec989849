"""Per-stage latency of the pipeline on a 768x432 video, at 1 and 2 onnxruntime threads.

Runs alternate between thread counts (A B A B ...) so machine noise hits both alike; the
first pass over the clip of each is warm-up and not timed. Prints p50/p95 per stage and
appends them to bench/history.jsonl (bench/history.py) unless --no-append.

    .venv/bin/python -m bench.pipeline_latency [VIDEO] [--rounds 3] [--no-append]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from bench.recorder import Recorder
from monopic.pipeline import Pipeline, PipelineConfig
from monopic.pose.tracker import TrackerConfig
from monopic.video import VideoSource

STAGES = ("detect", "landmarks", "pose", "features", "predict", "warning", "total")
# The tracker detects only when it (re)acquires; this row times one whole-frame detector
# pass on every frame, what acquisition costs at the least.
DETECT_EVERY_FRAME = "detector (whole frame, every frame)"
DEFAULT_VIDEO = Path(__file__).resolve().parents[1] / "tests" / "data" / "walk_clip.mp4"


def run_once(frames, threads: int) -> dict[str, list[float]]:
    pipeline = Pipeline(PipelineConfig(tracker=TrackerConfig(threads=threads)))
    times: dict[str, list[float]] = {s: [] for s in (*STAGES, DETECT_EVERY_FRAME)}
    for frame in frames:
        r = pipeline.process(frame)
        for s in STAGES:
            if s in r.stage_ms and (s != "detect" or r.pose.detector_runs > 0):
                times[s].append(r.stage_ms[s])
        t0 = time.perf_counter()
        pipeline.tracker.detector.detect(frame.image)
        times[DETECT_EVERY_FRAME].append((time.perf_counter() - t0) * 1e3)
    return times


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("video", nargs="?", type=Path, default=DEFAULT_VIDEO)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    recorder = Recorder("pipeline_latency", "Pipeline latency per stage")
    frames = list(VideoSource(str(args.video)))
    h, w = frames[0].image.shape[:2]
    for threads in (1, 2):  # warm-up
        run_once(frames, threads)
    rows = (*STAGES, DETECT_EVERY_FRAME)
    results: dict[int, dict[str, list[float]]] = {n: {s: [] for s in rows} for n in (1, 2)}
    for _ in range(args.rounds):
        for threads in (1, 2):
            for s, v in run_once(frames, threads).items():
                results[threads][s].extend(v)
    lines = [
        f"{len(frames)} frames of {args.video.name} ({w}x{h}), "
        f"{args.rounds} rounds per thread count",
        "",
        "| stage | 1 thread p50 | p95 | 2 threads p50 | p95 | ratio p50 (1/2) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    stages: list[dict[str, Any]] = []
    for s in rows:
        a, b = np.array(results[1][s]), np.array(results[2][s])
        if a.size == 0 or b.size == 0:
            continue
        p = [np.percentile(a, 50), np.percentile(a, 95), np.percentile(b, 50), np.percentile(b, 95)]
        ratio = p[0] / p[2] if p[2] > 0 else float("nan")
        stages.append(
            {
                "stage": s,
                "samples_1_thread": int(a.size),
                "p50_1_thread_ms": p[0],
                "p95_1_thread_ms": p[1],
                "samples_2_threads": int(b.size),
                "p50_2_threads_ms": p[2],
                "p95_2_threads_ms": p[3],
                "ratio_p50_1_to_2_x": ratio,
            }
        )
        lines.append(
            f"| {s} | {p[0]:.2f} ms | {p[1]:.2f} ms | {p[2]:.2f} ms | {p[3]:.2f} ms | {ratio:.2f} |"
        )
    lines += [
        "",
        "`detect` counts only frames where the tracker (re)acquires; "
        "`pose` = detect + crop + landmarks.",
    ]
    table = "\n".join(lines)
    print(table)
    summary = {
        "video": args.video.name,
        "frames": len(frames),
        "width_px": w,
        "height_px": h,
        "rounds": args.rounds,
        "stages": stages,
    }
    recorder.finish(summary, table, write=not args.no_append)


if __name__ == "__main__":
    main()
