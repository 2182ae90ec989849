"""The paper's reference pipeline as a benchmark worker (runs in .venv-reference).

MediaPipe's Python Pose solution (mediapipe 0.10.14, mp.solutions.pose.Pose with
static_image_mode=False, model_complexity=1: tracking mode, the full landmark model; 0
and 2 with --model lite / heavy, whose files bench/reference_env.py puts in place) and
then the authors' rule cascade. The cascade, its smoothing and the warning are monopic's
own pure-Python modules (monopic.features.orientation/.smoothing/.motion,
monopic.predict.rules, monopic.variants.warning/.path: numpy only, they import fine
here), so the stage after pose is the same code on both sides and the comparison
isolates the pose stage.

Threads: the Pose solution gives no thread option. Its two InferenceCalculatorCpu nodes
run TFLite with the XNNPACK delegate, whose thread count defaults to 1 on Linux desktop
builds; we set `delegate.xnnpack.num_threads` on both nodes of the canonical graph
config before the graph starts (patching SolutionBase._modify_calculator_options, the
one hook the solution calls with that config). The interpreter's own `cpu_num_thread`
stays at its default: XNNPACK runs the whole model, and a second spinning pool only
burnt CPU in a trial (2 threads: 600 ms CPU per frame under load). With --pin the
process is also confined to that many cores, like our worker.

    .venv-reference/bin/python -m bench.reference_worker --frames FRAMES.npy --threads 1
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

from bench.worker_common import run, worker_args

MIN_FOOT_VISIBILITY = 0.5  # as monopic.features.extractor
COMPLEXITY = {"lite": 0, "full": 1, "heavy": 2}  # MediaPipe's model_complexity
MAX_GAP_S = 0.5


def set_xnnpack_threads(threads: int) -> None:
    """Make every InferenceCalculator of solutions built after this use `threads` threads."""
    from mediapipe.calculators.tensor import inference_calculator_pb2
    from mediapipe.python import solution_base

    ext = inference_calculator_pb2.InferenceCalculatorOptions.ext
    original = solution_base.SolutionBase._modify_calculator_options

    def patched(self: Any, config: Any, params: Any) -> None:
        found = 0
        for node in config.node:
            if node.calculator.startswith("InferenceCalculator") and node.HasField("options"):
                opts = node.options.Extensions[ext]
                opts.delegate.xnnpack.num_threads = threads
                found += 1
        if found == 0:
            raise RuntimeError("no InferenceCalculator found: cannot set the thread count")
        original(self, config, params)

    solution_base.SolutionBase._modify_calculator_options = patched


class ReferenceRunner:
    """MediaPipe Pose (tracking) + the authors' cascade with monopic's feature code."""

    def __init__(self, args: argparse.Namespace) -> None:
        set_xnnpack_threads(args.threads)
        import mediapipe as mp

        from monopic.features.motion import VelocityEstimator
        from monopic.features.orientation import facing_angle
        from monopic.features.record import Features
        from monopic.features.smoothing import Kalman1D
        from monopic.predict.base import Mode
        from monopic.predict.rules import RulePredictor
        from monopic.variants.path import project_path
        from monopic.variants.warning import CollisionWarning

        self.pose = mp.solutions.pose.Pose(
            static_image_mode=False,
            model_complexity=COMPLEXITY[args.model],
            smooth_landmarks=not args.no_smooth,
        )
        self._velocity_cls, self._kalman_cls = VelocityEstimator, Kalman1D
        self._facing, self._features, self._mode = facing_angle, Features, Mode.IMAGE
        self.predictor, self.warning = RulePredictor(), CollisionWarning()
        self._project = project_path
        self.reset()

    def reset(self) -> None:
        self.pose.reset()
        self.velocity = self._velocity_cls(4, 4)
        self.kalman = self._kalman_cls()
        self.last_seen: float | None = None

    def process(
        self, image: np.ndarray, timestamp: float, index: int
    ) -> tuple[dict[str, float], np.ndarray | None]:
        h, w = image.shape[:2]
        t0 = time.perf_counter()
        image.flags.writeable = False  # MediaPipe's advice: pass by reference
        res = self.pose.process(image)
        lm = vis = None
        if res.pose_landmarks is not None:
            pts = res.pose_landmarks.landmark
            lm = np.array([(p.x * w, p.y * h, p.z * w) for p in pts], dtype=float)
            vis = np.array([p.visibility for p in pts], dtype=float)
        t1 = time.perf_counter()
        self._post(timestamp, lm, vis, w, h)
        t2 = time.perf_counter()
        stages = {"pose": (t1 - t0) * 1e3, "post": (t2 - t1) * 1e3}
        return stages, None if lm is None else lm[:, :2]

    def _post(
        self, t: float, lm: np.ndarray | None, vis: np.ndarray | None, w: int, h: int
    ) -> None:
        """What monopic.features.extractor + the pipeline do after pose, without ego state."""
        gap = self.last_seen is not None and t - self.last_seen > MAX_GAP_S
        if gap:
            self.velocity.reset()
            self.kalman.reset()
        if lm is None or vis is None:
            return
        self.last_seen = t
        x0, y0 = float(lm[:, 0].min()), float(lm[:, 1].min())
        x1, y1 = float(lm[:, 0].max()), float(lm[:, 1].max())
        center = ((x0 + x1) / 2, (y0 + y1) / 2)
        feet = [i for i in (27, 28, 29, 30, 31, 32) if vis[i] >= MIN_FOOT_VISIBILITY]
        if len(feet) >= 2 and np.all(lm[feet, 1] < h):
            foot = (float(lm[feet, 0].mean()), float(lm[feet, 1].max()))
        else:
            foot = ((x0 + x1) / 2, y1)
        phi_raw = self._facing(lm[11], lm[12])
        phi = self.kalman.update(phi_raw)
        vx, vy = self.velocity.update(t, *center)
        feats = self._features(
            timestamp=t,
            center=center,
            foot=foot,
            apparent_height=y1 - y0,
            phi=phi,
            vx=vx,
            vy=vy,
            phi_raw=phi_raw,
        )
        pred = self.predictor.predict(feats, 1.0)
        warn = self.warning.assess(feats, pred, self._mode, (w, h), None)
        self._project(feats, pred, warn.zone)


def options(ap: argparse.ArgumentParser) -> None:
    ap.add_argument(
        "--no-smooth", action="store_true", help="smooth_landmarks=False (default: True)"
    )
    ap.add_argument("--model", choices=list(COMPLEXITY), default="full")


def main() -> None:
    args = worker_args(__doc__.split("\n")[0], options)
    run(args, ReferenceRunner, "mediapipe-0.10.14")


if __name__ == "__main__":
    main()
