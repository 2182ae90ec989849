"""The pedestrian: a highway-env road object that walks its Track (sim.scenario.path).

The Track is known ahead (straight pieces between vertices, as its behaviour walks the
plan), so the simulator can ask where the pedestrian will be at any future time: the case
label and the time to collision use exactly the motion the body will make, not an
extrapolation. Every time is seconds since the scenario start.
"""

from __future__ import annotations

import copy
import math

import numpy as np
from highway_env.road.road import Road
from highway_env.vehicle.objects import RoadObject

from sim.geometry.highway_frame import reflect, world_to_highway
from sim.scenario.path import pedestrian_path
from sim.scenario.spec import PedestrianSpec
from sim.scenario.track import PathState, Track
from sim.world.gait import Gait


class Pedestrian(RoadObject):
    """The pedestrian as a highway-env road object following its scenario path.

    Its footprint is a square of `spec.footprint` metres turned with the heading; it is
    not solid, so highway-env marks it `hit` on contact instead of pushing the robot away
    (the contact is judged by the ground truth, the robot is not deflected).
    Positions and headings on this object are in highway-env's frame (sim.geometry.highway_frame).
    """

    def __init__(
        self,
        road: Road | None,
        spec: PedestrianSpec,
        gait: Gait | None = None,
        *,
        t_end: float = 30.0,
        seed: int = 0,
        path: Track | None = None,
    ) -> None:
        """`t_end`: how far ahead the walk is worked out (the run and the truth's lookahead);
        `seed`: the walk's own randomness (a human walker's wander); `path`: a walk worked
        out elsewhere (a crowd's), else the spec's own."""
        if not (math.isfinite(spec.footprint) and spec.footprint > 0):
            raise ValueError(f"pedestrian footprint must be positive, got {spec.footprint}")
        # Per-instance size, set before RoadObject.__init__ computes the diagonal from it.
        self.LENGTH = spec.footprint
        self.WIDTH = spec.footprint
        self.path = pedestrian_path(spec, t_end, seed) if path is None else path
        self.gait = gait or Gait(height=spec.looks.height)
        self.gait_phase = 0.0
        self.time = 0.0
        start = self.path.state(0.0)
        position, heading = world_to_highway(start.pose)
        super().__init__(road, position, heading, start.speed)
        self.solid = False

    def reset(self, gait_phase: float = 0.0) -> None:
        """Back to the start of the path."""
        phase = self.path.phase(0.0)
        self.gait_phase = float(gait_phase) % 1.0 if phase is None else phase
        self.hit = False
        self.set_time(0.0)

    def set_time(self, t: float) -> None:
        """Put the object where its path is at time t."""
        self.time = float(t)
        state = self.path.state(self.time)
        # highway-env's heading is the footprint's (its polygon is the square on the ground).
        self.position, self.heading = reflect(state.position, state.footprint_yaw)
        self.speed = state.speed

    def act(self, action: object = None) -> None:
        """The pedestrian follows its path; it takes no actions."""

    def step(self, dt: float) -> None:
        """Walk `dt` seconds along the path and advance the gait with the distance walked."""
        before = self.path.state(self.time).position
        self.set_time(self.time + dt)
        phase = self.path.phase(self.time)
        if phase is not None:  # the walk sets the stride (its body's sway and surge too)
            self.gait_phase = phase
            return
        walked = float(np.linalg.norm(self.path.state(self.time).position - before))
        self.gait_phase = self.gait.advance(self.gait_phase, walked / dt, dt)

    @property
    def body_sways(self) -> bool:
        """Whether the mannequin's gait sways the pelvis itself (else the walk's track does)."""
        return self.path.phases is None

    @property
    def state(self) -> PathState:
        """The current path state in the world frame."""
        return self.path.state(self.time)

    def polygon_at(self, t: float) -> np.ndarray:
        """Footprint polygon (5, 2), highway-env frame, where the path puts it at time t.

        A shallow copy moved to that pose draws it with RoadObject.polygon itself, so the
        future footprint is the same geometry highway-env checks collisions with.
        """
        state = self.path.state(t)
        ghost = copy.copy(self)
        ghost.position, ghost.heading = reflect(state.position, state.footprint_yaw)
        return ghost.polygon()

    def highway_velocity_at(self, t: float) -> np.ndarray:
        """Velocity (2,) in highway-env's frame on the path at time t."""
        return reflect(self.path.state(t).velocity, 0.0)[0]
