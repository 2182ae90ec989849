"""Our pipeline as a benchmark worker (runs in .venv): frames in, JSON lines out.

The twin of bench/reference_worker.py; bench/compare_reference.py alternates the two.
`threads` is the onnxruntime intra-op thread count of both models; with --pin the process
is also confined to that many cores, as the reference is.

Two bench-only variants, to measure changes before anyone makes them in monopic/:
--landmark-model swaps in another landmark ONNX file with the same inputs/outputs (e.g.
the pruned one from bench/prune_landmarks.py); --refine-heatmap adds MediaPipe's
RefineLandmarksFromHeatmapCalculator step (kernel 7, refine when the peak sigmoid
confidence is >= 0.5), which the reference graph runs and monopic does not.

    .venv/bin/python bench/pipeline_worker.py --frames recordings/bench/frames-*.npy --threads 1
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from worker_common import run, worker_args  # noqa: E402

POST_STAGES = ("features", "predict", "warning")
HEATMAP_KERNEL = 7
HEATMAP_MIN_CONFIDENCE = 0.5


def refine_from_heatmap(points: np.ndarray, heatmap: np.ndarray, size: int) -> np.ndarray:
    """MediaPipe's heatmap refinement of crop-pixel (x, y) for the first heatmap channels.

    As refine_landmarks_from_heatmap_calculator.cc: around each point's heatmap cell, the
    sigmoid-weighted mean cell position over a 7x7 window (cut at the border) replaces
    the point when the window's peak confidence reaches 0.5. Vectorised: one gather of
    the K 7x7 windows from a heatmap padded with zero confidence.
    """
    hh, hw, channels = heatmap.shape
    k = min(channels, len(points))
    off = (HEATMAP_KERNEL - 1) // 2
    col = np.trunc(points[:k, 0] / size * hw).astype(int)  # C++ int(): toward zero
    row = np.trunc(points[:k, 1] / size * hh).astype(int)
    inside = (col >= 0) & (col < hw) & (row >= 0) & (row < hh)
    padded = np.pad(heatmap[..., :k], ((off, off), (off, off), (0, 0)), constant_values=-np.inf)
    span = np.arange(HEATMAP_KERNEL)
    rr = np.clip(row, 0, hh - 1)[:, None] + span  # padded coordinates of the window rows
    cc = np.clip(col, 0, hw - 1)[:, None] + span
    logits = padded[rr[:, :, None], cc[:, None, :], np.arange(k)[:, None, None]]
    conf = 1.0 / (1.0 + np.exp(-logits.astype(np.float64)))  # (K, 7, 7); 0 off the map
    total = conf.sum(axis=(1, 2))
    ok = inside & (conf.max(axis=(1, 2)) >= HEATMAP_MIN_CONFIDENCE) & (total > 0)
    rows = (rr - off)[:, :, None].astype(float)  # back to heatmap cell coordinates
    cols = (cc - off)[:, None, :].astype(float)
    safe = np.where(total > 0, total, 1.0)
    x = (conf * cols).sum(axis=(1, 2)) / safe / hw * size
    y = (conf * rows).sum(axis=(1, 2)) / safe / hh * size
    out = points.copy()
    out[:k, 0] = np.where(ok, x, points[:k, 0])
    out[:k, 1] = np.where(ok, y, points[:k, 1])
    return out


class OurRunner:
    """monopic.Pipeline with the reference rule cascade, image mode, no robot state."""

    def __init__(self, args: argparse.Namespace) -> None:
        from monopic.features.extractor import FeatureExtractor
        from monopic.frame import Frame
        from monopic.pipeline import Pipeline, PipelineConfig
        from monopic.pose.sessions import make_session
        from monopic.pose.tracker import TrackerConfig

        self._frame = Frame
        self._extractor = FeatureExtractor
        self.pipeline = Pipeline(PipelineConfig(tracker=TrackerConfig(threads=args.threads)))
        model = self.pipeline.tracker.landmarks
        if args.landmark_model is not None:
            model.session = make_session(args.landmark_model, args.threads)
        if args.refine_heatmap:
            _add_heatmap_refinement(model)

    def reset(self) -> None:
        self.pipeline.tracker.reset()
        self.pipeline.features = self._extractor()

    def process(
        self, image: np.ndarray, timestamp: float, index: int
    ) -> tuple[dict[str, float], np.ndarray | None]:
        t0 = time.perf_counter()
        r = self.pipeline.process(self._frame(image, timestamp, None, index))
        ms = (time.perf_counter() - t0) * 1e3
        s = r.stage_ms
        stages = {
            "detect": s.get("detect", 0.0),
            "landmarks": s.get("landmarks", 0.0),
            "pose": s.get("pose", 0.0),
            "post": sum(s.get(k, 0.0) for k in POST_STAGES),
            "total": ms,
            "detector_runs": float(r.pose.detector_runs),
        }
        pose = r.pose.pose
        return stages, None if pose is None else pose.landmarks[:, :2]


def _add_heatmap_refinement(model) -> None:
    """Make the model's session also return the heatmap and refine x, y from it."""
    from monopic.pose.landmarks import INPUT_SIZE, NUM_POINTS

    session = model.session
    heatmap_name = next(o.name for o in session.get_outputs() if len(o.shape) == 4 and
                        o.shape[-1] == NUM_POINTS)  # fmt: skip

    class Refining:
        def run(self, names, feeds):
            points, flag, heatmap = session.run([*names, heatmap_name], feeds)
            pts = points.reshape(NUM_POINTS, 5).copy()
            pts[:, :2] = refine_from_heatmap(pts[:, :2], heatmap[0], INPUT_SIZE)
            return [pts.reshape(points.shape), flag]

    model.session = Refining()


def options(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--landmark-model", type=Path, default=None, help="another landmark .onnx")
    ap.add_argument("--refine-heatmap", action="store_true", help="MediaPipe's heatmap step")


def main() -> None:
    args = worker_args(__doc__.split("\n")[0], options)
    name = "monopic" + (f" ({args.landmark_model.name})" if args.landmark_model else "")
    run(args, OurRunner, name + (" + heatmap refinement" if args.refine_heatmap else ""))


if __name__ == "__main__":
    main()
