"""A person's bounding box (head top to feet, arm to arm) from a pose or from a detection.

Multi-person tracking associates people by their boxes, and a MOTChallenge evaluation
scores those boxes, so both sources give the same kind of box:
- from a pose: the 33 landmarks span eyes to toes; the head top lies about 7 % of that
  height above the eyes (anthropometric tables put the eyes at about 0.93 of stature),
  the soles about 1 % below the toe and heel points. The width is not the landmarks'
  spread (a swinging arm, or a small person's noisy wrist, doubles it) but the
  pedestrian boxes' usual aspect, 0.41 of the height (the Caltech pedestrian
  benchmark's standard), centred on the hips;
- from the detector: BlazePose's detector gives no body box (its box is the face's), but
  its mid-hip keypoint and full-body radius r do: on the shipped walking clip the
  landmark box ran from 0.83 r above the hips to 0.95 r below them (medians over 20
  frames, tools: the pose tracker beside the detector), centred on the mid-hip keypoint,
  with the same aspect.
"""

from __future__ import annotations

import math

import numpy as np

from monopic.pose.detector import Detection
from monopic.pose.landmarks import Pose

Box = tuple[float, float, float, float]  # xmin, ymin, xmax, ymax in pixels

HEAD_TOP = 0.07  # of the landmark box's height, above it
SOLE = 0.01  # below it
ABOVE_HIPS = 0.83  # landmark box top above the detector's mid-hip, in full-body radii
BELOW_HIPS = 0.95
ASPECT = 0.41  # width / height of a pedestrian's box


def around(centre_x: float, top: float, bottom: float) -> Box:
    """A person's box from their landmark span's top and bottom (eyes, toes) and centre."""
    span = bottom - top
    top, bottom = top - HEAD_TOP * span, bottom + SOLE * span
    half_width = ASPECT * (bottom - top) / 2
    return centre_x - half_width, top, centre_x + half_width, bottom


def pose_box(pose: Pose) -> Box:
    _, top, _, bottom = pose.box
    return around(hips(pose)[0], top, bottom)


def detection_box(det: Detection) -> Box:
    (hx, hy), scale_point = det.keypoints[0], det.keypoints[1]
    r = float(np.hypot(*(scale_point - det.keypoints[0])))
    return around(float(hx), float(hy) - ABOVE_HIPS * r, float(hy) + BELOW_HIPS * r)


def valid(box: Box) -> bool:
    return all(math.isfinite(v) for v in box) and box[2] > box[0] and box[3] > box[1]


def hips(pose: Pose) -> tuple[float, float]:
    """The mid-hip point, where the pose sits in its box (landmarks 23 and 24)."""
    x, y = pose.landmarks[23:25, :2].mean(axis=0)
    return float(x), float(y)
