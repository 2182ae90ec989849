"""The feature record: what the feature stage hands every predictor for one frame.

A field is added here when a predictor needs it; every field carries its units.
"""

from __future__ import annotations

from dataclasses import dataclass

from monopic.camera import CameraModel

Point = tuple[float, float]


@dataclass(frozen=True)
class GroundFeatures:
    """The pedestrian's foot point on the ground, in the robot's current frame."""

    position: Point  # (forward, left) metres
    velocity: Point  # the pedestrian's own ground velocity (forward, left), m/s
    camera: CameraModel  # the robot's own camera, to draw ground predictions on the image


@dataclass(frozen=True)
class Features:
    """Motion features of the tracked pedestrian at one frame.

    Image quantities are pixels (u right, v down) and px/s; phi is the paper's facing
    angle in degrees (smoothed); `ground` is present only when the camera model is known.
    """

    timestamp: float
    center: Point
    foot: Point
    apparent_height: float  # px, vertical extent of the landmarks
    phi: float
    vx: float
    vy: float
    ground: GroundFeatures | None = None
    phi_raw: float = float("nan")
