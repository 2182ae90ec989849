"""Where a scenario's people are against each other and the parked cars, over the run.

The checks of a scenario with several people that no single value decides (the file's
street checks are their model): a person whose footprint meets a parked car's at any time
of the run walks through it, and two people whose footprints overlap at the start stand
inside each other. Footprints are the squares the ground truth gives each person (side
`footprint`, turned with the walking line); a parked car is its box on the ground.

What is checked is the path as written: each person's plan as the rail target walks it
(planned_path). A human walker's wander and sway around that line are the walk's own,
drawn per run, and may brush a car the line clears (Euro NCAP's CPNCO child passes the
second parked car by 5 cm).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from sim.scenario.path import pedestrian_path
from sim.scenario.spec import Occluder, PedestrianSpec, Scenario
from sim.scenario.track import Track
from sim.scenario.walkers import RailWalker, ReplayWalker

# Footprints closer than this are apart (touching is not overlapping).
TOUCH = 1e-6  # m


@dataclass(frozen=True)
class CarContact:
    """Person `person` meets parked car `car` (indices) at time `t` standing at `xy`."""

    person: int
    car: int
    t: float
    xy: tuple[float, float]


def planned_path(person: PedestrianSpec, s: Scenario) -> Track:
    """A person's path as written: their plan walked by the rail target (their own walker
    when it is one), starting from standing over their walker's start distance (the one
    the placement timed the plan with), so it meets the placement's anchor as theirs does.
    A replayed person's path as written is the recording (their own walker's track)."""
    walker = person.behaviour
    if not isinstance(walker, RailWalker | ReplayWalker):
        rail = RailWalker(acceleration_distance=walker.start_distance)
        person = replace(person, behaviour=rail)
    return pedestrian_path(person, s.duration, s.seed)


def sample_times(track: Track, duration: float, dt: float) -> np.ndarray:
    """Every frame of the run and every vertex of the track within it (the times where
    its velocity may change), sorted."""
    frames = np.arange(0.0, duration, dt)
    return np.unique(np.concatenate([frames, [duration], track.breakpoints_between(0.0, duration)]))


def footprint_yaws(track: Track, times: np.ndarray) -> np.ndarray:
    """The footprint's heading at each time (the walking line's, piece by piece)."""
    k = np.searchsorted(track.times, times, side="right") - 1
    return track.footprint_yaws[k]


def boxes_overlap(
    centres: np.ndarray, yaws: np.ndarray, half: tuple[float, float],
    centre: Sequence[float], yaw: float, other_half: tuple[float, float],
) -> np.ndarray:  # fmt: skip
    """Whether each box (centres (n, 2), yaws (n,), half length and width `half`) overlaps
    one other box (separating axes: two rectangles overlap unless one of their four edge
    directions separates their projections)."""
    d = np.asarray(centres, dtype=float) - np.asarray(centre, dtype=float)
    a, b = half
    c, e = other_half
    own = [np.stack([np.cos(yaws), np.sin(yaws)], axis=1)]
    own.append(np.stack([-own[0][:, 1], own[0][:, 0]], axis=1))
    u = np.array([math.cos(yaw), math.sin(yaw)])
    other = [np.broadcast_to(u, d.shape), np.broadcast_to(np.array([-u[1], u[0]]), d.shape)]

    def dot(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return np.abs(np.sum(p * q, axis=1))

    apart = np.zeros(len(d), dtype=bool)
    for axis in (*own, *other):
        reach = a * dot(own[0], axis) + b * dot(own[1], axis)
        reach = reach + c * dot(other[0], axis) + e * dot(other[1], axis)
        apart |= dot(d, axis) >= reach - TOUCH
    return ~apart


def parked_car_contact(s: Scenario) -> CarContact | None:
    """The first person (in order) whose planned footprint meets a parked car's during
    the run, at the first time it does; None when nobody does."""
    cars = s.scene.occluders
    if not cars:
        return None
    for k, person in enumerate(s.planned):  # the crowd model keeps its own off the cars
        track = planned_path(person, s)
        times = sample_times(track, s.duration, s.dt)
        xy = track.positions_at(times)
        yaws = footprint_yaws(track, times)
        half = (person.footprint / 2, person.footprint / 2)
        for j, car in enumerate(cars):
            box = ((car.x, car.y), math.radians(car.yaw), (car.length / 2, car.width / 2))
            hit = np.flatnonzero(boxes_overlap(xy, yaws, half, *box))
            if len(hit):
                i = hit[0]
                return CarContact(k, j, float(times[i]), (float(xy[i, 0]), float(xy[i, 1])))
    return None


def start_overlap(s: Scenario) -> tuple[int, int] | None:
    """The first two people (indices, the earlier first) whose planned footprints overlap
    at the start; None when everyone stands apart."""
    starts = [planned_path(p, s).state(0.0) for p in s.planned]  # the crowd's: its own
    for k in range(1, len(starts)):
        for j in range(k):
            a, b = starts[j], starts[k]
            fa, fb = s.people[j].footprint / 2, s.people[k].footprint / 2
            if boxes_overlap(a.position[None], np.array([a.footprint_yaw]), (fa, fa),
                             b.position, b.footprint_yaw, (fb, fb))[0]:  # fmt: skip
                return j, k
    return None


def parked_car_text(car: Occluder) -> str:
    """A parked car as an error names it: where it stands."""
    return f"the parked car at x = {car.x:g} m, y = {car.y:g} m"
