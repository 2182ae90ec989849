"""The `human` walker: the plan (sim.scenario.plan) walked as a person walks it.

The plan's pieces give a route (a polyline from where the person stands, turning where
the plan turns) and what happens along it: walk at a speed, change speed, stop at a
point, stand until a time. The walker follows the route with:

- starts over `start_time` and speed changes over a share of it: a raised-cosine speed
  profile, so the acceleration rises and falls smoothly;
- stops over about `stop_time`: braking begins so that the same raised-cosine profile
  ends exactly at the plan's stopping point;
- turns along a circular arc whose radius keeps the yaw rate within `max_yaw_rate` at
  the walking speed (the arc cuts the corner, so the turn starts before the plan's);
- a slow wander of its walking speed (`speed_wander`, a share of it, over time since it
  set off) and of its line (`lateral_wander`, metres to either side, over distance
  walked, so a standing person does not drift): sums of three sinusoids drawn from the
  seed.

The speed is integrated every H seconds (trapezoids) into the distance along the route,
and each step is a vertex of the walker's Track. A walker walking at t = 0 set off long
before, so it is at speed; one that stands first sets off at the plan's start, or, when
the plan has an anchor, when it must to reach the anchor's distance along its approach
at the anchor's time (later than the plan's instant start would; see sim.scenario.path).

Intent cues (intent_cues) turn its head and shoulders, never its walk.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import ClassVar

import numpy as np

from sim.geometry.frames import wrap_angle
from sim.scenario.plan import Plan, anchored_plan, plan_pieces
from sim.scenario.stride import step_length
from sim.scenario.toml_table import TomlTable
from sim.scenario.track import H, Track
from sim.scenario.walkers.base import legacy_text

WANDER_PERIODS = (3.0, 12.0)  # s, the speed wander's sinusoids
WANDER_WAVELENGTHS = (2.5, 9.0)  # m, the line's sinusoids
PREROLL = 10.0  # s walked before t = 0 by a walker that is walking at t = 0
GOING = 0.6  # m/s: from here on the stride's surge and sway are full


@dataclass(frozen=True)
class HumanWalker:
    """A person walking the plan (scenarios/README.md: units, ranges, sources): starts and
    stops over a couple of steps (raised-cosine speed profiles), turns along arcs at a
    bounded yaw rate, wanders a little in speed and sideways, and shows intent cues."""

    model: ClassVar[str] = "human"
    start_time: float = 1.8  # s from standing to walking speed (about three steps)
    stop_time: float = 1.2  # s from walking speed to standing (about two steps)
    max_yaw_rate: float = 90.0  # deg/s along a turn
    speed_wander: float = 0.10  # amplitude of the speed's slow wander, share of its speed
    lateral_wander: float = 0.15  # m, amplitude of the sideways wander off the plan's line
    sway: float = 0.02  # m, the body's side-to-side sway once a stride
    surge: float = 0.12  # the body's speed rising and falling twice a stride, share of it
    # Intent cues (probability 0 and lead times 0: a walker without them, exactly):
    head_check_probability: float = 0.8  # of each head check toward the traffic
    head_check_lead: float = 1.0  # s before setting off that the check before it begins
    head_check_duration: float = 0.8  # s, out and back
    head_check_amplitude: float = 60.0  # deg of head yaw (the shoulders turn torso_share of it)
    head_check_interval: float = 1.5  # s between checks while walking or standing
    torso_share: float = 0.3  # of a head turn the shoulders follow
    turn_lead: float = 0.4  # s the head leads the walking line in turns (shoulders half of it)
    stop_lead: float = 0.6  # s of slowing to STOP_APPROACH of the speed before braking to a stop
    # Not a parameter of the walk: the acceleration distance of the placement that put it
    # (placed), written in its identity text only, as the one record of earlier versions
    # held it, so that their run ids and seeds stay the same (walkers.base.LEGACY_FIELDS).
    identity_acceleration_distance: float | None = field(default=None, repr=False, compare=False)

    @property
    def cues(self) -> bool:
        return self.head_check_probability > 0 or self.turn_lead > 0 or self.stop_lead > 0

    @property
    def start_distance(self) -> float:
        return 0.0  # it sets off when it must to meet the anchor (set_off_time)

    def placed(self, acceleration_distance: float) -> HumanWalker:
        if self.identity_acceleration_distance is not None:
            return self
        return replace(self, identity_acceleration_distance=acceleration_distance)

    def track(self, plan: Plan, t_end: float, seed: int) -> Track:
        t_start = set_off_time(self, anchored_plan(plan, self.start_distance), seed)
        return human_track(self, plan, t_end, seed, t_start)

    def identity(self) -> str:
        values = {f.name: getattr(self, f.name) for f in fields(self) if f.repr}
        return legacy_text(self.model, self.identity_acceleration_distance, values)

    @classmethod
    def from_table(cls, t: TomlTable) -> HumanWalker:
        base = cls()

        def number(key: str, low: float, high: float, unit: str = "") -> float:
            return t.number(key, getattr(base, key), low=low, high=high, unit=unit)

        walker = cls(
            start_time=number("start_time", 0.2, 5.0, "s"),
            stop_time=number("stop_time", 0.2, 5.0, "s"),
            max_yaw_rate=number("max_yaw_rate", 10.0, 360.0, "deg/s"),
            speed_wander=number("speed_wander", 0.0, 0.3),
            lateral_wander=number("lateral_wander", 0.0, 0.5, "m"),
            sway=number("sway", 0.0, 0.1, "m"),
            surge=number("surge", 0.0, 0.3),
            head_check_probability=number("head_check_probability", 0.0, 1.0),
            head_check_lead=number("head_check_lead", 0.0, 5.0, "s"),
            head_check_duration=number("head_check_duration", 0.2, 5.0, "s"),
            head_check_amplitude=number("head_check_amplitude", 0.0, 120.0, "deg"),
            head_check_interval=number("head_check_interval", 0.0, 30.0, "s"),
            torso_share=number("torso_share", 0.0, 1.0),
            turn_lead=number("turn_lead", 0.0, 2.0, "s"),
            stop_lead=number("stop_lead", 0.0, 3.0, "s"),
        )
        t.done()
        return walker


@dataclass(frozen=True)
class Stretch:
    """A piece of the plan along the route: from arc length `s0`, at `speed` (0: stand)."""

    s0: float
    time: float  # when the plan starts it
    speed: float
    heading: float


def stretches(plan: Plan) -> list[Stretch]:
    """The plan's pieces placed along the route by arc length (0 where it sets off)."""
    out: list[Stretch] = []
    s = 0.0
    pieces = plan_pieces(plan)
    for i, (t0, v, heading) in enumerate(pieces):
        out.append(Stretch(s, t0, v, heading))
        if i + 1 < len(pieces):
            s += v * (pieces[i + 1][0] - t0)
    return out


