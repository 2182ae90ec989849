"""Which detection is which tracked person: one-to-one by box overlap (Hungarian method).

Each person's expected box (their motion's prediction, or this frame's pose) against each
detection's box; scipy's linear_sum_assignment maximises the summed similarity. The
similarity is the boxes' overlap (IoU); a pair overlapping less than `min_iou` still
counts, as `min_iou`, when the centres lie within NEAR of the boxes' height and the
heights agree within HEIGHT_RATIO (a small person walking fast, seen again after the
landmark budget skipped them, has moved more than their own width); anything else is no
pair (two people a step apart stay two people).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from monopic.people.box import Box
from monopic.pose.detector import iou

MIN_IOU = 0.3
NEAR = 0.35  # centre distance, in heights
HEIGHT_RATIO = 1.5


@dataclass(frozen=True)
class Assignment:
    pairs: list[tuple[int, int]]  # (track index, detection index)
    lone_tracks: list[int]
    lone_detections: list[int]


def associate(tracks: list[Box], detections: list[Box], min_iou: float = MIN_IOU) -> Assignment:
    if not tracks or not detections:
        return Assignment([], list(range(len(tracks))), list(range(len(detections))))
    similar = np.array([[similarity(t, d, min_iou) for d in detections] for t in tracks])
    rows, cols = linear_sum_assignment(-similar)
    pairs = [(int(r), int(c)) for r, c in zip(rows, cols, strict=True) if similar[r, c] >= min_iou]
    paired_t = {r for r, _ in pairs}
    paired_d = {c for _, c in pairs}
    return Assignment(
        pairs,
        [i for i in range(len(tracks)) if i not in paired_t],
        [j for j in range(len(detections)) if j not in paired_d],
    )


def similarity(a: Box, b: Box, min_iou: float = MIN_IOU) -> float:
    """The boxes' IoU, or `min_iou` for boxes near each other of about one height."""
    overlap = iou(a, b)
    if overlap >= min_iou:
        return overlap
    ha, hb = a[3] - a[1], b[3] - b[1]
    if min(ha, hb) <= 0 or max(ha, hb) / min(ha, hb) > HEIGHT_RATIO:
        return overlap
    dx = (a[0] + a[2] - b[0] - b[2]) / 2
    dy = (a[1] + a[3] - b[1] - b[3]) / 2
    return min_iou if np.hypot(dx, dy) <= NEAR * (ha + hb) / 2 else overlap
