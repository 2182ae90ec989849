"""The pedestrian's motion: where a PedestrianSpec puts the person at any time, exactly.

The motion is a Track (sim.scenario.track): a polyline in time that the body, highway-env
and the ground truth all read.

The plan (PedestrianSpec): stand until `start_delay`, walk at `speed` along
`heading_deg`; each leg switches speed and turns the heading at `leg.at` (turns of legs
inside the start delay are applied while standing). How the plan is walked is the
spec's behaviour (sim.scenario.spec.Behaviour):

- `rail` (this module): the plan's straight pieces, except that every start from
  standing accelerates at a constant rate over the acceleration distance (fine pieces
  of H seconds through it), as Euro NCAP's pedestrian targets do; with distance 0 it
  is the plan itself;
- `human` (sim.scenario.human): one piece every H seconds of a walker that starts,
  stops and turns as people do.

A spec's anchor (a point at a time the placement solved for) is then met exactly.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from sim.scenario.spec import PedestrianSpec
from sim.scenario.track import H, Track

DEFAULT_ACCELERATION_DISTANCE = 1.0  # m, Euro NCAP's near-side target (far side 1.5 m)


def plan_pieces(spec: PedestrianSpec) -> list[tuple[float, float, float]]:
    """The plan as (start time, speed, heading rad) pieces, the last one open."""
    for label, value in (("pedestrian speed", spec.speed), ("start_delay", spec.start_delay)):
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{label} must be >= 0, got {value}")
    for leg in spec.legs:
        if not (math.isfinite(leg.at) and leg.at >= 0):
            raise ValueError(f"a leg must start at a time >= 0 s, got {leg.at}")
        if not (math.isfinite(leg.speed) and leg.speed >= 0):
            raise ValueError(f"leg speed must be >= 0, got {leg.speed}")
    times = sorted({0.0, float(spec.start_delay), *(float(leg.at) for leg in spec.legs)})
    legs = sorted(spec.legs, key=lambda leg: leg.at)

    def speed(t: float) -> float:
        if t < spec.start_delay:
            return 0.0
        value = spec.speed
        for leg in legs:
            if leg.at <= t:
                value = leg.speed
        return float(value)

    return [(t, speed(t), spec.heading_at(t)) for t in times]


def rail_track(spec: PedestrianSpec, acceleration_distance: float) -> Track:
    """The plan's pieces, every start from standing accelerating over the given distance."""
    if not (math.isfinite(acceleration_distance) and acceleration_distance >= 0):
        raise ValueError(f"acceleration_distance must be >= 0 m, got {acceleration_distance}")
    pieces = plan_pieces(spec)
    times: list[float] = []
    points: list[np.ndarray] = []
    yaws: list[float] = []
    position = np.array([spec.x, spec.y], dtype=float)
    previous_speed = spec.speed if spec.start_delay <= 0 else 0.0  # walking already at t = 0
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


def pedestrian_path(spec: PedestrianSpec, t_end: float, seed: int = 0) -> Track:
    """The pedestrian's Track up to at least t_end (it goes on straight after), per behaviour.

    `seed` draws a human walker's wander (the scenario's seed: the same run, the same walk).
    The anchor belongs to the approach (the plan without its legs): a walker that stops
    at the kerb or turns away walks the same approach as the one that walks on, and is
    shifted as that one is to pass the anchor (which it then never reaches).
    """
    behaviour = spec.behaviour
    if behaviour.model == "human":
        from sim.scenario.human import human_track, set_off_time

        t_start = set_off_time(anchored_plan(spec), seed)

        def build(s: PedestrianSpec) -> Track:
            return human_track(s, t_end, seed, t_start)
    else:
        distance = behaviour.acceleration_distance
        distance = DEFAULT_ACCELERATION_DISTANCE if distance is None else distance

        def build(s: PedestrianSpec) -> Track:
            return rail_track(s, distance)

    track = build(spec)
    anchor = spec.anchor
    if anchor is not None:  # pass the placement's point at its time, exactly
        reference = anchored_plan(spec)
        walked = track if reference is spec else build(reference)
        miss = np.array([anchor.x, anchor.y]) - walked.state(anchor.time).position
        track = track.translated(miss)
    return track


def anchored_plan(spec: PedestrianSpec) -> PedestrianSpec:
    """The plan the anchor belongs to: the whole plan when it passes the anchor (a pause on
    the way), else its approach (the plan without its legs: it stops or turns first)."""
    if spec.anchor is None or not spec.legs:
        return spec
    b = spec.behaviour
    accel = b.acceleration_distance if b.model == "rail" else 0.0
    plan = rail_track(spec, DEFAULT_ACCELERATION_DISTANCE if accel is None else accel)
    at = plan.state(spec.anchor.time).position
    if math.hypot(at[0] - spec.anchor.x, at[1] - spec.anchor.y) < 1e-6:
        return spec
    return replace(spec, legs=())
