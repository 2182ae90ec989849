"""The pedestrian: a scenario path, and a highway-env road object that walks it.

The path is known in closed form (straight pieces at constant speed between the start,
the end of the start delay and the legs), so the simulator can ask where the pedestrian
will be at any future time: the case label and the time to collision use exactly the
motion the body will make, not an extrapolation.

Timing: every time is seconds since the scenario start. The pedestrian stands (facing its
heading) until `start_delay`, then walks at `speed`; a leg switches speed and turns the
heading at `leg.at`. Turns of legs that fall inside the start delay are applied while
standing; their speed applies from the end of the delay.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np
from highway_env.road.road import Road
from highway_env.vehicle.objects import RoadObject

from sim.frames import Pose2D
from sim.gait import Gait
from sim.highway_frame import highway_vector_to_world, reflect, world_to_highway
from sim.scenario import PedestrianSpec


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


class Pedestrian(RoadObject):
    """The pedestrian as a highway-env road object following its scenario path.

    Its footprint is a square of `spec.footprint` metres turned with the heading; it is
    not solid, so highway-env marks it `hit` on contact instead of pushing the robot away
    (the contact is judged by the ground truth, the robot is not deflected).
    Positions and headings on this object are in highway-env's frame (sim.highway_frame).
    """

    def __init__(self, road: Road | None, spec: PedestrianSpec, gait: Gait | None = None) -> None:
        if not (math.isfinite(spec.footprint) and spec.footprint > 0):
            raise ValueError(f"pedestrian footprint must be positive, got {spec.footprint}")
        # Per-instance size, set before RoadObject.__init__ computes the diagonal from it.
        self.LENGTH = spec.footprint
        self.WIDTH = spec.footprint
        self.path = PedestrianPath(spec)
        self.gait = gait or Gait(height=spec.looks.height)
        self.gait_phase = 0.0
        self.time = 0.0
        start = self.path.state(0.0)
        position, heading = world_to_highway(start.pose)
        super().__init__(road, position, heading, start.speed)
        self.solid = False

    def reset(self, gait_phase: float = 0.0) -> None:
        """Back to the start of the path."""
        self.gait_phase = float(gait_phase) % 1.0
        self.hit = False
        self.set_time(0.0)

    def set_time(self, t: float) -> None:
        """Put the object where its path is at time t."""
        self.time = float(t)
        state = self.path.state(self.time)
        self.position, self.heading = world_to_highway(state.pose)
        self.speed = state.speed

    def act(self, action: object = None) -> None:
        """The pedestrian follows its path; it takes no actions."""

    def step(self, dt: float) -> None:
        """Walk `dt` seconds along the path and advance the gait with the distance walked."""
        before = self.path.state(self.time).position
        self.set_time(self.time + dt)
        walked = float(np.linalg.norm(self.path.state(self.time).position - before))
        self.gait_phase = self.gait.advance(self.gait_phase, walked / dt, dt)

    @property
    def state(self) -> PathState:
        """The current path state in the world frame."""
        return self.path.state(self.time)

    @property
    def world_velocity(self) -> np.ndarray:
        return highway_vector_to_world(self.velocity)

    def polygon_at(self, t: float) -> np.ndarray:
        """Footprint polygon (5, 2), highway-env frame, where the path puts it at time t.

        A shallow copy moved to that pose draws it with RoadObject.polygon itself, so the
        future footprint is the same geometry highway-env checks collisions with.
        """
        state = self.path.state(t)
        ghost = copy.copy(self)
        ghost.position, ghost.heading = reflect(state.position, state.yaw)
        return ghost.polygon()

    def highway_velocity_at(self, t: float) -> np.ndarray:
        """Velocity (2,) in highway-env's frame on the path at time t."""
        return reflect(self.path.state(t).velocity, 0.0)[0]
