"""BlazePose landmark model (lite, full or heavy; full by default) run on a rotated region.

The model sees the region as 256x256 RGB in [0, 1] and returns 39 points x (x, y, z,
visibility logit, presence logit) in crop pixels: the 33 landmarks, then auxiliary points
whose first two (33 centre, 34 scale/rotation) give the next frame's region. z is in the
same scale as x; we return it in image pixels like x. The pose flag says whether a person
is in the crop at all. As in MediaPipe's pose graph, x and y are then refined from the
model's 64x64 heatmap output (`refine_from_heatmap`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from monopic.pose.region import DEFAULT_SCALE, Region
from monopic.pose.sessions import (
    DEFAULT_LANDMARK_MODEL,
    DEFAULT_RUNTIME,
    landmark_file,
    make_session,
    model_path,
)
from monopic.pose.skeleton import NUM_LANDMARKS
from monopic.pose.warp import WarpBuffers

INPUT_SIZE = 256
NUM_POINTS = 39
# MediaPipe's pose landmark graph runs RefineLandmarksFromHeatmapCalculator with
# kernel_size 7 and the default min_confidence_to_refine 0.5.
HEATMAP_KERNEL = 7
HEATMAP_MIN_CONFIDENCE = 0.5
_WINDOW = np.arange(-(HEATMAP_KERNEL // 2), HEATMAP_KERNEL // 2 + 1)  # cell offsets


@dataclass(frozen=True)
class Pose:
    """One person's landmarks in image pixels."""

    landmarks: np.ndarray  # (33, 3): x, y in pixels; z in pixels (x scale), hips ~ 0
    visibility: np.ndarray  # (33,) probability the point is visible
    presence: np.ndarray  # (33,) probability the point is in the frame
    score: float  # pose flag: probability a person is in the region
    region: Region  # the crop the landmarks came from
    aux: np.ndarray  # (6, 2) auxiliary points in pixels (0 centre, 1 scale point)

    @property
    def box(self) -> tuple[float, float, float, float]:
        """Bounding box of the 33 landmarks (xmin, ymin, xmax, ymax)."""
        xy = self.landmarks[:, :2]
        (x0, y0), (x1, y1) = xy.min(axis=0).tolist(), xy.max(axis=0).tolist()
        return x0, y0, x1, y1

    @property
    def height(self) -> float:
        """Apparent height: vertical extent of the landmarks in pixels."""
        y = self.landmarks[:, 1]
        return float(y.max() - y.min())

    def next_region(self, scale: float = DEFAULT_SCALE) -> Region:
        """The region to crop in the next frame, from the auxiliary points."""
        return Region.from_keypoints(tuple(self.aux[0]), tuple(self.aux[1]), scale)


class LandmarkModel:
    def __init__(
        self,
        threads: int = 1,
        model: str = DEFAULT_LANDMARK_MODEL,
        runtime: str = DEFAULT_RUNTIME,
        spin: bool = False,
    ) -> None:
        # The three models share inputs and outputs; only size and accuracy differ.
        self.model = model
        file = landmark_file(model)
        # Spinning only when asked: on a shared host it costs far more than it saves
        # (sessions.make_session).
        self.session = make_session(model_path(file), threads, spin=spin, runtime=runtime)
        self.input_name = self.session.get_inputs()[0].name
        # Outputs are told apart by shape: landmarks (1, 195), pose flag (1, 1), heatmap
        # (1, 39, 64, 64): channels first, as the converted files keep it (NOTICE.md).
        names: dict[str, str] = {}
        for out in self.session.get_outputs():
            dims = [d for d in out.shape if isinstance(d, int)]
            size = int(np.prod(dims))
            if size == NUM_POINTS * 5:
                names["points"] = out.name
            elif size == 1:
                names["flag"] = out.name
            elif len(out.shape) == 4 and out.shape[1] == NUM_POINTS:
                names["heatmap"] = out.name
        if missing := {"points", "flag", "heatmap"} - names.keys():
            raise ValueError(f"{file} lacks the {sorted(missing)} output(s)")
        self.output_names = [names["points"], names["flag"], names["heatmap"]]
        # The crop and the model's input, written in place frame after frame (warp.py).
        self._buffers = WarpBuffers.of((INPUT_SIZE, INPUT_SIZE))
        self._tensor = np.empty((1, INPUT_SIZE, INPUT_SIZE, 3), np.float32)
        # The outputs too: onnxruntime writes them into kept arrays (an I/O binding), so a
        # run neither allocates them nor copies the 640 kB heatmap out (62-65 us a run on
        # the AVX-512 EPYC at 1 and 2 threads, bench/io_binding.py; the same values).
        declared = {o.name: o.shape for o in self.session.get_outputs()}
        self._outputs = [
            np.empty(_fixed(file, n, declared[n]), np.float32) for n in self.output_names
        ]
        self._binding = self.session.io_binding()
        for name, out in zip(self.output_names, self._outputs, strict=True):
            self._binding.bind_output(name, "cpu", 0, out.dtype, list(out.shape), out.ctypes.data)

    def run(self, image: np.ndarray, region: Region) -> Pose:
        crop = region.crop(image, INPUT_SIZE, self._buffers)
        # Cast and scale in one pass into the input buffer: each value float32(v) *
        # float32(1 / 255), as a cast then a scale.
        np.multiply(crop, np.float32(1.0 / 255.0), out=self._tensor[0], dtype=np.float32)
        self._infer()
        points, flag, heatmap = self._outputs
        pts = points.reshape(NUM_POINTS, 5).astype(np.float64)
        # (H, W, C) view of the channels-first map: no copy, the refinement gathers 7x7.
        pts[:, :2] = refine_from_heatmap(pts[:, :2], heatmap[0].transpose(1, 2, 0), INPUT_SIZE)
        xy = region.to_image(pts[:, :2], INPUT_SIZE)
        z = pts[:, 2] * (region.side / INPUT_SIZE)
        lm = np.column_stack([xy[:NUM_LANDMARKS], z[:NUM_LANDMARKS]])
        # Visibility and presence in one pass, each row contiguous.
        probability = _sigmoid(np.ascontiguousarray(pts[:NUM_LANDMARKS, 3:5].T))
        return Pose(
            landmarks=lm,
            visibility=probability[0],
            presence=probability[1],
            score=float(_flag_probability(float(np.ravel(flag)[0]))),
            region=region,
            aux=xy[NUM_LANDMARKS:],
        )

    def _infer(self) -> None:
        """Run the model on the input buffer into the kept output arrays.

        The input is bound before every run (under 1 us): OpenVINO's plug-in copies an
        input when it is bound, so a binding made once ran every crop as the array stood
        then (landmarks 80-100 px off the CPU runtime's; tests/monopic/test_tracker.py).
        """
        self._binding.bind_cpu_input(self.input_name, self._tensor)
        self.session.run_with_iobinding(self._binding)


