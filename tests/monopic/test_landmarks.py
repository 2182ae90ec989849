"""The landmark stage: MediaPipe's heatmap refinement and its wiring into LandmarkModel."""

from __future__ import annotations

import numpy as np
import onnxruntime as ort
import pytest

from monopic.pose.landmarks import (
    HEATMAP_KERNEL,
    HEATMAP_MIN_CONFIDENCE,
    INPUT_SIZE,
    NUM_POINTS,
    LandmarkModel,
    refine_from_heatmap,
)
from monopic.pose.region import Region
from monopic.pose.sessions import LANDMARK_FILE, model_path
from tests.paths import DATA

FIXTURE = DATA / "pose_reference.npz"
SIZE = 256
CELLS = 64  # heatmap side: one cell is SIZE / CELLS = 4 crop pixels
CELL = SIZE / CELLS


def empty_heatmap(channels: int = 3) -> np.ndarray:
    """Logits of -inf: confidence exactly 0 everywhere."""
    return np.full((CELLS, CELLS, channels), -np.inf, dtype=np.float32)


def loop_refine(points: np.ndarray, heatmap: np.ndarray, size: int) -> np.ndarray:
    """A line-by-line port of refine_landmarks_from_heatmap_calculator.cc, as the oracle."""
    hh, hw, channels = heatmap.shape
    out = points.astype(np.float64).copy()
    off = (HEATMAP_KERNEL - 1) // 2
    for i in range(min(channels, len(points))):
        col, row = int(points[i, 0] / size * hw), int(points[i, 1] / size * hh)
        if col < 0 or col >= hw or row < 0 or row >= hh:
            continue
        total = wcol = wrow = peak = 0.0
        for r in range(max(0, row - off), min(hh, row + off + 1)):
            for c in range(max(0, col - off), min(hw, col + off + 1)):
                conf = 1.0 / (1.0 + np.exp(-float(heatmap[r, c, i])))
                total += conf
                peak = max(peak, conf)
                wcol += c * conf
                wrow += r * conf
        if peak >= HEATMAP_MIN_CONFIDENCE and total > 0:
            out[i] = (wcol / hw / total * size, wrow / hh / total * size)
    return out


def test_a_confident_peak_pulls_the_point_onto_its_cell() -> None:
    heatmap = empty_heatmap()
    heatmap[20, 30, 0] = 5.0  # channel 0: one confident cell at row 20, column 30
    points = np.array([[32.5 * CELL, 22.2 * CELL], [10.0, 10.0], [100.0, 100.0]])
    out = refine_from_heatmap(points, heatmap, SIZE)
    # Cell (row 20, col 30) is 2 columns and 2 rows away: inside the 7x7 window.
    np.testing.assert_allclose(out[0], [30 * CELL, 20 * CELL], atol=1e-9)
    np.testing.assert_array_equal(out[1:], points[1:])  # channels 1, 2: no confidence


def test_two_equal_peaks_give_their_midpoint() -> None:
    heatmap = empty_heatmap(1)
    heatmap[10, 10, 0] = heatmap[12, 14, 0] = 2.0
    out = refine_from_heatmap(np.array([[12 * CELL, 11 * CELL]]), heatmap, SIZE)
    np.testing.assert_allclose(out[0], [12 * CELL, 11 * CELL], atol=1e-9)
    heatmap[12, 14, 0] = 0.0  # weights sigmoid(2) : sigmoid(0) pull towards (10, 10)
    out = refine_from_heatmap(np.array([[12 * CELL, 11 * CELL]]), heatmap, SIZE)
    w = 1 / (1 + np.exp(-2.0))
    expected = (w * np.array([10, 10]) + 0.5 * np.array([14, 12])) / (w + 0.5) * CELL
    np.testing.assert_allclose(out[0], expected, atol=1e-9)


def test_below_min_confidence_leaves_the_point_unchanged() -> None:
    heatmap = empty_heatmap(1)
    point = np.array([[33.0 * CELL + 1.0, 40.0 * CELL + 2.0]])
    heatmap[41, 34, 0] = -0.01  # sigmoid 0.4975 < 0.5
    np.testing.assert_array_equal(refine_from_heatmap(point, heatmap, SIZE), point)
    heatmap[41, 34, 0] = 0.0  # sigmoid 0.5: refines (the calculator's test is >=)
    np.testing.assert_allclose(
        refine_from_heatmap(point, heatmap, SIZE)[0], [34 * CELL, 41 * CELL], atol=1e-9
    )


def test_a_point_off_the_map_is_unchanged_even_next_to_a_peak() -> None:
    heatmap = np.zeros((CELLS, CELLS, 4), dtype=np.float32)  # confidence 0.5 everywhere
    points = np.array([[-4.5, 100.0], [100.0, -4.5], [SIZE + 0.5, 100.0], [100.0, SIZE + 0.5]])
    np.testing.assert_array_equal(refine_from_heatmap(points, heatmap, SIZE), points)
    # Truncation toward zero, as C++ int(): -0.5 px is still cell 0, on the map.
    assert refine_from_heatmap(np.array([[-0.5, 100.0]]), heatmap, SIZE)[0, 0] > 0


def test_points_without_a_heatmap_channel_are_unchanged() -> None:
    heatmap = np.zeros((CELLS, CELLS, 1), dtype=np.float32)
    points = np.array([[50.0, 50.0], [60.0, 60.0]])
    out = refine_from_heatmap(points, heatmap, SIZE)
    assert not np.array_equal(out[0], points[0])
    np.testing.assert_array_equal(out[1], points[1])


