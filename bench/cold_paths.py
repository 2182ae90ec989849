"""What the stage around the landmark model costs right after a model run, and warm.

Inside the pipeline the Python and numpy steps around the landmark model take
about three times what they take in a loop of their own: an onnxruntime run leaves every
code path cold, so the first numpy call after it and each call of a kind not yet run this
frame cost far more than the same call run again. This times, in one process and
alternated, each step twice: right after a landmark model run (as in the pipeline) and
right after running the same step (warm). The steps: the first numpy call, a Python loop,
a few different numpy calls, the heatmap refinement, and a frame of the shipped clip
widened to four channels, cropped and made the model's float input, into fresh arrays or
into the buffers the landmark model keeps (monopic.pose.warp.WarpBuffers), and the same
with the frame widened only around the crop, as the tracker does while it tracks
(monopic.pose.warp.WideFrame).

    .venv/bin/python -m bench.cold_paths [--rounds 300] [--threads 1] [--no-append]
"""

from __future__ import annotations

import argparse
import itertools
import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from bench.recorder import Recorder
from monopic.pose.landmarks import INPUT_SIZE, LandmarkModel, refine_from_heatmap
from monopic.pose.region import Region
from monopic.pose.sessions import quantised_unavailable
from monopic.pose.warp import WarpBuffers, WideFrame, four_channel
from monopic.video import VideoSource

TITLE = "The steps around the landmark model: right after a model run against warm"
CLIP = Path(__file__).resolve().parents[1] / "tests" / "data" / "walk_clip.mp4"


def steps(frames: list[np.ndarray]) -> dict[str, Callable[[], object]]:
    """Each step as a call; every call does the same work each time (the crops widen the
    next of the clip's frames to four channels first, as the tracker does each frame)."""
    rng = np.random.default_rng(0)
    small = rng.random(80)
    heatmap = rng.normal(-2.0, 3.0, (39, 64, 64)).astype(np.float32).transpose(1, 2, 0)
    points = rng.uniform(0.0, 256.0, (39, 2))
    h, w = frames[0].shape[:2]
    region = Region(w / 2, h / 2, 220.0, 0.1)  # 18 % of a frame widened around it
    wide = WideFrame()
    order = itertools.count()
    buffers = WarpBuffers.of((INPUT_SIZE, INPUT_SIZE))
    tensor = np.empty((INPUT_SIZE, INPUT_SIZE, 3), np.float32)
    scale = np.float32(1.0 / 255.0)

    def python_loop() -> int:
        total = 0
        for i in range(50):
            total += i
        return total

    def mixed() -> object:
        b = small * 2.0
        c = np.exp(b)
        return c.sum(), np.where(b > 1.0, b, 0.0), np.stack((b, c)).max(axis=1)

    def frame() -> np.ndarray:
        return four_channel(frames[next(order) % len(frames)])

    def crop_fresh() -> object:
        crop = region.crop(frame(), INPUT_SIZE)
        out = crop.astype(np.float32)
        out *= scale
        return out

    def crop_reused() -> object:
        crop = region.crop(frame(), INPUT_SIZE, buffers)
        return np.multiply(crop, scale, out=tensor, dtype=np.float32)

    def crop_around() -> object:
        wide.start(frames[next(order) % len(frames)])
        crop = region.crop(wide.around(*region.bounds()), INPUT_SIZE, buffers)
        return np.multiply(crop, scale, out=tensor, dtype=np.float32)

    return {
        "one numpy call (np.add on 80 floats)": lambda: np.add(small, 1.0),
        "a Python loop of 50 additions": python_loop,
        "six numpy calls of different kinds": mixed,
        "heatmap refinement (39 points)": lambda: refine_from_heatmap(points, heatmap, 256),
        "frame to 4 channels, crop, float input: fresh arrays": crop_fresh,
        "the same into reused buffers": crop_reused,
        "the same, the frame widened around the crop only (WideFrame)": crop_around,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=300)
    ap.add_argument("--threads", type=int, default=1, help="the landmark model's threads")
    ap.add_argument("--no-append", action="store_true")
    args = ap.parse_args()
    if args.rounds < 1 or args.threads < 1:
        raise SystemExit(f"cold_paths: --rounds and --threads must be 1 or more, got "
                         f"{args.rounds} and {args.threads}")  # fmt: skip
    os.sched_setaffinity(0, sorted(os.sched_getaffinity(0))[: args.threads])
    recorder = Recorder("cold_paths", TITLE)
    frames = [f.image for f in VideoSource(str(CLIP))]  # the shipped clip, 60 frames
    # The judged setting's model; the float one where the CPU cannot run int8 (no VNNI).
    name = "full-int8" if quantised_unavailable() is None else "full"
    model = LandmarkModel(args.threads, name)
    tensor = np.random.default_rng(1).random((1, INPUT_SIZE, INPUT_SIZE, 3), dtype=np.float32)

    def run_model() -> None:
        model.session.run(model.output_names, {model.input_name: tensor})

    calls = steps(frames)
    times: dict[str, dict[str, list[float]]] = {k: {"cold": [], "warm": []} for k in calls}
    for _ in range(args.rounds):
        for name, call in calls.items():
            for state, before in (("cold", run_model), ("warm", call)):
                before()
                t0 = time.perf_counter()
                call()
                times[name][state].append(time.perf_counter() - t0)
    rows = []
    for name, by in times.items():
        cold, warm = (1e6 * float(np.median(by[s])) for s in ("cold", "warm"))
        rows.append({"step": name, "after_model_us": cold, "warm_us": warm, "ratio": cold / warm})
    lines = [
        f"{args.rounds} rounds, landmark model {name} at {args.threads} thread(s); "
        "median us per call, each step right after a model run and right after itself.",
        "",
        "| step | right after a model run | warm | ratio |",
        "| --- | ---: | ---: | ---: |",
        *(
            f"| {r['step']} | {r['after_model_us']:.1f} | {r['warm_us']:.1f} | {r['ratio']:.1f}x |"
            for r in rows
        ),
    ]
    table = "\n".join(lines)
    print(table)
    recorder.finish({"rounds": args.rounds, "threads": args.threads, "steps": rows}, table,
                    write=not args.no_append)  # fmt: skip


if __name__ == "__main__":
    main()
