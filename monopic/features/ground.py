"""Ground-plane motion in the robot's frame with the robot's own motion taken out.

A moving camera makes a standing pedestrian appear to approach. The robot knows its own
speed and yaw rate, so it integrates them into an odometry pose, tracks the pedestrian's
foot point in that fixed odometry frame (a Kalman filter, `ground_track`, fed each foot
point with its pixel noise carried onto the ground), and rotates position and velocity
back into its current frame. The result is the pedestrian's own ground velocity.

Beside the track, the measurements it believed also go into a short window fit
(`window.GroundKinematics`) for the intent features: speed, acceleration along the
walking direction and heading rate. The track's own outputs do not depend on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from monopic.features.ground_track import GroundTrack, GroundTrackConfig
from monopic.features.window import GroundKinematics, Kinematics, KinematicsConfig
from monopic.frame import EgoState


@dataclass
class Odometry:
    """Dead-reckoned robot pose (x, y, yaw) in a fixed frame from speed and yaw rate."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    t: float | None = None

    def update(self, t: float, ego: EgoState) -> None:
        if self.t is not None:
            dt = t - self.t
            mid = self.yaw + 0.5 * ego.yaw_rate * dt
            self.x += ego.speed * math.cos(mid) * dt
            self.y += ego.speed * math.sin(mid) * dt
            self.yaw += ego.yaw_rate * dt
        self.t = t

    def to_fixed(self, p: tuple[float, float]) -> tuple[float, float]:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return (self.x + c * p[0] - s * p[1], self.y + s * p[0] + c * p[1])

    def rotate_to_robot(self, v: tuple[float, float]) -> tuple[float, float]:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return (c * v[0] + s * v[1], -s * v[0] + c * v[1])

    def to_robot(self, p: tuple[float, float]) -> tuple[float, float]:
        """A fixed-frame point in the robot's current frame (inverse of `to_fixed`)."""
        return self.rotate_to_robot((p[0] - self.x, p[1] - self.y))

    def rotation(self) -> np.ndarray:
        """Robot-frame vectors to fixed-frame vectors."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([[c, -s], [s, c]])


@dataclass
class GroundMotion:
    """Own ground position and velocity of a tracked foot point, from a moving robot."""

    config: GroundTrackConfig = field(default_factory=GroundTrackConfig)
    odometry: Odometry = field(default_factory=Odometry)
    kinematics_config: KinematicsConfig = field(default_factory=KinematicsConfig)
    _track: GroundTrack = field(init=False)
    _kinematics: GroundKinematics = field(init=False)

    def __post_init__(self) -> None:
        self._track = GroundTrack(self.config)
        self._kinematics = GroundKinematics(self.kinematics_config)

    def observe_ego(self, t: float, ego: EgoState) -> None:
        """Advance odometry; call on every frame, with or without a pedestrian."""
        self.odometry.update(t, ego)

    def update(
        self, t: float, ego: EgoState, foot_px: tuple[float, float], apparent_height: float = 0.0
    ) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """(position, own velocity) in the robot's current frame, or None above the horizon.

        `apparent_height` (px) sets the foot point's pixel noise: a big, near person's
        landmarks jitter by more pixels than a small, far one's.
        """
        row_noise, column_noise = self._pixel_noise(apparent_height)
        measured = foot_on_ground(
            ego, foot_px, row_noise, self.config.min_position_noise, column_noise
        )
        if measured is None:
            return None
        g, cov = measured
        rot = self.odometry.rotation()
        z = np.array(self.odometry.to_fixed((float(g[0]), float(g[1]))))
        R = rot @ cov @ rot.T
        starts = self._track.starts
        if self._track.update(t, z, R):  # the window believes what the track believes
            if self._track.starts != starts:
                self._kinematics.reset()  # a restart: another person, or a jump
            self._kinematics.add(t, z, R)
        p, v = self._track.position, self._track.velocity
        position = self.odometry.to_robot((float(p[0]), float(p[1])))
        return position, self.odometry.rotate_to_robot((float(v[0]), float(v[1])))

    def kinematics(self) -> Kinematics:
        """The window fit's speed, along-track acceleration and heading rate, read at the
        window's centre (`Kinematics.age` seconds before the newest measurement)."""
        return self._kinematics.estimate()

    def reset_track(self) -> None:
        self._track.reset()
        self._kinematics.reset()

    def _pixel_noise(self, apparent_height: float) -> tuple[float, float | None]:
        """The foot point's pixel noise (px): the row's, and the column's when it has its own."""
        c = self.config
        h = apparent_height if math.isfinite(apparent_height) and apparent_height > 0 else 0.0
        column = None
        if c.column_pixel_noise is not None:
            column = c.column_pixel_noise + c.column_pixel_noise_per_height * h
        return c.pixel_noise + c.pixel_noise_per_height * h, column


def foot_on_ground(
    ego: EgoState,
    foot_px: tuple[float, float],
    pixel_noise: float,
    min_noise: float = 0.05,
    column_noise: float | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """The ground point under a foot pixel and its covariance (robot frame, m and m^2).

    The covariance is the pixel noise (the row's `pixel_noise`, the column's
    `column_noise`, the same when None) carried through the ground projection (its
    Jacobian by central differences), so it stretches along the line of sight with range.
    None when the pixel or its neighbourhood sees no ground (at the horizon).
    """
    u, v = foot_px
    e = 0.5
    pts = np.array([[u, v], [u + e, v], [u - e, v], [u, v + e], [u, v - e]], dtype=float)
    g = ego.camera.ground_point(pts)
    if not np.all(np.isfinite(g)):
        return None
    J = np.column_stack([(g[1] - g[2]) / (2 * e), (g[3] - g[4]) / (2 * e)])
    if column_noise is None:  # isotropic: as before the column had its own noise, bit for bit
        cov = pixel_noise**2 * (J @ J.T) + min_noise**2 * np.eye(2)
    else:
        cov = J @ np.diag([column_noise**2, pixel_noise**2]) @ J.T + min_noise**2 * np.eye(2)
    return g[0], cov
