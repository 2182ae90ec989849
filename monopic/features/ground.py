"""Ground-plane motion in the robot's frame with the robot's own motion taken out.

A moving camera makes a standing pedestrian appear to approach. The robot knows its own
speed and yaw rate, so it integrates them into an odometry pose, stores the pedestrian's
foot point in that fixed odometry frame, differentiates there, and rotates the velocity
back into its current frame. The result is the pedestrian's own ground velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from monopic.features.motion import VelocityEstimator
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


@dataclass
class GroundMotion:
    """Own ground velocity of a tracked foot point, from frames of a moving robot."""

    window: int = 4
    average: int = 4
    odometry: Odometry = field(default_factory=Odometry)
    _velocity: VelocityEstimator = field(init=False)

    def __post_init__(self) -> None:
        self._velocity = VelocityEstimator(self.window, self.average)

    def observe_ego(self, t: float, ego: EgoState) -> None:
        """Advance odometry; call on every frame, with or without a pedestrian."""
        self.odometry.update(t, ego)

    def update(
        self, t: float, ego: EgoState, foot_px: tuple[float, float]
    ) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """(position, own velocity) in the robot's current frame, or None above the horizon."""
        g = ego.camera.ground_point(np.array(foot_px, dtype=float))
        if not np.all(np.isfinite(g)):
            return None
        pos = (float(g[0]), float(g[1]))
        fx, fy = self.odometry.to_fixed(pos)
        vx, vy = self._velocity.update(t, fx, fy)
        if not (math.isfinite(vx) and math.isfinite(vy)):
            return pos, (float("nan"), float("nan"))
        return pos, self.odometry.rotate_to_robot((vx, vy))

    def reset_track(self) -> None:
        self._velocity.reset()
