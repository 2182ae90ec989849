"""A variant of our landmark model that computes only the outputs the pipeline reads.

pose_landmark_full.onnx has five outputs (landmarks, pose flag, segmentation, heatmap,
world landmarks); monopic reads the first two, but onnxruntime runs the whole graph
whatever outputs are requested. onnx.utils.extract_model keeps only the nodes those two
need (73 of the 96 convolutions): the same numbers, less work. Runs in .venv-reference
(which has onnx; the project's venv does not). The output is a benchmark artefact under
recordings/bench/, not a shipped model.

    .venv-reference/bin/python bench/prune_landmarks.py [--out recordings/bench/...onnx]
        [--keep landmarks pose_flag]
"""

from __future__ import annotations

import argparse
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "monopic" / "pose" / "models" / "pose_landmark_full.onnx"
DEFAULT_OUT = ROOT / "recordings" / "bench" / "pose_landmark_full.pruned.onnx"
KEEP = ("landmarks", "pose_flag")


def prune(source: Path, out: Path, keep: tuple[str, ...] = KEEP) -> Path:
    """Write the sub-model of `source` that computes `keep` only; return its path."""
    import onnx
    import onnx.utils

    model = onnx.load(str(source))
    inputs = [i.name for i in model.graph.input]
    out.parent.mkdir(parents=True, exist_ok=True)
    onnx.utils.extract_model(str(source), str(out), inputs, list(keep), check_model=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", type=Path, default=SOURCE)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--keep", nargs="+", default=list(KEEP))
    args = ap.parse_args()
    print(prune(args.source, args.out, tuple(args.keep)))


if __name__ == "__main__":
    main()