def _unit(heading: float) -> np.ndarray:
    return np.array([math.cos(heading), math.sin(heading)])


@dataclass(frozen=True)
class Corner:
    s: float  # plan arc length of the plan's corner
    heading_in: float
    turn: float  # rad, counter-clockwise positive
    radius: float  # m, of the arc that replaces it

    @property
    def half(self) -> float:
        """Plan arc length the arc takes on either side of the corner."""
        return self.radius * math.tan(abs(self.turn) / 2)


@dataclass(frozen=True)
class Route:
    """The plan's polyline from the start point, its corners rounded by arcs."""

    start: np.ndarray
    heading0: float
    corners: tuple[Corner, ...]

    def point(self, s: float) -> tuple[np.ndarray, float]:
        """Position and tangent heading at plan arc length s."""
        p, heading, done = self.start, self.heading0, 0.0
        for c in self.corners:
            if s <= c.s - c.half:
                break
            entry = p + (c.s - c.half - done) * _unit(heading)
            side = 1.0 if c.turn > 0 else -1.0
            centre = entry + c.radius * _unit(heading + side * math.pi / 2)
            u = min((s - (c.s - c.half)) / (2 * c.half), 1.0)
            on_arc = centre + c.radius * _unit(heading - side * math.pi / 2 + c.turn * u)
            if u < 1.0:
                return on_arc, heading + c.turn * u
            p, heading, done = on_arc, heading + c.turn, c.s + c.half
        return p + (s - done) * _unit(heading), heading


