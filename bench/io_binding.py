"""What the landmark model's I/O binding saves: a plain run against a run into kept arrays.

`session.run` allocates the three outputs and copies each out of onnxruntime,
the heatmap's 640 kB among them; monopic.pose.landmarks.LandmarkModel binds its input and
outputs to arrays it keeps, so a run writes into them. This alternates the two, call by
call, on one session (the shipped model, a crop of the shipped clip as input), with a
numpy step between calls as the pipeline has, and checks both give the same outputs.

    .venv/bin/python -m bench.io_binding [--rounds 1500] [--threads 1 2] [--model full-int8]
        [--no-append]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from bench.recorder import Recorder
from monopic.pose.landmarks import INPUT_SIZE, LandmarkModel
from monopic.pose.region import Region
from monopic.pose.sessions import LANDMARK_MODELS, quantised_unavailable
from monopic.video import VideoSource

TITLE = "The landmark model's I/O binding: a plain run against a run into kept arrays"
CLIP = Path(__file__).resolve().parents[1] / "tests" / "data" / "walk_clip.mp4"


def paired(model: LandmarkModel, rounds: int) -> dict[str, float]:
    """Median plain and bound run times (ms) and the median of their paired difference."""
    plain_times, bound_times = [], []
    between = np.random.default_rng(1).random(300_000)
    feeds = {model.input_name: model._tensor}
    for _ in range(rounds):
        between.sum()
        t0 = time.perf_counter()
        model.session.run(model.output_names, feeds)
        plain_times.append(time.perf_counter() - t0)
        between.sum()
        t0 = time.perf_counter()
        model._infer()
        bound_times.append(time.perf_counter() - t0)
    plain, bound = np.array(plain_times), np.array(bound_times)
    return {
        "plain_ms": 1e3 * float(np.median(plain)),
        "bound_ms": 1e3 * float(np.median(bound)),
        "saved_us": 1e6 * float(np.median(plain - bound)),
        "ratio": float(np.median(bound / plain)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=1500)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    # The judged setting's model by default; the float one where the CPU cannot run int8.
    default = "full-int8" if quantised_unavailable() is None else "full"
    ap.add_argument("--model", choices=sorted(LANDMARK_MODELS), default=default)
    ap.add_argument("--no-append", action="store_true")
    args = ap.parse_args()
    if args.rounds < 1 or min(args.threads) < 1:
        raise SystemExit(f"io_binding: --rounds and --threads must be 1 or more, got "
                         f"{args.rounds} and {args.threads}")  # fmt: skip
    recorder = Recorder("io_binding", TITLE)
    image = next(iter(VideoSource(str(CLIP)))).image
    h, w = image.shape[:2]
    cores = sorted(os.sched_getaffinity(0))
    rows = []
    for threads in args.threads:
        os.sched_setaffinity(0, cores[:threads])
        model = LandmarkModel(threads, args.model)
        model.run(image, Region(w / 2, h / 2, 0.8 * h, 0.0))  # fills the input tensor
        plain = model.session.run(model.output_names, {model.input_name: model._tensor})
        model._infer()
        same = all(np.array_equal(a, b) for a, b in zip(plain, model._outputs, strict=True))
        if not same:
            raise SystemExit("io_binding: the bound run's outputs differ from the plain run's")
        rows.append({"threads": threads, **paired(model, args.rounds)})
    lines = [
        f"{args.rounds} alternated pairs, landmark model {args.model}, a {INPUT_SIZE} px crop "
        "of the shipped clip; outputs equal both ways.",
        "",
        "| threads | plain run, ms | bound run, ms | saved per run (paired median), us | ratio |",
        "| ---: | ---: | ---: | ---: | ---: |",
        *(
            f"| {r['threads']} | {r['plain_ms']:.2f} | {r['bound_ms']:.2f} | "
            f"{r['saved_us']:.0f} | {r['ratio']:.3f} |"
            for r in rows
        ),
    ]
    table = "\n".join(lines)
    print(table)
    recorder.finish({"rounds": args.rounds, "model": args.model, "rows": rows}, table,
                    write=not args.no_append)  # fmt: skip


if __name__ == "__main__":
    main()
