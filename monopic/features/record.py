"""The feature record: what the feature stage hands every predictor for one frame.

A field is added here when a predictor needs it; every field carries its units.
"""

from __future__ import annotations

from dataclasses import dataclass

from monopic.camera import CameraModel

Point = tuple[float, float]
_NAN = float("nan")


@dataclass(frozen=True)
class GroundFeatures:
    """The pedestrian's foot point on the ground, in the robot's current frame."""

    position: Point  # (forward, left) metres
    velocity: Point  # the pedestrian's own ground velocity (forward, left), m/s
    camera: CameraModel  # the robot's own camera, to draw ground predictions on the image
    # Intent features (window.GroundKinematics: a 1 s fit read at its centre, about 0.5 s
    # ago; not the track above, which the constant-velocity baseline reads); NaN until
    # the window is full enough.
    speed: float = _NAN  # m/s over the ground
    acceleration: float = _NAN  # m/s^2 along the walking direction (< 0 slowing)
    heading_rate: float = _NAN  # deg/s, > 0 turning left (counter-clockwise from above)
    # Against the robot's swept path (swept_path.py): the band of its width along x.
    path_offset: float = _NAN  # m, signed from the path's centre line, + left
    path_distance: float = _NAN  # m, lateral distance to the band's nearer edge, 0 inside


@dataclass(frozen=True)
class Features:
    """Motion features of the tracked pedestrian at one frame.

    Image quantities are pixels (u right, v down) and px/s; phi is the paper's facing
    angle in degrees (smoothed); `ground` is present only when the camera model is known.
    Intent features after `phi_raw` default to NaN (not computed), so a record built
    without them means what it meant before they existed.
    """

    timestamp: float
    center: Point
    foot: Point
    apparent_height: float  # px, vertical extent of the landmarks
    phi: float
    vx: float
    vy: float
    ground: GroundFeatures | None = None
    phi_raw: float = _NAN
    phi_rate: float = _NAN  # deg/s, least-squares slope of the smoothed phi over 0.5 s
    head_yaw: float = _NAN  # deg, head from the shoulders, + to the person's left (head.py)
    head_visibility: float = _NAN  # 0-1, min visibility of the ears and shoulders
    head_facing: float = _NAN  # deg, the head's facing from the camera, image x only (head.py)
    head_toward: float = _NAN  # deg, head turned toward the camera over the last ~1 s
