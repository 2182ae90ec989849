"""BlazePose person detector (pose_detection.onnx) with letterboxing, decoding and NMS.

MediaPipe's wiring (pose_detection_cpu.pbtxt): the window is letterboxed to 224x224,
values in [-1, 1]; each of 2254 anchors regresses box centre, width, height and four
keypoints (0 mid-hip, 1 full-body size/rotation, 2 mid-shoulder, 3 upper-body), scaled
by 224; scores are sigmoid(clip(logit, -100, 100)); weighted non-max suppression at
IoU 0.3. Far pedestrians are too small for the whole frame squeezed into 224 px, so the
detector can also run on windows of the frame (monopic.pose.search).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor, wait
from dataclasses import dataclass

import cv2
import numpy as np
from onnxruntime import InferenceSession

from monopic.pose.anchors import INPUT_SIZE, ssd_anchor_centres
from monopic.pose.region import DEFAULT_SCALE, Region
from monopic.pose.search import Faint, SearchSteps, Window
from monopic.pose.sessions import (
    DEFAULT_DETECTOR_MODEL,
    DEFAULT_RUNTIME,
    detector_file,
    make_session,
    model_path,
)
from monopic.pose.warp import warp

MIN_SCORE = 0.5
NMS_IOU = 0.3


@dataclass(frozen=True)
class Detection:
    """A detected person in image pixels."""

    score: float
    box: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
    keypoints: np.ndarray  # (4, 2): mid-hip, full-body scale, mid-shoulder, upper-body scale

    def region(self, scale: float = DEFAULT_SCALE) -> Region:
        """The landmark model's crop for this person, from the mid-hip and full-body
        scale keypoints (as Pose.next_region does from the auxiliary points)."""
        return Region.from_keypoints(tuple(self.keypoints[0]), tuple(self.keypoints[1]), scale)


class PoseDetector:
    """Runs the detector on windows of a frame and returns detections in frame pixels."""

    def __init__(
        self,
        threads: int = 1,
        min_score: float = MIN_SCORE,
        runtime: str = DEFAULT_RUNTIME,
        model: str = DEFAULT_DETECTOR_MODEL,
        spin: bool = False,
        zoom_score: float | None = None,
        region_scale: float = DEFAULT_SCALE,
        window_model: str | None = None,
    ) -> None:
        # Both detector models share inputs and outputs (monopic.pose.sessions).
        path = model_path(detector_file(model))
        self.session = make_session(path, threads, spin=spin, runtime=runtime)
        # `window_model` runs on the windows smaller than the frame (the search's zooms and
        # tiles, for walkers the whole frame cannot see), `model` on the whole frame; by
        # default `model` on both.
        window_path = model_path(detector_file(model if window_model is None else window_model))
        self._window_session = (
            self.session
            if window_path == path
            else make_session(window_path, threads, spin=spin, runtime=runtime)
        )
        # A frame's windows are independent passes: with more than one thread they run side
        # by side, one single-threaded pass per thread (onnxruntime runs a session from
        # several threads at once, each on its caller's thread), rather than one after
        # another with each pass split across the threads, which scales poorly on the
        # detector's small maps. The same outputs bit for bit (test). CPU runtime only.
        self._threads = threads
        self._tiles: ThreadPoolExecutor | None = None
        if threads > 1 and runtime == "cpu":
            self._tile_session = make_session(path, 1, runtime=runtime)
            self._window_tile_session = (
                self._tile_session
                if window_path == path
                else make_session(window_path, 1, runtime=runtime)
            )
            self._tiles = ThreadPoolExecutor(threads, thread_name_prefix="tiles")
            weakref.finalize(self, self._tiles.shutdown, wait=False)
        self.input_name = self.session.get_inputs()[0].name
        outputs = self.session.get_outputs()
        by_width = {o.shape[-1]: o.name for o in outputs}
        self.regressor_name, self.score_name = by_width[12], by_width[1]
        self.anchors = ssd_anchor_centres()
        self.min_score = min_score
        # A window with no detection reports its best anchor scoring at least this (and
        # the region its keypoints give, at region_scale); None reports none.
        self.zoom_score = zoom_score
        self.region_scale = region_scale

    def detect(self, image: np.ndarray, windows: list[Window] | None = None) -> list[Detection]:
        """All detections, best first, after weighted NMS across every window, one window
        after another (`detect_first` runs windows side by side)."""
        h, w = image.shape[:2]
        windows = windows or [Window(0, 0, w, h)]
        found = [
            det for win in windows for det in self._look(image, win, self._session(image, win))[0]
        ]
        return weighted_nms(found, NMS_IOU)

    def detect_first(
        self,
        image: np.ndarray,
        steps: SearchSteps,
        accept: Callable[[list[Detection]], bool] = bool,
    ) -> tuple[list[Detection], int]:
        """The detections (weighted NMS within the window) of the first window `steps`
        gives whose detections `accept` takes (by default: any), or none; and the detector
        passes spent. Each window that finds no one tells `steps` its faint candidate.

        One thread: window after window. More: one single-threaded pass per thread, the
        windows `steps` would give next running beside the current one (the whole frame
        beside the first tile); results are read in `steps`' order, so the detections and
        what `steps` learns are the same either way; only the passes spent (at most
        threads - 1 more) and the time differ.
        """
        if self._tiles is None:
            runs = 0
            while (win := steps.next()) is not None:
                runs += 1
                dets, faint = self.look(image, win)
                if dets and accept(dets):
                    return dets, runs
                steps.learn(faint)
            return [], runs
        running: dict[Window, Future] = {}
        runs = 0

        def start(win: Window) -> None:
            nonlocal runs
            if win not in running:
                session = self._session(image, win, pooled=True)
                running[win] = self._tiles.submit(self._look, image, win, session)
                runs += 1

        try:
            while (win := steps.next()) is not None:
                start(win)
                for ahead in steps.upcoming(self._threads):
                    if len(running) >= self._threads:
                        break
                    start(ahead)
                raw, faint = running.pop(win).result()
                dets = weighted_nms(raw, NMS_IOU)
                if dets and accept(dets):
                    return dets, runs
                steps.learn(faint)
            return [], runs
        finally:
            wait(running.values())  # let no pass run on beside the landmark model

    def look(self, image: np.ndarray, win: Window) -> tuple[list[Detection], Faint | None]:
        """One detector pass on `win`: its detections after weighted NMS, and, when there
        are none, its best anchor if that reaches the zoom's threshold (a faint candidate)."""
        raw, faint = self._look(image, win, self._session(image, win))
        return weighted_nms(raw, NMS_IOU), faint

    def _session(self, image: np.ndarray, win: Window, pooled: bool = False) -> InferenceSession:
        """The session for `win`: the window model's unless it is the whole frame; with
        `pooled`, the single-threaded twin a pool thread runs."""
        h, w = image.shape[:2]
        whole = (win.x, win.y, win.width, win.height) == (0, 0, w, h)
        if pooled:
            return self._tile_session if whole else self._window_tile_session
        return self.session if whole else self._window_session

    def _look(
        self, image: np.ndarray, win: Window, session: InferenceSession
    ) -> tuple[list[Detection], Faint | None]:
        """The window's detections before NMS, and its faint candidate when it has none."""
        tensor, to_frame = letterbox(image, win, INPUT_SIZE)
        raw_boxes, raw_scores = session.run(
            [self.regressor_name, self.score_name], {self.input_name: tensor[None]}
        )
        boxes = raw_boxes.reshape(-1, 12)
        logits = np.clip(raw_scores.reshape(-1).astype(np.float64), -100.0, 100.0)
        scores = 1.0 / (1.0 + np.exp(-logits))
        keep = np.flatnonzero(scores >= self.min_score)
        dets = [self._decode(boxes[i], float(scores[i]), i, to_frame) for i in keep]
        if dets or self.zoom_score is None:
            return dets, None
        best = int(np.argmax(scores))
        if scores[best] < self.zoom_score:
            return [], None
        region = self._decode(boxes[best], float(scores[best]), best, to_frame).region(
            self.region_scale
        )
        return [], Faint(float(scores[best]), region) if region.valid else None

    def _decode(self, box: np.ndarray, score: float, anchor: int, to_frame) -> Detection:
        ax, ay = self.anchors[anchor]
        r = box / INPUT_SIZE
        cx, cy, bw, bh = r[0] + ax, r[1] + ay, r[2], r[3]
        kps = r[4:12].reshape(4, 2) + (ax, ay)
        corners = to_frame(np.array([[cx - bw / 2, cy - bh / 2], [cx + bw / 2, cy + bh / 2]]))
        return Detection(
            score=score,
            box=(corners[0, 0], corners[0, 1], corners[1, 0], corners[1, 1]),
            keypoints=to_frame(kps),
        )


