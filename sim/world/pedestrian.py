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

import numpy as np
from highway_env.road.road import Road
from highway_env.vehicle.objects import RoadObject

from sim.geometry.highway_frame import highway_vector_to_world, reflect, world_to_highway
from sim.scenario.path import PathState, PedestrianPath
from sim.scenario.spec import PedestrianSpec
from sim.world.gait import Gait


class Pedestrian(RoadObject):
    """The pedestrian as a highway-env road object following its scenario path.

    Its footprint is a square of `spec.footprint` metres turned with the heading; it is
    not solid, so highway-env marks it `hit` on contact instead of pushing the robot away
    (the contact is judged by the ground truth, the robot is not deflected).
    Positions and headings on this object are in highway-env's frame (sim.geometry.highway_frame).
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
