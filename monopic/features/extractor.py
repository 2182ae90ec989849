"""Pose -> motion features, frame after frame, as the authors' pipeline computes them."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from monopic.features.ground import GroundMotion
from monopic.features.ground_track import GroundTrackConfig
from monopic.features.head import MIN_HEAD_VISIBILITY, HeadTurnWindow, head_facing, head_yaw
from monopic.features.motion import VelocityEstimator
from monopic.features.orientation import facing_angle
from monopic.features.record import Features, GroundFeatures
from monopic.features.smoothing import Kalman1D
from monopic.features.swept_path import path_offset
from monopic.features.window import KinematicsConfig, SlidingWindow, angle_rate
from monopic.frame import EgoState
from monopic.pose.landmarks import Pose
from monopic.pose.skeleton import (
    FOOT_LANDMARKS,
    LEFT_HIP,
    LEFT_SHOULDER,
    RIGHT_HIP,
    RIGHT_SHOULDER,
)

# Landmarks (feet, hips, shoulders) below this visibility are not trusted for the ground point.
MIN_FOOT_VISIBILITY = 0.5
# The default robot's width, m: monopic.variants.zone.RobotGeometry's (the pipeline passes
# its own robot's; features cannot import the variants above them).
DEFAULT_ROBOT_WIDTH = 0.6


class GroundColumn(StrEnum):
    """Which landmarks give the ground point's image column (its row is always the feet's).

    The feet alternate with each step and one of them is often hidden, so their mean
    column swings by a step's width; the hips (the body's centre of mass) and the
    shoulders move with the walker's body, not its stride. Hips by default: on the intent
    sweep (192 human-walker runs) the ground track's near-miss warnings fell from 33 to 29
    of 96 and its nuisance warnings from 431 to 258 an hour at the same recall
    (docs/intent/ground-tree.md).
    """

    FEET = "feet"
    HIPS = "hips"
    SHOULDERS = "shoulders"


# The column the pipeline uses unless told otherwise (FeatureExtractor, PipelineConfig).
DEFAULT_GROUND_COLUMN = GroundColumn.HIPS

_COLUMN_PAIRS = {
    GroundColumn.HIPS: (LEFT_HIP, RIGHT_HIP),
    GroundColumn.SHOULDERS: (LEFT_SHOULDER, RIGHT_SHOULDER),
}


_FOOT_INDEX = np.array(FOOT_LANDMARKS)


def foot_point(
    pose: Pose, image_height: int, column: GroundColumn = GroundColumn.FEET
) -> tuple[float, float]:
    """Where the pedestrian stands on the image.

    The lowest visible ankle/heel/toe row at the mean column of the visible foot points;
    when the feet are not visible (cut off by the frame, occluded), the bottom of the
    landmark box under its centre. With `column` hips or shoulders, the column is that
    pair's midpoint when both are visible (else as above).
    """
    idx = _FOOT_INDEX[pose.visibility[_FOOT_INDEX] >= MIN_FOOT_VISIBILITY]
    pts = pose.landmarks[idx, :2]
    if len(idx) >= 2 and np.all(pts[:, 1] < image_height):
        u, v = float(pts[:, 0].mean()), float(pts[:, 1].max())
    else:
        x0, _, x1, y1 = pose.box
        u, v = (x0 + x1) / 2, y1
    pair = _COLUMN_PAIRS.get(column)
    if pair is not None and min(pose.visibility[i] for i in pair) >= MIN_FOOT_VISIBILITY:
        left, right = pair
        u = (float(pose.landmarks[left, 0]) + float(pose.landmarks[right, 0])) / 2  # np.mean's
    return u, v


@dataclass
class FeatureExtractor:
    """Stateful per-track feature computation; reset it when the track is lost for long."""

    velocity_window: int = 4  # image velocity, as the authors compute it
    velocity_average: int = 4
    ground_track: GroundTrackConfig = field(default_factory=GroundTrackConfig)
    max_gap: float = 0.5  # seconds without a pose before the track's history is dropped
    phi_filter: Kalman1D = field(default_factory=Kalman1D)
    # Intent features: none of them feeds today's predictors.
    kinematics: KinematicsConfig = field(default_factory=KinematicsConfig)
    phi_rate_window: float = 0.5  # s: a shoulder turn leading a walking turn takes ~0.5 s
    robot_width: float = DEFAULT_ROBOT_WIDTH  # m, the swept path's width
    ground_column: GroundColumn = DEFAULT_GROUND_COLUMN  # the ground point's image column
    min_head_visibility: float = MIN_HEAD_VISIBILITY
    _image_velocity: VelocityEstimator = field(init=False)
    _ground: GroundMotion = field(init=False)
    _phi_history: SlidingWindow = field(init=False)
    _head_turn: HeadTurnWindow = field(default_factory=HeadTurnWindow, init=False)
    _last_seen: float | None = field(default=None, init=False)

    def __post_init__(self) -> None:
        self._image_velocity = VelocityEstimator(self.velocity_window, self.velocity_average)
        self._ground = GroundMotion(self.ground_track, kinematics_config=self.kinematics)
        self._phi_history = SlidingWindow(self.phi_rate_window)

    def update(
        self, timestamp: float, pose: Pose | None, image_height: int, ego: EgoState | None = None
    ) -> Features | None:
        """Features for this frame, or None when no pedestrian is seen."""
        if ego is not None:
            self._ground.observe_ego(timestamp, ego)
        if pose is None:
            if self._last_seen is not None and timestamp - self._last_seen > self.max_gap:
                self._reset_track()
            return None
        if self._last_seen is not None and timestamp - self._last_seen > self.max_gap:
            self._reset_track()
        self._last_seen = timestamp

        x0, y0, x1, y1 = pose.box
        center = ((x0 + x1) / 2, (y0 + y1) / 2)
        foot = foot_point(pose, image_height, self.ground_column)
        phi_raw = facing_angle(pose.landmarks[LEFT_SHOULDER], pose.landmarks[RIGHT_SHOULDER])
        phi = self.phi_filter.update(phi_raw)
        self._phi_history.add(timestamp, phi)
        vx, vy = self._image_velocity.update(timestamp, *center)
        head = head_yaw(pose.landmarks, pose.visibility, self.min_head_visibility)
        facing = head_facing(pose.landmarks, pose.visibility, self.min_head_visibility)
        head_toward = self._head_turn.update(timestamp, facing)
        ground = None
        if ego is not None:
            g = self._ground.update(timestamp, ego, foot, pose.height)
            if g is not None:
                k = self._ground.kinematics()
                side = path_offset(g[0], self.robot_width)
                ground = GroundFeatures(
                    position=g[0],
                    velocity=g[1],
                    camera=ego.camera,
                    speed=k.speed,
                    acceleration=k.acceleration,
                    heading_rate=k.heading_rate,
                    path_offset=side.offset,
                    path_distance=side.distance,
                )
        return Features(
            timestamp=timestamp,
            center=center,
            foot=foot,
            apparent_height=pose.height,
            phi=phi,
            vx=vx,
            vy=vy,
            ground=ground,
            phi_raw=phi_raw,
            phi_rate=angle_rate(self._phi_history),
            head_yaw=head.yaw,
            head_visibility=head.visibility,
            head_facing=facing,
            head_toward=head_toward,
        )

    def _reset_track(self) -> None:
        self._image_velocity.reset()
        self._ground.reset_track()
        self.phi_filter.reset()
        self._phi_history.reset()
        self._head_turn.reset()
