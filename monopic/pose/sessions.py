"""onnxruntime sessions with an explicit thread budget.

Parallel sweep workers each run their own pipeline; sessions that spin-wait or take every
core would fight, so the thread count is always explicit (sweep workers use one).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import onnxruntime as ort

DETECTOR_FILE = "pose_detection.onnx"
# MediaPipe's three landmark models (its model_complexity 0, 1, 2), all converted by
# `make models` from MediaPipe's own files (monopic/pose/models/NOTICE.md says where each
# comes from). Full is the one the paper and MediaPipe's Pose solution use by default.
LANDMARK_MODELS = {
    "lite": "pose_landmark_lite.onnx",
    "full": "pose_landmark_full.onnx",
    "heavy": "pose_landmark_heavy.onnx",
}
DEFAULT_LANDMARK_MODEL = "full"
LANDMARK_FILE = LANDMARK_MODELS[DEFAULT_LANDMARK_MODEL]


def landmark_file(model: str) -> str:
    """The shipped file of landmark model `model` (lite, full or heavy)."""
    try:
        return LANDMARK_MODELS[model]
    except KeyError:
        raise ValueError(
            f"unknown landmark model {model!r}: choose one of {', '.join(LANDMARK_MODELS)}"
        ) from None


def model_path(name: str) -> Path:
    """Path of a model shipped inside the package (monopic/pose/models/)."""
    path = Path(str(resources.files("monopic.pose") / "models" / name))
    if not path.is_file():
        raise FileNotFoundError(
            f"pose model {path} is missing: reinstall the package or run `make models`"
        )
    return path


def make_session(path: Path, threads: int = 1, spin: bool = False) -> ort.InferenceSession:
    """A CPU session using exactly `threads` intra-op threads.

    `spin` lets a multi-threaded session's idle threads spin-wait between runs. On a
    quiet host that saved the landmark model 7 % at 2 threads (7.8 vs 8.3 ms per frame,
    issue 7); on a loaded one it cost 1.6x (45 vs 27 ms, alternated, load average 11,
    issue 21) and burns CPU time between frames, so no session spins by default. Never
    for two sessions that take turns: each one's spinning threads then hold the cores
    the other needs (the detector ran 2x slower right after a spinning landmark
    session). One thread has no pool: nothing spins.
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = threads
    opts.inter_op_num_threads = 1
    opts.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    spinning = "1" if spin and threads > 1 else "0"
    opts.add_session_config_entry("session.intra_op.allow_spinning", spinning)
    if threads > 1:  # smaller blocks, taken dynamically: a delayed thread does less
        opts.add_session_config_entry("session.dynamic_block_base", "4")
    opts.add_session_config_entry("session.inter_op.allow_spinning", "0")
    return ort.InferenceSession(str(path), sess_options=opts, providers=["CPUExecutionProvider"])
