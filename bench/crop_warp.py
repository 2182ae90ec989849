"""The pose models' input warps: OpenCV on the RGB frame against its four-channel form.

monopic.pose.warp says why the tracker widens each frame to four channels once: OpenCV's
vector kernels take 4-channel uint8 only. This times, alternated on the same frames and
rotated crops (bench/alternate.py): the 256 px landmark crop and the 224 px detector
letterbox of the whole frame, each from the RGB frame and from its four-channel form,
and the widening itself; one OpenCV thread, as a sweep worker has.

    .venv/bin/python -m bench.crop_warp [--rounds 6] [--no-append]
"""

from __future__ import annotations

import argparse
import math

import cv2
import numpy as np

from bench.alternate import alternated_ms
from bench.frameset import build, load
from bench.recorder import Recorder
from monopic.pose.warp import four_channel

TITLE = "The pose models' input warps: RGB frame against its four-channel form"
CROP, LETTERBOX = 256, 224


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=6, help="alternated rounds (A B, B A, ...)")
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    if args.rounds < 2:
        raise SystemExit(f"crop_warp: --rounds must be at least 2, got {args.rounds}")
    cv2.setNumThreads(1)
    recorder = Recorder("crop_warp", TITLE)
    fs = load(*build())
    frames = [np.ascontiguousarray(fs.images[i]) for i in range(0, len(fs), 4)]
    rng = np.random.default_rng(0)
    inputs = []
    for image in frames:
        h, w = image.shape[:2]
        a, side = rng.uniform(-0.5, 0.5), rng.uniform(100, 300)
        k = side / CROP
        c, s = math.cos(a) * k, math.sin(a) * k
        crop = np.array([[c, -s, rng.uniform(0, w - side)], [s, c, rng.uniform(0, h - side)]])
        scale = LETTERBOX / max(w, h)
        box = np.array([[scale, 0.0, 0.0], [0.0, scale, (LETTERBOX - h * scale) / 2]])
        inputs.append((image, four_channel(image), crop, box))
    inv = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    calls = {
        "crop, RGB": lambda x: cv2.warpAffine(x[0], x[2], (CROP, CROP), flags=inv),
        "crop, four-channel": lambda x: cv2.warpAffine(x[1], x[2], (CROP, CROP), flags=inv),
        "letterbox, RGB": lambda x: cv2.warpAffine(
            x[0], x[3], (LETTERBOX, LETTERBOX), flags=cv2.INTER_AREA
        ),
        "letterbox, four-channel": lambda x: cv2.warpAffine(
            x[1], x[3], (LETTERBOX, LETTERBOX), flags=cv2.INTER_AREA
        ),
        "widen the frame to four channels": lambda x: four_channel(x[0]),
    }
    timed = alternated_ms(calls, inputs, args.rounds)
    ms = timed["ms"]
    h, w = frames[0].shape[:2]
    rows = [f"| {name} | {v:.3f} ms |" for name, v in ms.items()]
    table = "\n".join(
        [
            f"{len(inputs)} frames of {w}x{h} (bench/frameset.py), {args.rounds} alternated "
            f"rounds, one OpenCV thread; load average {timed['load_min']:.1f}-"
            f"{timed['load_max']:.1f}.",
            "",
            "| warp | median |",
            "| --- | ---: |",
            *rows,
            "",
            f"Crop: four-channel / RGB = **{ms['crop, four-channel'] / ms['crop, RGB']:.2f}**; "
            f"letterbox: **{ms['letterbox, four-channel'] / ms['letterbox, RGB']:.2f}**.",
        ]
    )
    print(table)
    results = {
        "frames": len(inputs),
        "rounds": args.rounds,
        **{name.replace(", ", "_").replace(" ", "_") + "_ms": v for name, v in ms.items()},
    }
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