def letterbox(image: np.ndarray, win: Window, size: int):
    """The window resized into size x size keeping its aspect (centred, zero padding).

    `image` is RGB or, cheaper to warp, its four-channel form (monopic.pose.warp).

    Returns the float32 NHWC-less tensor in [-1, 1] and a function mapping normalised
    [0, 1] tensor coordinates back to frame pixels.
    """
    scale = size / max(win.width, win.height)
    pad_x = (size - win.width * scale) / 2
    pad_y = (size - win.height * scale) / 2
    # frame pixel -> tensor pixel: t = (p - win.origin) * scale + pad (continuous coords)
    m = np.array(
        [[scale, 0.0, pad_x - win.x * scale], [0.0, scale, pad_y - win.y * scale]],
        dtype=np.float64,
    )
    m_idx = m.copy()
    m_idx[:, 2] += 0.5 * scale - 0.5  # sample at pixel centres
    resized = warp(image, m_idx, (size, size), cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR)
    # Cast, then scale and shift in place: no temporaries.
    tensor = resized.astype(np.float32)
    tensor *= np.float32(2.0 / 255.0)
    tensor -= np.float32(1.0)

    def to_frame(norm: np.ndarray) -> np.ndarray:
        t = np.asarray(norm, dtype=float) * size
        return (t - (pad_x, pad_y)) / scale + (win.x, win.y)

    return tensor, to_frame


def iou(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> float:
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def weighted_nms(dets: list[Detection], threshold: float) -> list[Detection]:
    """MediaPipe's weighted NMS: each kept detection is the score-weighted mean of its cluster."""
    remaining = sorted(dets, key=lambda d: -d.score)
    kept: list[Detection] = []
    while remaining:
        top = remaining[0]
        overlaps = [i == 0 or iou(top.box, d.box) > threshold for i, d in enumerate(remaining)]
        cluster = [d for d, o in zip(remaining, overlaps, strict=True) if o]
        others = [d for d, o in zip(remaining, overlaps, strict=True) if not o]
        w = np.array([d.score for d in cluster])
        box = np.average(np.array([d.box for d in cluster]), axis=0, weights=w)
        kps = np.average(np.stack([d.keypoints for d in cluster]), axis=0, weights=w)
        kept.append(Detection(top.score, tuple(float(v) for v in box), kps))
        remaining = others
    return kept
