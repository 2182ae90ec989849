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
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import cv2
import numpy as np
from onnxruntime import InferenceSession

from monopic.pose.anchors import INPUT_SIZE, ssd_anchor_centres
from monopic.pose.search import Window
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


class PoseDetector:
    """Runs the detector on windows of a frame and returns detections in frame pixels."""

    def __init__(
        self,
        threads: int = 1,
        min_score: float = MIN_SCORE,
        runtime: str = DEFAULT_RUNTIME,
        model: str = DEFAULT_DETECTOR_MODEL,
        spin: bool = False,
    ) -> None:
        # Both detector models share inputs and outputs (monopic.pose.sessions).
        path = model_path(detector_file(model))
        self.session = make_session(path, threads, spin=spin, runtime=runtime)
        # A frame's tiles are independent passes: with more than one thread, they run side
        # by side, one single-threaded pass per thread (onnxruntime runs a session from
        # several threads at once, each on its caller's thread), rather than one after
        # another with each pass split across the threads, which scales poorly on the
        # detector's small maps. The same outputs bit for bit (test). CPU runtime only.
        self._tiles: ThreadPoolExecutor | None = None
        if threads > 1 and runtime == "cpu":
            self._tile_session = make_session(path, 1, runtime=runtime)
            self._tiles = ThreadPoolExecutor(threads, thread_name_prefix="tiles")
            weakref.finalize(self, self._tiles.shutdown, wait=False)
        self.input_name = self.session.get_inputs()[0].name
        outputs = self.session.get_outputs()
        by_width = {o.shape[-1]: o.name for o in outputs}
        self.regressor_name, self.score_name = by_width[12], by_width[1]
        self.anchors = ssd_anchor_centres()
        self.min_score = min_score

    def detect(self, image: np.ndarray, windows: list[Window] | None = None) -> list[Detection]:
        """All detections, best first, after weighted NMS across every window."""
        h, w = image.shape[:2]
        windows = windows or [Window(0, 0, w, h)]
        if len(windows) > 1 and self._tiles is not None:
            session = self._tile_session
            per_window = list(
                self._tiles.map(lambda w: self._detect_window(image, w, session), windows)
            )
        else:
            per_window = [self._detect_window(image, win, self.session) for win in windows]
        found = [det for dets in per_window for det in dets]  # in window order, as before
        return weighted_nms(found, NMS_IOU)

    def _detect_window(
        self, image: np.ndarray, win: Window, session: InferenceSession
    ) -> list[Detection]:
        tensor, to_frame = letterbox(image, win, INPUT_SIZE)
        raw_boxes, raw_scores = session.run(
            [self.regressor_name, self.score_name], {self.input_name: tensor[None]}
        )
        boxes = raw_boxes.reshape(-1, 12)
        logits = np.clip(raw_scores.reshape(-1).astype(np.float64), -100.0, 100.0)
        scores = 1.0 / (1.0 + np.exp(-logits))
        keep = np.flatnonzero(scores >= self.min_score)
        out = []
        for i in keep:
            ax, ay = self.anchors[i]
            r = boxes[i] / INPUT_SIZE
            cx, cy, bw, bh = r[0] + ax, r[1] + ay, r[2], r[3]
            kps = r[4:12].reshape(4, 2) + (ax, ay)
            corners = to_frame(np.array([[cx - bw / 2, cy - bh / 2], [cx + bw / 2, cy + bh / 2]]))
            out.append(
                Detection(
                    score=float(scores[i]),
                    box=(corners[0, 0], corners[0, 1], corners[1, 0], corners[1, 1]),
                    keypoints=to_frame(kps),
                )
            )
        return out


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
