"""The shipped BlazePose ONNX files reproduce the original MediaPipe TFLite models.

``tests/data/pose_reference.npz`` holds the original TFLite models' outputs on fixed
inputs (written by ``tools/models/convert.py``; its ``doc`` entry explains the layout).
Tolerances are ~15-50x the differences measured with onnxruntime 1.31 at conversion
time (see ``monopic/pose/models/NOTICE.md``), to absorb CPU kernel differences while
still catching a wrong conversion, a wrong input scaling or a swapped output. The
landmark models (lite, full, heavy) are shipped pruned to the outputs monopic reads; the
fixture holds those, for each of the three on the same inputs.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import numpy as np
import onnxruntime as ort
import pytest

from monopic.pose.sessions import RUNTIMES, make_session, runtime_unavailable
from tests.paths import ROOT

MODELS = ROOT / "monopic" / "pose" / "models"
FIXTURE = ROOT / "tests" / "data" / "pose_reference.npz"

# Detector (224 px input scale). Box/keypoint regressors are in input pixels: measured
# max 6.0e-4 px, i.e. 3e-6 of the 224 px frame.
DETECTOR_BOX_TOL_PX = 0.01
# Detector scores are logits (sigmoid them): measured max 3.1e-4.
DETECTOR_SCORE_TOL_LOGIT = 5e-3
# Landmark x, y in 256 px crop pixels, all 39 points: measured max 3.4e-4 px.
LANDMARK_XY_TOL_PX = 0.01
# Landmark z (crop pixel scale, relative to the hips): measured max 9.7e-4.
LANDMARK_Z_TOL_PX = 0.02
# Visibility / presence logits: measured max 7.4e-5.
LANDMARK_VIS_TOL_LOGIT = 1e-3
# Pose flag is already a probability: measured max 6.5e-7.
POSE_FLAG_TOL = 1e-4
# Heatmap logits (range about -40..3): measured max 3.8e-4.
HEATMAP_TOL_LOGIT = 5e-3

DETECTOR = "pose_detection"
LANDMARKS = ("pose_landmark_lite", "pose_landmark_full", "pose_landmark_heavy")
SCALE: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    DETECTOR: lambda u8: u8.astype(np.float32) / 127.5 - 1.0,  # RGB in [-1, 1]
} | {name: (lambda u8: u8.astype(np.float32) / 255.0) for name in LANDMARKS}  # RGB in [0, 1]
N_IMAGES = 2  # image 0: a person (Grace Hopper), image 1: seeded synthetic blobs


@cache
def fixture() -> dict[str, np.ndarray]:
    with np.load(FIXTURE, allow_pickle=False) as data:
        return {key: data[key] for key in data.files}


@cache
def session(model: str, runtime: str = "cpu") -> ort.InferenceSession:
    if runtime == "cpu":
        opts = ort.SessionOptions()
        opts.intra_op_num_threads = 1
        opts.inter_op_num_threads = 1
        return ort.InferenceSession(
            str(MODELS / f"{model}.onnx"), opts, providers=["CPUExecutionProvider"]
        )
    return make_session(MODELS / f"{model}.onnx", 1, runtime=runtime)  # as the pipeline does


# Every runtime the pipeline offers must reproduce the TFLite models within the same
# tolerances; the optional one is skipped, saying so, where its extra is not installed.
UNAVAILABLE = {r: runtime_unavailable(r) for r in RUNTIMES}  # why not, asked once each
RUNTIME_PARAMS = [
    pytest.param(
        r,
        marks=pytest.mark.skipif(UNAVAILABLE[r] is not None, reason=str(UNAVAILABLE[r])),
    )
    for r in RUNTIMES
]


@cache
def run(model: str, index: int, runtime: str = "cpu") -> dict[str, np.ndarray]:
    """ONNX outputs for one fixture image (batch dim dropped), subsampled like the fixture."""
    sess = session(model, runtime)
    image = SCALE[model](fixture()[f"{model}.input"][index])[None]
    names = [o.name for o in sess.get_outputs()]
    outs = dict(zip(names, (o[0] for o in sess.run(names, {"image": image})), strict=True))
    if "heatmap" in outs:
        outs["heatmap"] = outs["heatmap"].transpose(1, 2, 0)  # TFLite's (H, W, C)
    for name in names:
        stride_key = f"{model}.{name}.stride"
        if stride_key in fixture():
            stride = int(fixture()[stride_key])
            outs[name] = outs[name][::stride, ::stride]
    return outs


def reference(model: str, output: str, index: int) -> np.ndarray:
    return fixture()[f"{model}.{output}"][index]


def sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.clip(x.astype(np.float64), -100.0, 100.0)))


def max_err(a: np.ndarray, b: np.ndarray) -> float:
    assert a.shape == b.shape
    return float(np.abs(a.astype(np.float64) - b.astype(np.float64)).max())


def test_detector_signature() -> None:
    det = session(DETECTOR)
    assert [(i.name, i.shape) for i in det.get_inputs()] == [("image", [1, 224, 224, 3])]
    assert [(o.name, o.shape) for o in det.get_outputs()] == [
        ("box_regressors", [1, 2254, 12]),
        ("scores", [1, 2254, 1]),
    ]


@pytest.mark.parametrize("model", LANDMARKS)
def test_landmark_signature(model: str) -> None:
    lmk = session(model)
    assert [(i.name, i.shape) for i in lmk.get_inputs()] == [("image", [1, 256, 256, 3])]
    # Exactly the outputs monopic reads: the unpruned conversion also has `segmentation`
    # and `world_landmarks`, whose branches onnxruntime would run on every frame.
    assert [(o.name, o.shape) for o in lmk.get_outputs()] == [
        ("landmarks", [1, 195]),
        ("pose_flag", [1, 1]),
        ("heatmap", [1, 39, 64, 64]),  # channels first: the fixture keeps TFLite's NHWC
    ]


@pytest.mark.parametrize("model", LANDMARKS)
def test_fixture_is_meaningful(model: str) -> None:
    """Image 0 must really show a person, or the landmark comparison proves little."""
    assert sigmoid(reference(DETECTOR, "scores", 0)).max() > 0.5
    # Pose flags on the photo: lite 0.89, full 0.996, heavy 0.99998; the blobs below 0.06.
    assert reference(model, "pose_flag", 0)[0] > 0.8
    assert reference(model, "pose_flag", 1)[0] < 0.2


@pytest.mark.parametrize("runtime", RUNTIME_PARAMS)
@pytest.mark.parametrize("index", range(N_IMAGES))
def test_detector_matches_tflite(index: int, runtime: str) -> None:
    got = run(DETECTOR, index, runtime)
    assert max_err(got["box_regressors"], reference(DETECTOR, "box_regressors", index)) <= (
        DETECTOR_BOX_TOL_PX
    )
    assert max_err(got["scores"], reference(DETECTOR, "scores", index)) <= (
        DETECTOR_SCORE_TOL_LOGIT
    )


@pytest.mark.parametrize("runtime", RUNTIME_PARAMS)
@pytest.mark.parametrize("model", LANDMARKS)
@pytest.mark.parametrize("index", range(N_IMAGES))
def test_landmarks_match_tflite(model: str, index: int, runtime: str) -> None:
    got = run(model, index, runtime)["landmarks"].reshape(39, 5)
    ref = reference(model, "landmarks", index).reshape(39, 5)
    assert max_err(got[:, :2], ref[:, :2]) <= LANDMARK_XY_TOL_PX
    assert max_err(got[:, 2], ref[:, 2]) <= LANDMARK_Z_TOL_PX
    assert max_err(got[:, 3:], ref[:, 3:]) <= LANDMARK_VIS_TOL_LOGIT


@pytest.mark.parametrize("runtime", RUNTIME_PARAMS)
@pytest.mark.parametrize("model", LANDMARKS)
@pytest.mark.parametrize("index", range(N_IMAGES))
def test_other_landmark_outputs_match_tflite(model: str, index: int, runtime: str) -> None:
    got = run(model, index, runtime)
    assert max_err(got["pose_flag"], reference(model, "pose_flag", index)) <= POSE_FLAG_TOL
    assert max_err(got["heatmap"], reference(model, "heatmap", index)) <= HEATMAP_TOL_LOGIT