def route(spec: Plan, plan: list[Stretch], max_yaw_rate: float) -> Route:
    """The route through the plan's turns, each corner an arc at the yaw-rate bound."""
    vertices: list[tuple[float, float, float]] = []  # (s, heading after, speed around)
    for p in plan:
        if vertices and abs(p.s0 - vertices[-1][0]) < 1e-9:  # a turn while standing
            vertices[-1] = (vertices[-1][0], p.heading, max(vertices[-1][2], p.speed))
        else:
            vertices.append((p.s0, p.heading, p.speed))
    omega = math.radians(max_yaw_rate)
    corners: list[Corner] = []
    for k in range(1, len(vertices)):
        s, heading, speed = vertices[k]
        turn = wrap_angle(heading - vertices[k - 1][1])
        if abs(turn) < 1e-9:
            continue
        radius = max(speed, vertices[k - 1][2], 0.1) / omega
        before = s - (corners[-1].s + corners[-1].half if corners else 0.0)
        after = vertices[k + 1][0] - s if k + 1 < len(vertices) else math.inf
        room = 0.45 * min(before, after)  # the arc stays within its two segments
        half = radius * math.tan(abs(turn) / 2)
        if half > room:
            radius = radius * room / half if room > 0 else 0.0
        if radius > 0:
            corners.append(Corner(s, vertices[k - 1][1], turn, radius))
    start = np.array([spec.x, spec.y], dtype=float)
    return Route(start, vertices[0][1], tuple(corners))


def _wander(rng: np.random.Generator, bounds: tuple[float, float]) -> np.ndarray:
    """Three sinusoids (period or wavelength, phase, weight; weights summing to 1)."""
    periods = rng.uniform(*bounds, size=3)
    phases = rng.uniform(0, 2 * math.pi, size=3)
    weights = rng.uniform(0.5, 1.0, size=3)
    return np.column_stack([periods, phases, weights / weights.sum()])


