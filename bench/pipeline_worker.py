"""Our pipeline as a benchmark worker (runs in .venv): frames in, JSON lines out.

The twin of bench/reference_worker.py; bench/compare_reference.py alternates the two.
`threads` is the onnxruntime intra-op thread count of both models; with --pin the process
is also confined to that many cores, as the reference is. The landmark stage is monopic's
as shipped: the pruned landmark model and MediaPipe's heatmap refinement
(monopic.pose.landmarks.refine_from_heatmap), as in the reference graph. With --people
the pipeline follows everyone in view (PipelineConfig.people = PeopleConfig()); the
landmarks reported are those of the person whose warning is the robot's.

    .venv/bin/python -m bench.pipeline_worker --frames recordings/bench/frames-*.npy --threads 1
        [--model lite|full|heavy|full-int8] [--detector float|int8]
        [--window-detector float|int8] [--runtime cpu|openvino]
        [--spin] [--search tiles|whole-frame] [--people]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from bench.worker_common import run, worker_args

POST_STAGES = ("features", "predict", "warning")


class OurRunner:
    """monopic.Pipeline with the reference rule cascade, image mode, no robot state."""

    def __init__(self, args: argparse.Namespace) -> None:
        from monopic.frame import Frame
        from monopic.people.tracker import PeopleConfig
        from monopic.pipeline import Pipeline, PipelineConfig
        from monopic.pose.tracker import TrackerConfig

        self._frame = Frame
        config = TrackerConfig(
            threads=args.threads,
            model=args.model,
            detector=args.detector,
            window_detector=args.window_detector,
            runtime=args.runtime,
            spin=args.spin,
            # MediaPipe's search: the whole frame only, no tiles nor zooms for far pedestrians.
            **(
                {"acquire_tiles": (), "far_tiles": (), "zoom_score": None}
                if args.search == "whole-frame"
                else {}
            ),
        )
        people = PeopleConfig() if args.people else None
        self.pipeline = Pipeline(PipelineConfig(tracker=config, people=people))

    def reset(self) -> None:
        """Forget the tracks at a sequence start without loading the models again (a new
        Pipeline would, inside the timed pass): the tracker's state and each person's
        features and last decisions, which would otherwise carry over to whoever gets
        their identity in the next sequence."""
        self.pipeline.reset()

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


def options(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--model", choices=("lite", "full", "heavy", "full-int8"), default="full")
    ap.add_argument("--detector", choices=("float", "int8"), default="float")
    ap.add_argument(
        "--window-detector",
        choices=("float", "int8"),
        default=None,
        help="the detector on the search's zooms and tiles (default: --detector's)",
    )
    ap.add_argument("--runtime", choices=("cpu", "openvino"), default="cpu")
    ap.add_argument("--spin", action="store_true", help="threads spin-wait within a run")
    ap.add_argument(
        "--search",
        choices=("tiles", "whole-frame"),
        default="tiles",
        help="while no one is tracked: the tile cascade (ours) or the whole frame only "
        "(MediaPipe's way)",
    )
    ap.add_argument(
        "--people", action="store_true", help="follow everyone in view (PeopleConfig())"
    )


def main() -> None:
    run(worker_args(__doc__.split("\n")[0], options), OurRunner, "monopic")


if __name__ == "__main__":
    main()
