"""The pedestrian's plan: what a walker reads of a PedestrianSpec, and the plan as placed.

The plan: stand until `start_delay`, walk at `speed` along `heading_deg`; each leg
switches speed and turns the heading at `leg.at` (turns of legs inside the start delay are
applied while standing). A walker (sim.scenario.walkers) walks it its own way. The
placements (sim.scenario.families, sim.scenario.cases) time a plan as the Euro NCAP rail
target walks it (rail_track: straight pieces, every start from standing over an
acceleration distance), and may anchor it: a point it passes at a time, which every
walker then meets exactly (sim.scenario.path).

This module sits below the walkers and the scenario's records: it names the plan by what
is read of it (Plan), so that neither imports the other in a ring.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Protocol, TypeVar

import numpy as np

from sim.scenario.track import H, Track


@dataclass(frozen=True)
class Leg:
    """One piece of the pedestrian's path after the start.

    From `at` seconds after the start, walk at `speed` (0: stand still) with the heading
    turned by `turn_deg` (counter-clockwise) relative to the previous leg. The start is
    the scenario's t = 0 (start_delay does not shift legs; see sim.world.pedestrian).
    """

    at: float
    speed: float
    turn_deg: float = 0.0


@dataclass(frozen=True)
class Anchor:
    """A point the walker passes at a given time (the placement solved for it)."""

    time: float  # s from the start
    x: float  # world, m
    y: float


class Stature(Protocol):
    @property
    def height(self) -> float: ...  # m


class Plan(Protocol):
    """What a walker reads of its pedestrian (sim.scenario.spec.PedestrianSpec is one, a
    frozen dataclass: the anchored plan is a copy of it without its legs)."""

    @property
    def x(self) -> float: ...  # world, m: where it stands at t = 0
    @property
    def y(self) -> float: ...
    @property
    def speed(self) -> float: ...  # m/s, 0 for standing
    @property
    def legs(self) -> tuple[Leg, ...]: ...
    @property
    def start_delay(self) -> float: ...  # s standing at the start before walking
    @property
    def anchor(self) -> Anchor | None: ...
    @property
    def looks(self) -> Stature: ...  # the mannequin: its stature sets a stride's length

    def heading_at(self, t: float) -> float: ...  # rad, the plan's heading at time t


P = TypeVar("P", bound=Plan)


def plan_pieces(plan: Plan) -> list[tuple[float, float, float]]:
    """The plan as (start time, speed, heading rad) pieces, the last one open."""
    for label, value in (("pedestrian speed", plan.speed), ("start_delay", plan.start_delay)):
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{label} must be >= 0, got {value}")
    for leg in plan.legs:
        if not (math.isfinite(leg.at) and leg.at >= 0):
            raise ValueError(f"a leg must start at a time >= 0 s, got {leg.at}")
        if not (math.isfinite(leg.speed) and leg.speed >= 0):
            raise ValueError(f"leg speed must be >= 0, got {leg.speed}")
    times = sorted({0.0, float(plan.start_delay), *(float(leg.at) for leg in plan.legs)})
    legs = sorted(plan.legs, key=lambda leg: leg.at)

    def speed(t: float) -> float:
        if t < plan.start_delay:
            return 0.0
        value = plan.speed
        for leg in legs:
            if leg.at <= t:
                value = leg.speed
        return float(value)

    return [(t, speed(t), plan.heading_at(t)) for t in times]


def rail_track(plan: Plan, acceleration_distance: float) -> Track:
    """The plan's pieces, every start from standing accelerating over the given distance.

    The Euro NCAP target's walk (sim.scenario.walkers.rail) and the timing of every
    placement; with distance 0 it is the plan itself (instant starts)."""
    if not (math.isfinite(acceleration_distance) and acceleration_distance >= 0):
        raise ValueError(f"acceleration_distance must be >= 0 m, got {acceleration_distance}")
    pieces = plan_pieces(plan)
    times: list[float] = []
    points: list[np.ndarray] = []
    yaws: list[float] = []
    position = np.array([plan.x, plan.y], dtype=float)
    previous_speed = plan.speed if plan.start_delay <= 0 else 0.0  # walking already at t = 0
    for i, (t0, v, yaw) in enumerate(pieces):
        t1 = pieces[i + 1][0] if i + 1 < len(pieces) else math.inf
        direction = np.array([math.cos(yaw), math.sin(yaw)])
        accelerate = v > 0 and previous_speed == 0 and acceleration_distance > 0 and t0 > 0
        if accelerate:  # from standing: constant acceleration a over the distance
            duration = 2 * acceleration_distance / v
            a = v / duration
            end = min(t0 + duration, t1)
            n = max(1, math.ceil((end - t0) / H))
            for j in range(n):
                tau = (end - t0) * j / n
                times.append(t0 + tau)
                points.append(position + direction * 0.5 * a * tau**2)
                yaws.append(yaw)
            tau = end - t0
            position = position + direction * 0.5 * a * tau**2
            if end < t1:  # at speed until the next piece
                times.append(end)
                points.append(position)
                yaws.append(yaw)
                if math.isfinite(t1):
                    position = position + direction * v * (t1 - end)
        else:
            times.append(t0)
            points.append(position)
            yaws.append(yaw)
            if math.isfinite(t1):
                position = position + direction * v * (t1 - t0)
        previous_speed = v
    _, v_end, yaw_end = pieces[-1]
    end_velocity = v_end * np.array([math.cos(yaw_end), math.sin(yaw_end)])
    return Track.from_vertices(np.array(times), np.array(points), np.array(yaws), end_velocity)


def anchored_plan(plan: P, start_distance: float) -> P:
    """The plan the anchor belongs to: the whole plan when it passes the anchor (a pause on
    the way), else its approach (the plan without its legs: it stops or turns first).

    `start_distance` is the walker's (Walker.start_distance): the plan is timed as the
    placement timed it for that walker."""
    if plan.anchor is None or not plan.legs:
        return plan
    at = rail_track(plan, start_distance).state(plan.anchor.time).position
    if math.hypot(at[0] - plan.anchor.x, at[1] - plan.anchor.y) < 1e-6:
        return plan
    return replace(plan, legs=())  # type: ignore[type-var]  # a dataclass: see Plan
