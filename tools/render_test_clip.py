"""Render the end-to-end test clip and its ground truth (see sim/dataset/clip.py).

    .venv/bin/python -m tools.render_test_clip

writes tests/data/walk_clip.mp4 and tests/data/walk_clip_truth.csv.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from sim.dataset.clip import ClipSpec, render_clip

REPO = Path(__file__).resolve().parent.parent
DEFAULT_VIDEO = REPO / "tests" / "data" / "walk_clip.mp4"
DEFAULT_TRUTH = REPO / "tests" / "data" / "walk_clip_truth.csv"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--video", type=Path, default=DEFAULT_VIDEO)
    parser.add_argument("--truth", type=Path, default=DEFAULT_TRUTH)
    parser.add_argument(
        "--frames-dir", type=Path, default=None, help="also save the rendered frames here as PNG"
    )
    args = parser.parse_args(argv)
    clip = ClipSpec()
    times = render_clip(clip, args.video, args.truth, args.frames_dir)
    size_kb = args.video.stat().st_size / 1024
    print(
        f"{len(times)} frames {clip.width}x{clip.height} -> {args.video} ({size_kb:.0f} kB), "
        f"{args.truth}; render median {np.median(times) * 1000:.1f} ms/frame"
    )


if __name__ == "__main__":
    main()
