"""MediaPipe's three landmark models, ours and the reference's, in one table.

For each choice (lite, full, heavy: MediaPipe's model_complexity 0, 1, 2) our pipeline
with that landmark model (`TrackerConfig.model`, `monopic video --model`) and MediaPipe
0.10.14's Pose solution with the same model run over the same frames as in
bench/compare_reference.py (the workers, pinning and ABBA order are that script's): time
per frame (p50 on the frames both found), process CPU time per frame, the share of frames
each finds, and the landmark error against the truth on the frames both found, with the
paired 95 % interval of ours - reference (bench/paired.py).

    .venv/bin/python -m bench.model_choices [--rounds 2] [--threads 1] [--no-append]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

import numpy as np

from bench.compare_reference import (
    OURS,
    REF,
    Collected,
    found_mask,
    landmark_errors,
    pct,
    pooled_median,
    run_worker,
)
from bench.frameset import build, load
from bench.landmark_profile import macs_per_frame
from bench.paired import paired_median_difference
from bench.recorder import Recorder
from bench.reference_env import ensure
from monopic.pose.sessions import LANDMARK_MODELS, model_path

MODELS = ("lite", "full", "heavy")
TITLE = "Landmark model choices (lite, full, heavy): ours and the reference"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=2, help="ABBA rounds per model")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--warmup", type=int, default=30)
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    recorder = Recorder("model_choices", TITLE)
    npy, npz = build()
    fs = load(npy, npz)
    ref_python = ensure()
    start = time.perf_counter()
    loads: list[float] = []
    collected = {m: Collected() for m in MODELS}
    t = args.threads
    for rnd in range(args.rounds):
        for model in MODELS if rnd % 2 == 0 else MODELS[::-1]:
            for side in (OURS, REF) if rnd % 2 == 0 else (REF, OURS):
                run = run_worker(side, npy, t, args.warmup, ref_python, True, model)
                loads += [run.load_before, run.load_after]
                collected[model].runs.append(run)
                ms = 1e3 * run.summary["wall_s"] / run.summary["frames"]
                print(f"round {rnd + 1} {model} {side}: {ms:.1f} ms/frame", file=sys.stderr)
    n = len(fs)
    in_frame = fs.visible.any(axis=1)
    rows: list[dict[str, Any]] = []
    lines = [
        f"{n} frames 768x432 (the compare_reference frame set); {t} thread(s), workers pinned "
        f"to {t} core(s); {args.rounds} ABBA rounds; load average during the runs "
        f"{min(loads):.1f}-{max(loads):.1f} on {os.cpu_count()} cores; "
        f"{time.perf_counter() - start:.0f} s in all. Landmark error: median over the visible "
        "landmarks of the frames both found (all 33 mapped landmarks).",
        "",
        "| model | MMAC per frame | ours p50 | reference p50 | ours/ref | CPU-ms per frame "
        "ours / ref | found ours / ref | frames both found | error ours | error ref "
        "| ours - ref [95 %] |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    macs = {m: macs_per_frame(model_path(LANDMARK_MODELS[m]))[0] / 1e6 for m in MODELS}
    for model in MODELS:
        col = collected[model]
        first = {x: col.of(x, t)[0] for x in (OURS, REF)}
        found = {x: found_mask(r, n) for x, r in first.items()}
        both = found[OURS] & found[REF]
        p50 = {
            x: pct([r["ms"] for run in col.of(x, t) for r in run.rows if both[r["i"]]], 50)
            for x in (OURS, REF)
        }
        cpu = {
            x: 1e3
            * float(np.median([r.summary["cpu_s"] / r.summary["frames"] for r in col.of(x, t)]))
            for x in (OURS, REF)
        }
        common = np.flatnonzero(both & in_frame)
        errs = {x: landmark_errors(fs, first[x], common)["all visible"] for x in (OURS, REF)}
        diff = paired_median_difference(errs[OURS], errs[REF], fs.sequence[common])
        row = {
            "model": model,
            "macs_m": macs[model],
            "ours_p50_ms": p50[OURS],
            "reference_p50_ms": p50[REF],
            "ratio_p50_x": p50[OURS] / p50[REF],
            "ours_cpu_ms_per_frame": cpu[OURS],
            "reference_cpu_ms_per_frame": cpu[REF],
            "found_pct": {x: 100 * float(found[x].mean()) for x in (OURS, REF)},
            "both_found": int(len(common)),
            "error_px": {x: pooled_median(errs[x]) for x in (OURS, REF)},
            "difference_px": diff.difference,
            "low_px": diff.low,
            "high_px": diff.high,
            "verdict": diff.verdict,
        }
        rows.append(row)
        lines.append(
            f"| {model} | {macs[model]:.0f} | {p50[OURS]:.2f} ms | {p50[REF]:.2f} ms "
            f"| {row['ratio_p50_x']:.2f} | {cpu[OURS]:.1f} / {cpu[REF]:.1f} "
            f"| {row['found_pct'][OURS]:.0f} % / {row['found_pct'][REF]:.0f} % | {len(common)} "
            f"| {row['error_px'][OURS]:.2f} px | {row['error_px'][REF]:.2f} px "
            f"| {diff.difference:+.2f} [{diff.low:+.2f}, {diff.high:+.2f}] px ({diff.verdict}) |"
        )
    results = {
        "frames": n,
        "threads": t,
        "rounds": args.rounds,
        "load_min": min(loads),
        "load_max": max(loads),
        "models": rows,
    }
    table = "\n".join(lines)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
