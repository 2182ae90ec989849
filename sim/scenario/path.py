"""The pedestrian's path in closed form: where a PedestrianSpec puts the person at any time.

Straight pieces at constant speed between the start, the end of the start delay and the
legs, so the simulator can ask where the pedestrian will be at any future time: the case
label and the time to collision use exactly the motion the body will make.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.geometry.frames import Pose2D
from sim.scenario.spec import PedestrianSpec


@dataclass(frozen=True)
class PathState:
    """The pedestrian on its path at one time (world frame)."""

    time: float
    position: np.ndarray  # (2,) world x, y
    yaw: float  # rad, CCW from east: where the person faces and walks
    speed: float  # m/s

    @property
    def velocity(self) -> np.ndarray:
        """World ground velocity (2,), m/s."""
        return self.speed * np.array([math.cos(self.yaw), math.sin(self.yaw)])

    @property
    def pose(self) -> Pose2D:
        return Pose2D(float(self.position[0]), float(self.position[1]), self.yaw)


class PedestrianPath:
    """Closed-form position, heading and speed of a PedestrianSpec at any time >= 0."""

    def __init__(self, spec: PedestrianSpec) -> None:
        if not (math.isfinite(spec.speed) and spec.speed >= 0):
            raise ValueError(f"pedestrian speed must be >= 0, got {spec.speed}")
        if not (math.isfinite(spec.start_delay) and spec.start_delay >= 0):
            raise ValueError(f"start_delay must be >= 0 s, got {spec.start_delay}")
        for leg in spec.legs:
            if not (math.isfinite(leg.at) and leg.at >= 0):
                raise ValueError(f"a leg must start at a time >= 0 s, got {leg.at}")
            if not (math.isfinite(leg.speed) and leg.speed >= 0):
                raise ValueError(f"leg speed must be >= 0, got {leg.speed}")
        self.spec = spec
        times = sorted({0.0, float(spec.start_delay), *(float(leg.at) for leg in spec.legs)})
        # One constant-velocity piece from each breakpoint to the next (the last is open).
        self.breakpoints = np.array(times)
        starts = [np.array([spec.x, spec.y], dtype=float)]
        for t0, t1 in zip(times[:-1], times[1:], strict=True):
            starts.append(starts[-1] + (t1 - t0) * self._piece_velocity(t0))
        self._starts = starts

    def _speed(self, t: float) -> float:
        if t < self.spec.start_delay:
            return 0.0
        speed = self.spec.speed
        for leg in sorted(self.spec.legs, key=lambda leg: leg.at):
            if leg.at <= t:
                speed = leg.speed
        return float(speed)

    def _piece_velocity(self, t0: float) -> np.ndarray:
        yaw = self.spec.heading_at(t0)
        return self._speed(t0) * np.array([math.cos(yaw), math.sin(yaw)])

    def state(self, t: float) -> PathState:
        """Where the pedestrian is at time t (s since the scenario start)."""
        if not (math.isfinite(t) and t >= 0):
            raise ValueError(f"path time must be >= 0, got {t}")
        k = int(np.searchsorted(self.breakpoints, t, side="right")) - 1
        t0 = float(self.breakpoints[k])
        position = self._starts[k] + (t - t0) * self._piece_velocity(t0)
        return PathState(t, position, self.spec.heading_at(t), self._speed(t))

    def breakpoints_between(self, t0: float, t1: float) -> list[float]:
        """Times in (t0, t1) where the velocity may change."""
        return [float(b) for b in self.breakpoints if t0 < b < t1]