def test_matches_a_port_of_the_mediapipe_loop_on_random_maps() -> None:
    rng = np.random.default_rng(7)
    heatmap = rng.normal(-3.0, 3.0, (CELLS, CELLS, NUM_POINTS)).astype(np.float32)
    for _ in range(20):
        # Inside, on the border and off the map alike.
        points = rng.uniform(-20.0, SIZE + 20.0, (NUM_POINTS, 2))
        points[:4] = [[0.0, 0.0], [SIZE - 0.01, SIZE - 0.01], [-0.9, 3.0], [3.0, SIZE]]
        got = refine_from_heatmap(points, heatmap, SIZE)
        np.testing.assert_allclose(got, loop_refine(points, heatmap, SIZE), atol=1e-9)
    moved = ~np.all(got == points, axis=1)
    assert 5 < moved.sum() < NUM_POINTS  # both branches exercised


def test_landmark_model_returns_the_refined_points() -> None:
    """LandmarkModel.run = raw model output -> refinement -> image pixels."""
    with np.load(FIXTURE) as data:
        image = data["pose_landmark_full.input"][0]  # the fixture's person, 256x256
    region = Region(cx=INPUT_SIZE / 2, cy=INPUT_SIZE / 2, side=INPUT_SIZE, rotation=0.0)
    model = LandmarkModel()
    crop = region.crop(image, INPUT_SIZE)
    np.testing.assert_array_equal(crop, image)  # the region is the identity

    raw_session = ort.InferenceSession(
        str(model_path(LANDMARK_FILE)), providers=["CPUExecutionProvider"]
    )
    points, heatmap = raw_session.run(
        ["landmarks", "heatmap"], {"image": (image.astype(np.float32) / 255.0)[None]}
    )
    raw = points.reshape(NUM_POINTS, 5)[:, :2].astype(np.float64)
    refined = refine_from_heatmap(raw, heatmap[0].transpose(1, 2, 0), INPUT_SIZE)
    pose = model.run(image, region)
    got = np.vstack([pose.landmarks[:, :2], pose.aux])
    np.testing.assert_allclose(got, refined, atol=1e-3)
    # The photo shows head and shoulders: those 13 points (0-12) are confident enough to
    # move, by a few pixels (the regression and the heatmap agree that closely).
    shift = np.linalg.norm(refined[:13] - raw[:13], axis=1)
    assert np.all(shift > 0.1), shift
    assert np.median(shift) < 4.0, shift


def test_a_model_without_a_heatmap_output_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    class NoHeatmap:
        def __init__(self, session: ort.InferenceSession) -> None:
            self.inner = session

        def get_inputs(self) -> list[ort.NodeArg]:
            return self.inner.get_inputs()

        def get_outputs(self) -> list[ort.NodeArg]:
            return [o for o in self.inner.get_outputs() if o.name != "heatmap"]

    import monopic.pose.landmarks as landmarks

    real = landmarks.make_session
    monkeypatch.setattr(landmarks, "make_session", lambda *a, **kw: NoHeatmap(real(*a, **kw)))
    with pytest.raises(ValueError, match="heatmap"):
        LandmarkModel()


def test_runs_into_kept_outputs_leave_earlier_poses_untouched() -> None:
    """The outputs are written into kept arrays (an I/O binding): each run's pose equals a
    fresh model's, and a later run does not change a pose already returned."""
    with np.load(FIXTURE) as data:
        image = data["pose_landmark_full.input"][0]
    regions = [
        Region(cx=INPUT_SIZE / 2, cy=INPUT_SIZE / 2, side=INPUT_SIZE, rotation=0.0),
        Region(cx=INPUT_SIZE / 2 + 9, cy=INPUT_SIZE / 2 - 5, side=INPUT_SIZE * 0.8, rotation=0.3),
    ]
    kept = LandmarkModel()
    first = kept.run(image, regions[0])
    snapshot = first.landmarks.copy(), first.visibility.copy(), first.aux.copy()
    second = kept.run(image, regions[1])
    for got, region in ((first, regions[0]), (second, regions[1])):
        want = LandmarkModel().run(image, region)
        np.testing.assert_array_equal(got.landmarks, want.landmarks)
        np.testing.assert_array_equal(got.visibility, want.visibility)
        np.testing.assert_array_equal(got.presence, want.presence)
        np.testing.assert_array_equal(got.aux, want.aux)
        assert got.score == want.score
    assert not np.array_equal(first.landmarks, second.landmarks)
    for before, after in zip(snapshot, (first.landmarks, first.visibility, first.aux), strict=True):
        np.testing.assert_array_equal(before, after)


def test_a_model_whose_output_shape_is_not_fixed_is_refused(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from types import SimpleNamespace

    class BatchFree:
        def __init__(self, session: ort.InferenceSession) -> None:
            self.inner = session

        def get_inputs(self) -> list[ort.NodeArg]:
            return self.inner.get_inputs()

        def get_outputs(self) -> list[SimpleNamespace]:
            return [
                SimpleNamespace(name=o.name, shape=["batch", *o.shape[1:]])
                for o in self.inner.get_outputs()
            ]

    import monopic.pose.landmarks as landmarks

    real = landmarks.make_session
    monkeypatch.setattr(landmarks, "make_session", lambda *a, **kw: BatchFree(real(*a, **kw)))
    with pytest.raises(ValueError, match=r"pose_landmark_full\.onnx: output 'landmarks' has "
                       r"shape \['batch', 195\]; a fixed shape is needed"):  # fmt: skip
        LandmarkModel()
