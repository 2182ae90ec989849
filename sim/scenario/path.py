"""The pedestrian's motion: where a PedestrianSpec puts the person at any time, exactly.

A Track is a polyline in time: vertices (t_k, p_k) joined by straight pieces at
constant velocity, the last piece going on for ever. The body (MuJoCo), highway-env's
road object and the ground truth all read the same Track, so the truth's case of the
next second, its collisions and times to contact use exactly the motion the body makes.

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
from dataclasses import dataclass, replace

import numpy as np

from sim.geometry.frames import Pose2D
from sim.scenario.spec import PedestrianSpec

H = 0.01  # s, the fine step of accelerations and of human walks
DEFAULT_ACCELERATION_DISTANCE = 1.0  # m, Euro NCAP's near-side target (far side 1.5 m)


@dataclass(frozen=True)
class PathState:
    """The pedestrian on its path at one time (world frame)."""

    time: float
    position: np.ndarray  # (2,) world x, y
    yaw: float  # rad, CCW from east: where the person faces (and walks, when walking)
    velocity: np.ndarray  # (2,) world ground velocity, m/s
    footprint_yaw: float = math.nan  # rad: the square on the ground follows the walking line

    def __post_init__(self) -> None:
        if math.isnan(self.footprint_yaw):
            object.__setattr__(self, "footprint_yaw", self.yaw)

    @property
    def speed(self) -> float:
        return float(math.hypot(self.velocity[0], self.velocity[1]))

    @property
    def pose(self) -> Pose2D:
        return Pose2D(float(self.position[0]), float(self.position[1]), self.yaw)


class Track:
    """Vertices at `times` (from 0, increasing), piece k from vertex k at `velocities[k]`.

    `yaws[k]` is the heading on piece k (the body's); `footprint_yaws[k]` the heading of
    the square the pedestrian occupies on the ground (the walking line's: a human walker's
    sway turns the body, not the ground it covers). The last piece has no end.
    """

    def __init__(self, times: np.ndarray, positions: np.ndarray, velocities: np.ndarray,
                 yaws: np.ndarray, footprint_yaws: np.ndarray | None = None,
                 phases: np.ndarray | None = None) -> None:  # fmt: skip
        self.times = np.asarray(times, dtype=float)
        self.positions = np.asarray(positions, dtype=float).reshape(-1, 2)
        self.velocities = np.asarray(velocities, dtype=float).reshape(-1, 2)
        self.yaws = np.asarray(yaws, dtype=float)
        self.footprint_yaws = self.yaws if footprint_yaws is None else np.asarray(footprint_yaws)
        # The stride phase (strides since some start, unwrapped) where the walk sets it;
        # None: the mannequin's gait keeps its own phase.
        self.phases = None if phases is None else np.asarray(phases, dtype=float)
        n = len(self.times)
        arrays = (self.positions, self.velocities, self.yaws, self.footprint_yaws)
        sizes = {len(a) for a in arrays + (() if self.phases is None else (self.phases,))}
        if not (n >= 1 and sizes == {n}):
            raise ValueError("a track needs as many positions, velocities and yaws as times")
        if self.times[0] != 0.0 or np.any(np.diff(self.times) <= 0):
            raise ValueError("track times must start at 0 and increase")

    @classmethod
    def from_vertices(cls, times: np.ndarray, positions: np.ndarray, yaws: np.ndarray,
                      end_velocity: np.ndarray, footprint_yaws: np.ndarray | None = None,
                      phases: np.ndarray | None = None) -> Track:  # fmt: skip
        """Pieces joining the vertices; the last one goes on at `end_velocity`."""
        times = np.asarray(times, dtype=float)
        positions = np.asarray(positions, dtype=float).reshape(-1, 2)
        velocities = np.empty_like(positions)
        if len(times) > 1:
            velocities[:-1] = np.diff(positions, axis=0) / np.diff(times)[:, None]
        velocities[-1] = end_velocity
        return cls(times, positions, velocities, np.asarray(yaws, dtype=float), footprint_yaws,
                   phases)  # fmt: skip

    def _piece(self, t: float) -> int:
        if not (math.isfinite(t) and t >= 0):
            raise ValueError(f"path time must be >= 0, got {t}")
        return int(np.searchsorted(self.times, t, side="right")) - 1

    def state(self, t: float) -> PathState:
        """Where the pedestrian is at time t (s since the scenario start)."""
        k = self._piece(t)
        v = self.velocities[k]
        position = self.positions[k] + (t - self.times[k]) * v
        return PathState(float(t), position, float(self.yaws[k]), v.copy(),
                         float(self.footprint_yaws[k]))  # fmt: skip

    def positions_at(self, times: np.ndarray) -> np.ndarray:
        """(n, 2) positions at many times (>= 0) at once."""
        times = np.asarray(times, dtype=float)
        k = np.searchsorted(self.times, times, side="right") - 1
        return self.positions[k] + (times - self.times[k])[:, None] * self.velocities[k]

    def breakpoints_between(self, t0: float, t1: float) -> list[float]:
        """Times in (t0, t1) where the velocity may change."""
        lo = int(np.searchsorted(self.times, t0, side="right"))
        hi = int(np.searchsorted(self.times, t1, side="left"))
        return [float(t) for t in self.times[lo:hi]]

    def phase(self, t: float) -> float | None:
        """The stride phase in [0, 1) at time t, where the walk sets it."""
        if self.phases is None:
            return None
        return float(np.interp(t, self.times, self.phases)) % 1.0

    def translated(self, offset: np.ndarray) -> Track:
        return Track(self.times, self.positions + offset, self.velocities, self.yaws,
                     self.footprint_yaws, self.phases)  # fmt: skip


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

        approach = replace(spec, legs=())
        t_start = set_off_time(approach, seed)

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
        reference = build(replace(spec, legs=())) if spec.legs else track
        miss = np.array([anchor.x, anchor.y]) - reference.state(anchor.time).position
        track = track.translated(miss)
    return track