def sines(table: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The sum of the table's sinusoids at each x."""
    x = np.asarray(x, dtype=float)[..., None]
    return np.sum(table[:, 2] * np.sin(2 * math.pi * x / table[:, 0] + table[:, 1]), axis=-1)


STOP_APPROACH = 0.6  # share of its speed a walker slows to over `stop_lead` before a stop


@dataclass
class Walk:
    """The walker's distance along the route over time, H seconds at a time."""

    plan: list[Stretch]
    b: HumanWalker
    speed_wander: np.ndarray  # a _wander table, over time since setting off

    def profile(self, t_start: float, s_start: float, t_end: float, until_s: float = math.inf):
        """(times, arc lengths, events) from setting off at `t_start` at arc length
        `s_start`, to t_end (or until the arc length passes `until_s`). Events are
        (time, kind): "set-off" (from standing), "stop" (arrived at a stop), "slow" (a
        slower stretch begins: a hesitation)."""
        plan, b = self.plan, self.b
        walking = [k for k, p in enumerate(plan) if p.speed > 0]
        if not walking:
            return np.array([t_start]), np.array([s_start]), []
        i = walking[0]
        t, s, v = t_start, s_start, 0.0
        mode, t0, v0, duration = "ramp", t, 0.0, b.start_time
        s_stop = hold_until = math.inf
        approach_from = math.inf  # when the slowing before a stop began
        times, arcs = [t], [s]
        events: list[tuple[float, str]] = [(t_start, "set-off")]
        steps = max(1, math.ceil((t_end - t_start) / H))
        wander = 1 + b.speed_wander * sines(self.speed_wander, np.arange(steps + 1) * H)
        for step in range(1, steps + 1):
            if s > until_s:
                break
            t = t_start + step * H
            v_before = v
            slowing = 1.0
            if t > approach_from:  # the last steps before a stop: slower
                tau = min((t - approach_from) / b.stop_lead, 1.0)
                slowing = 1 - (1 - STOP_APPROACH) * (1 - math.cos(math.pi * tau)) / 2
            cruise = plan[i].speed * float(wander[step]) * slowing
            if mode == "hold" and t >= hold_until:
                mode, t0, v0, duration = "ramp", t - H, 0.0, b.start_time
                events.append((t - H, "set-off"))
            if mode == "ramp":
                tau = min((t - t0) / duration, 1.0)
                v = v0 + (cruise - v0) * (1 - math.cos(math.pi * tau)) / 2
                if tau >= 1.0:
                    mode = "cruise"
            elif mode == "cruise":
                v = cruise
            elif mode == "brake":
                tau = min((t - t0) / duration, 1.0)
                v = v0 * (1 + math.cos(math.pi * tau)) / 2
            else:  # standing: held at a stop, or for good
                v = 0.0
            s += (v_before + v) / 2 * H
            if mode == "brake" and (t - t0) >= duration:
                s, v = s_stop, 0.0
                events.append((t, "stop"))
                approach_from = math.inf
                nxt = i + 2  # past the standing stretch
                if nxt < len(plan) and plan[nxt].speed > 0:
                    i, mode, hold_until = nxt, "hold", plan[nxt].time
                else:
                    mode = "stand"
            elif mode in ("ramp", "cruise") and i + 1 < len(plan):
                nxt = plan[i + 1]
                if nxt.speed == 0:
                    remaining = nxt.s0 - s
                    # Slowing first: over stop_lead to STOP_APPROACH, then the braking.
                    slow_down = v * b.stop_lead * (1 + STOP_APPROACH) / 2
                    reach = v * b.stop_time / 2 * STOP_APPROACH + slow_down
                    if b.stop_lead > 0 and approach_from == math.inf and remaining <= reach:
                        approach_from = t
                    if remaining <= v * (b.stop_time / 2 + H):  # brake now to stop there
                        mode, t0, v0, s_stop = "brake", t, v, nxt.s0
                        duration = max(2 * max(remaining, 0.0) / max(v, 1e-9), H)
                elif s >= nxt.s0:
                    change = abs(nxt.speed - plan[i].speed) / max(nxt.speed, plan[i].speed)
                    if nxt.speed < plan[i].speed:
                        events.append((t, "slow"))
                    i += 1
                    if change > 1e-9:
                        mode, t0, v0, duration = "ramp", t, v, max(b.start_time * change, H)
            times.append(t)
            arcs.append(s)
        return np.array(times), np.array(arcs), events


def set_off_time(b: HumanWalker, spec: Plan, seed: int) -> float:
    """When the walker sets off: the plan's start, or what meets the plan's anchor."""
    plan = stretches(spec)
    first = next((p for p in plan if p.speed > 0), None)
    if first is None:
        return 0.0
    if first.time == 0.0:
        return -PREROLL  # walking at t = 0: it set off long before
    if spec.anchor is None:
        return first.time
    s_anchor = _arc_at(plan, spec.anchor.time)  # where the plan is then, along the route
    walk = Walk(plan, b, wander_tables(seed)[0])
    times, arcs, _ = walk.profile(0.0, 0.0, spec.anchor.time + 4 * b.start_time + 20.0, s_anchor)
    if not (0 < s_anchor <= arcs[-1]):
        return first.time
    return spec.anchor.time - float(np.interp(s_anchor, arcs, times))


def wander_tables(seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng([int(seed), 0x4855])  # "HU": the walker's own stream
    return _wander(rng, WANDER_PERIODS), _wander(rng, WANDER_WAVELENGTHS)


def human_track(b: HumanWalker, spec: Plan, t_end: float, seed: int, t_start: float) -> Track:
    """The walker's Track from 0 to at least t_end, setting off at `t_start`."""
    for name in ("start_time", "stop_time", "max_yaw_rate"):
        if not getattr(b, name) > 0:
            raise ValueError(f"behaviour.{name} must be > 0, got {getattr(b, name)}")
    speed_table, line_table = wander_tables(seed)
    plan = stretches(spec)
    walk = Walk(plan, b, speed_table)
    times, arcs, events = walk.profile(t_start, 0.0, t_end + H)
    if t_start < 0:  # at t = 0 it is at arc length 0, where the plan starts
        offset = float(np.interp(0.0, times, arcs))
        times, arcs, events = walk.profile(t_start, -offset, t_end + H)
        at_zero = float(np.interp(0.0, times, arcs))
        keep = times > 1e-6
        times, arcs = np.concatenate([[0.0], times[keep]]), np.concatenate([[at_zero], arcs[keep]])
    elif t_start > 1e-6:  # standing where the plan starts until it sets off (a vertex every
        # H seconds too: the head may turn while it stands)
        standing = np.arange(0.0, t_start - H / 2, H)
        times = np.concatenate([standing, times])
        arcs = np.concatenate([np.zeros(len(standing)), arcs])
    else:
        times = times - times[0]
    path = route(spec, plan, b.max_yaw_rate)
    speeds, phases, surge, sway = strides(b, times, arcs, spec.looks.height, seed)
    base = np.empty((len(times), 2))
    tangents = np.empty(len(times))
    for k, s in enumerate(arcs):
        base[k], tangents[k] = path.point(float(s))
    side = b.lateral_wander * sines(line_table, arcs) + sway
    ahead = np.column_stack([np.cos(tangents), np.sin(tangents)])
    normal = np.column_stack([-ahead[:, 1], ahead[:, 0]])
    points = base + side[:, None] * normal + surge[:, None] * ahead
    steps = np.diff(points, axis=0)
    moving = np.hypot(steps[:, 0], steps[:, 1]) > 1e-9
    yaws = tangents.copy()
    yaws[:-1][moving] = np.arctan2(steps[moving, 1], steps[moving, 0])
    end = np.zeros(2)
    if len(times) > 1 and moving[-1]:
        end = steps[-1] / (times[-1] - times[-2])
        yaws[-1] = yaws[-2]
    head, torso = intent_cues(b, times, tangents, speeds, events, seed)
    return Track.from_vertices(
        times, points, yaws, end, footprint_yaws=tangents, phases=phases, head_yaws=head,
        torso_yaws=torso,
    )  # fmt: skip


def strides(b: HumanWalker, times: np.ndarray, arcs: np.ndarray, height: float, seed: int
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Stride-level motion along a walk (arc length `arcs` at `times`): each vertex's
    speed, the stride phase, the body's surge (m ahead: twice a stride) and sway (m to the
    left: once a stride), faded in as the walker gets going. The same phase drives the
    mannequin's legs."""
    rng = np.random.default_rng([int(seed), 0x5354])  # "ST"
    ds, dt = np.diff(arcs), np.diff(times)
    # Each vertex's speed is the one it was reached at (so the vertex where a standing
    # walker sets off is still where it stood); the first vertex's, the one it leaves at.
    speeds = np.concatenate([[ds[0] / dt[0]], ds / dt]) if len(ds) else np.zeros(1)
    steps_m = np.array([step_length(float(v), height) for v in speeds])
    with np.errstate(divide="ignore", invalid="ignore"):
        dphase = np.where(steps_m[1:] > 0, ds / (2 * steps_m[1:]), 0.0)
    phases = float(rng.uniform()) + np.concatenate([[0.0], np.cumsum(dphase)])
    going = np.clip(speeds / GOING, 0.0, 1.0)
    surge = b.surge * steps_m / (2 * math.pi) * np.sin(4 * math.pi * phases) * going
    sway = b.sway * np.sin(2 * math.pi * phases) * going
    return speeds, phases, surge, sway


def _arc_at(plan: list[Stretch], t: float) -> float:
    """The plan's arc length at time t (its instant starts and stops)."""
    s = 0.0
    for p in plan:
        if p.time > t:
            break
        s = p.s0 + p.speed * (t - p.time)
    return s


TRAFFIC_FROM = math.pi  # world heading toward the traffic that approaches (the robot drives east)
CHECK_AFTER_STOP = 0.2  # s after arriving at a stop that a check begins


def _bump(u: np.ndarray) -> np.ndarray:
    """A head check's shape over its duration (u in [0, 1]): out, held, back."""
    rise = np.clip(u / 0.3, 0.0, 1.0)
    fall = np.clip((1.0 - u) / 0.3, 0.0, 1.0)
    shape = (1 - np.cos(np.pi * np.minimum(rise, fall))) / 2
    return np.where((u >= 0) & (u <= 1), shape, 0.0)


def intent_cues(
    b: HumanWalker,
    times: np.ndarray,
    path_yaws: np.ndarray,
    speeds: np.ndarray,
    events: list[tuple[float, str]],
    seed: int,
) -> tuple[np.ndarray, np.ndarray]:
    """(head turned from the shoulders, shoulders turned from the walking line), radians.

    Head checks toward the traffic: `head_check_lead` before setting off, just after
    arriving at a stop, at a slower stretch (a hesitation), and every
    `head_check_interval` while walking or standing; each with `head_check_probability`,
    its own draw from the seed. The shoulders follow `torso_share` of a check. In turns
    the head looks `turn_lead` ahead along the walking line, the shoulders half as far.
    Nothing here moves the walker: the cues turn its head and shoulders only.
    """
    rng = np.random.default_rng([int(seed), 0x4943])  # "IC"
    yaw = np.unwrap(path_yaws)
    checks = np.zeros(len(times))
    p, duration = b.head_check_probability, b.head_check_duration
    starts: list[float] = []
    for t, kind in events:
        if kind == "set-off":
            starts.append(t - b.head_check_lead)
        elif kind == "stop":
            starts.append(t + CHECK_AFTER_STOP)
        else:
            starts.append(t)
    walking = speeds > 0.5
    t_end = float(times[-1])
    k = 1
    while b.head_check_interval > 0 and k * b.head_check_interval < t_end:
        t = k * b.head_check_interval
        i = min(int(np.searchsorted(times, t)), len(times) - 1)
        if walking[i] or not walking.any():
            starts.append(t)
        k += 1
    for start in sorted(starts):
        if rng.uniform() >= p or start + duration <= 0:
            continue
        i = min(max(int(np.searchsorted(times, start)), 0), len(times) - 1)
        toward = float(math.remainder(TRAFFIC_FROM - yaw[i], 2 * math.pi))
        amplitude = math.copysign(min(math.radians(b.head_check_amplitude), abs(toward)), toward)
        checks += amplitude * _bump((times - start) / duration)
    limit = math.radians(b.head_check_amplitude)
    checks = np.clip(checks, -limit, limit)
    ahead = np.interp(times + b.turn_lead, times, yaw) - yaw
    half = np.interp(times + b.turn_lead / 2, times, yaw) - yaw
    torso = b.torso_share * checks + 0.5 * half
    head = checks + ahead - torso
    return head, torso
