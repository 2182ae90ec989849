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
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
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
        # A frame's windows are independent passes: with more than one thread they run side
        # by side, one single-threaded pass per thread (onnxruntime runs a session from
        # several threads at once, each on its caller's thread), rather than one after
        # another with each pass split across the threads, which scales poorly on the
        # detector's small maps. The same outputs bit for bit (test). CPU runtime only.
        self._threads = threads
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
        """All detections, best first, after weighted NMS across every window, one window
        after another (`detect_first` runs windows side by side)."""
        h, w = image.shape[:2]
        windows = windows or [Window(0, 0, w, h)]
        found = [det for win in windows for det in self._detect_window(image, win, self.session)]
        return weighted_nms(found, NMS_IOU)

    def detect_first(
        self,
        image: np.ndarray,
        batches: list[list[Window]],
        accept: Callable[[list[Detection]], bool] = bool,
    ) -> tuple[list[Detection], int]:
        """The detections of the first batch of windows whose detections (weighted NMS
        within the batch, as `detect`) `accept` takes (by default: any), or none; and the
        detector passes spent.

        One thread: batch after batch, stopping at the first that finds someone. More:
        the windows go in order to one single-threaded pass per thread, so the next
        batch's first windows run beside the current batch (the whole frame beside the
        first tile); when a batch finds someone, the passes already running are waited
        for and counted, and no more start. The detections are the same either way; only
        the passes spent (at most threads - 1 more) and the time differ.
        """
        windows = [(b, win) for b, batch in enumerate(batches) for win in batch]
        if self._tiles is None or len(windows) < 2:
            runs = 0
            for batch in batches:
                runs += len(batch)
                dets = self.detect(image, batch)
                if dets and accept(dets):
                    return dets, runs
            return [], runs
        results: list[list[Detection] | None] = [None] * len(windows)
        running: dict[Future, int] = {}
        queued = 0  # windows handed to the passes so far

        def top_up(end: int) -> None:  # one pass per thread, in window order, up to `end`
            nonlocal queued
            while queued < min(end, len(windows)) and len(running) < self._threads:
                win = windows[queued][1]
                job = self._tiles.submit(self._detect_window, image, win, self._tile_session)
                running[job] = queued
                queued += 1

        for b in range(len(batches)):
            members = [k for k, (bb, _) in enumerate(windows) if bb == b]
            while any(results[k] is None for k in members):
                top_up(members[-1] + self._threads)  # at most threads - 1 windows ahead
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for job in done:
                    results[running.pop(job)] = job.result()
            dets = weighted_nms([d for k in members for d in results[k] or []], NMS_IOU)
            if dets and accept(dets):
                wait(running)  # let no pass run on beside the landmark model
                return dets, queued
        return [], queued

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