def refine_from_heatmap(points: np.ndarray, heatmap: np.ndarray, size: int) -> np.ndarray:
    """MediaPipe's heatmap refinement of crop-pixel (x, y), vectorised.

    The reference pipeline (MediaPipe Pose) refines the regressed coordinates this way,
    and on the shipped clip it brings our shoulders closer to the truth (median 3.9 ->
    2.8 px, `bench/compare_reference.py`). As MediaPipe's
    mediapipe/calculators/util/refine_landmarks_from_heatmap_calculator.cc: a point
    whose heatmap cell (x / size * width truncated toward zero, as C++ int()) lies on
    the map is replaced by the sigmoid-weighted mean cell position over the 7x7 window
    around that cell (cut at the border), if the window's peak confidence reaches 0.5;
    otherwise, or off the map, it is left as is. Like the calculator, the result is
    the weighted cell index / width * size, without a half-cell offset.

    points: (N, 2) x, y in pixels of the size x size crop; heatmap: (H, W, C) logits,
    channel i for point i (the first min(N, C) points are refined). Returns a copy.
    """
    hh, hw, channels = heatmap.shape
    k = min(channels, len(points))
    dims, last = _map_bounds(hw, hh)  # (2,) and (2, 1): columns, rows
    # Few, whole-array steps: right after a model run each numpy call costs 10-40 us here
    # (cold code; bench/cold_paths.py), many times its cost in a loop of its own.
    cell = (points[:k, :2] / size * dims).astype(int)  # (k, 2) column, row; a cast truncates
    centre = np.minimum(np.maximum(cell, 0), last[:, 0])
    inside = (cell == centre).all(axis=1)
    # The k windows' columns and rows, (k, 2, 7), around the cell moved onto the map; cells
    # off the map get confidence 0 (the calculator cuts its window there instead, which
    # sums the same).
    win = centre[:, :, None] + _WINDOW
    at = np.minimum(np.maximum(win, 0), last)
    on = at == win
    # One gather from the channels-first map (no copy when `heatmap` is the model output's
    # (H, W, C) view): faster than indexing the strided view.
    chw = np.ascontiguousarray(heatmap.transpose(2, 0, 1))
    logits = chw[_channel_index(k), at[:, 1, :, None], at[:, 0, None, :]].astype(np.float64)
    with np.errstate(over="ignore"):  # exp(huge) -> inf -> confidence 0
        conf = np.where(on[:, 1, :, None] & on[:, 0, None, :], 1.0 / (1.0 + np.exp(-logits)), 0.0)
    total = conf.sum(axis=(1, 2))
    positive = total > 0
    ok = inside & (conf.max(axis=(1, 2)) >= HEATMAP_MIN_CONFIDENCE) & positive
    # Column then row weights, (k, 2, 7): the weighted mean cell of each, x and y at once.
    weights = np.stack((conf.sum(axis=1), conf.sum(axis=2)), axis=1)
    mean = (weights * win).sum(axis=2) / np.where(positive, total, 1.0)[:, None]
    out = np.array(points, dtype=np.float64)
    out[:k] = np.where(ok[:, None], mean / dims * size, out[:k])
    return out


def _fixed(file: str, name: str, shape: list[int | str | None]) -> tuple[int, ...]:
    """An output's declared shape, which must be fixed for its array to be kept."""
    if not all(isinstance(d, int) and d > 0 for d in shape):
        raise ValueError(f"{file}: output {name!r} has shape {shape}; a fixed shape is needed")
    return tuple(int(d) for d in shape)


@functools.lru_cache(maxsize=4)
def _map_bounds(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(width, height) and their last cells as a column, built once per map size."""
    dims = np.array([width, height])
    return dims, (dims - 1)[:, None]


@functools.lru_cache(maxsize=4)
def _channel_index(k: int) -> np.ndarray:
    """(k, 1, 1) channel numbers, built once: the refinement's gather index."""
    return np.arange(k)[:, None, None]


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.clip(x, -100, 100)))


def _flag_probability(value: float) -> float:
    """The converted model emits the pose flag already as a probability."""
    return value
