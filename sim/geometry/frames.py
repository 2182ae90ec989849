"""The simulator's world frame and its link to the robot frame of monopic.camera.

World frame (MuJoCo's): metres, x east, y north, z up, right-handed, ground at z = 0.
Headings (yaw) are radians counter-clockwise from east, so yaw 0 faces east and
yaw pi/2 faces north. A robot pose (x, y, yaw) puts the origin of monopic's robot frame
(x forward, y left, z up, on the ground) at world (x, y, 0) with its x axis along yaw.
Everything the pipeline is allowed to know is expressed in that robot frame; the
simulator keeps the world frame and converts here, in one place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Pose2D:
    """A position on the ground and a heading: world x, y (m), yaw (rad, CCW from east)."""

    x: float
    y: float
    yaw: float

    def rotation(self) -> np.ndarray:
        """3x3 rotation from this pose's local frame (x forward, y left, z up) to world."""
        return yaw_matrix(self.yaw)

    def to_local(self, points_world: np.ndarray) -> np.ndarray:
        """World points (..., 3) into the pose's local frame (..., 3)."""
        p = np.asarray(points_world, dtype=float) - np.array([self.x, self.y, 0.0])
        return p @ self.rotation()

    def to_world(self, points_local: np.ndarray) -> np.ndarray:
        """Local points (..., 3) into the world frame (..., 3)."""
        p = np.asarray(points_local, dtype=float) @ self.rotation().T
        return p + np.array([self.x, self.y, 0.0])


def yaw_matrix(yaw: float) -> np.ndarray:
    """Rotation about world z by `yaw` radians."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def yaw_quat(yaw: float) -> np.ndarray:
    """MuJoCo quaternion (w, x, y, z) of a rotation about z by `yaw` radians."""
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def wrap_angle(angle: float) -> float:
    """Angle in radians wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi
