"""Intent labels from the simulator's truth: what the pedestrian will do within the horizon.

The pipeline never sees these; they are what a learner is trained and judged against.
Everything is in the robot's frame at the labelled time: the robot keeps its course, so
its path is the line ahead along its current heading, and a pedestrian's side of it is
the sign of their lateral position (+ left) now.

Four classes, from the pedestrian's true Track (sim.scenario.track) over (t, t + horizon]:

- stop: moving now (own ground speed at least the dead zone, monopic.cases'
  GROUND_DEAD_ZONE_MPS) and the speed falls below it within the horizon. Read on the
  Track's own pieces, so the time is exact: a stop reached exactly at the horizon counts.
- turn away: walking now (the trailing mean speed below at the dead zone or more), the
  direction turns away from the path's centre line by as much as `dead_zone` of lateral
  speed at the speed now (the share of the walk toward the centre line drops by
  dead_zone / speed), while the pedestrian still walks (trailing mean and Track speed
  at the dead zone or more: a stopped walker's mean moves on for a while): a crossing
  walker turning to walk along the kerb or back, one walking along the path
  stepping aside. Standing now: walking off away from the path at the dead zone or more;
- start crossing: walking now, the direction turns toward the centre line by as much
  (one walking along the kerb turning in), and the lateral speed toward it reaches the
  dead zone; standing now: walking off toward the path at the dead zone or more (one
  waiting at the kerb stepping off). Direction, not lateral speed, so that slowing down
  or speeding up on the same line is neither;
- keep going: none of these (walking on as now, standing on, or crossing on).

Turns are read on mean velocities over the trailing `smoothing` seconds (0.5 s, about
one step at 1.8 steps/s): a human walker's stride surge (12 % of its speed twice a
stride) and sway would otherwise read as turns. Trailing, so an event at time tau means
the motion up to tau already shows it; "now" is the last half second, what the robot
could have seen. Turn events are found on a `step` grid (0.05 s) in (t, t + horizon].
The earliest event wins; at the same time stop before turn away before start crossing.
On the centre line itself (|lateral| < 1 mm) there is no side: any lateral motion
leads away from the centre, so it counts as away.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np

from monopic.cases import GROUND_DEAD_ZONE_MPS, Case, case_from_ground_velocity
from sim.geometry.frames import Pose2D
from sim.scenario.track import Track

ON_CENTRE_M = 1e-3  # m: closer to the centre line than this, the pedestrian has no side


class Intent(StrEnum):
    """What the pedestrian does within the horizon, against the robot's path."""

    KEEP_GOING = "keep going"
    STOP = "stop"
    TURN_AWAY = "turn away"
    START_CROSSING = "start crossing"


# At the same event time, the first of these wins.
_PRECEDENCE = (Intent.STOP, Intent.TURN_AWAY, Intent.START_CROSSING)


@dataclass(frozen=True)
class IntentConfig:
    """How motion is read from the truth; defaults from the walker's stride, not tuned."""

    dead_zone: float = GROUND_DEAD_ZONE_MPS  # m/s: moving, and a change that counts
    smoothing: float = 0.5  # s, trailing mean of the lateral velocity
    step: float = 0.05  # s, grid of the turn events

    def __post_init__(self) -> None:
        for name in ("dead_zone", "smoothing", "step"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be positive, got {value}")


@dataclass(frozen=True)
class IntentLabel:
    """The intent class, when it happens, and the case of the motion now."""

    intent: Intent
    time: float | None  # s from now to the event; None for keep going
    case_now: Case  # monopic.cases' case of the pedestrian's own velocity now


def trailing_velocity(track: Track, times: np.ndarray, window: float) -> np.ndarray:
    """(n, 2) mean world velocity over [tau - window, tau] (clipped at the Track's start).

    At tau = 0 there is no past: the velocity of the piece starting there.
    """
    times = np.asarray(times, dtype=float)
    lo = np.maximum(times - window, 0.0)
    span = times - lo
    out = np.empty((len(times), 2))
    some = span > 1e-9
    out[some] = (track.positions_at(times[some]) - track.positions_at(lo[some])) / span[some, None]
    for k in np.flatnonzero(~some):
        out[k] = track.state(float(times[k])).velocity
    return out


def first_slow_time(track: Track, t: float, horizon: float, dead_zone: float) -> float | None:
    """The first time in (t, t + horizon] the Track's speed is below `dead_zone`, or None."""
    end = t + horizon
    k0 = int(np.searchsorted(track.times, t, side="right")) - 1
    k1 = int(np.searchsorted(track.times, end, side="right")) - 1
    v = track.velocities[k0 : k1 + 1]
    slow = np.flatnonzero(np.hypot(v[:, 0], v[:, 1]) < dead_zone)
    return max(float(track.times[k0 + slow[0]]), t) if slow.size else None


def intent_label(
    track: Track,
    t: float,
    robot: Pose2D,
    horizon: float,
    config: IntentConfig | None = None,
) -> IntentLabel:
    """Label time `t` of a pedestrian walking `track`, seen from a robot at `robot`."""
    c = config or IntentConfig()
    if not (math.isfinite(horizon) and horizon > 0):
        raise ValueError(f"horizon must be positive seconds, got {horizon}")
    cos, sin = math.cos(robot.yaw), math.sin(robot.yaw)

    def lateral(v: np.ndarray) -> np.ndarray:  # world vectors -> the robot's left axis
        return -sin * v[..., 0] + cos * v[..., 1]

    now = track.state(t)
    v_now = now.velocity
    forward_now = cos * v_now[0] + sin * v_now[1]
    case_now = case_from_ground_velocity(float(forward_now), float(lateral(v_now)))
    moving_now = now.speed >= c.dead_zone

    taus = t + np.linspace(0.0, horizon, max(1, round(horizon / c.step)) + 1)
    v = trailing_velocity(track, taus, c.smoothing)
    speed = np.hypot(v[:, 0], v[:, 1])
    side = float(lateral(now.position - np.array([robot.x, robot.y])))
    left = lateral(v)
    approach = -np.sign(side) * left if abs(side) >= ON_CENTRE_M else -np.abs(left)
    # Walking at tau: by the trailing mean and by the Track itself (a stopped walker's
    # trailing mean still moves for half a second, in the direction it walked).
    pieces = np.searchsorted(track.times, taus, side="right") - 1
    walking = (speed >= c.dead_zone) & (
        np.hypot(track.velocities[pieces, 0], track.velocities[pieces, 1]) >= c.dead_zone
    )
    if speed[0] >= c.dead_zone:
        # Walking now: a turn is a change of direction worth `dead_zone` of lateral speed
        # at today's speed, so slowing down or speeding up is not a turn.
        with np.errstate(invalid="ignore", divide="ignore"):
            direction = np.where(walking, approach / speed, np.nan)
        d0, dd = approach[0] / speed[0], c.dead_zone / speed[0]
        away_at = walking[1:] & (direction[1:] <= d0 - dd)
        toward_at = walking[1:] & (direction[1:] >= d0 + dd) & (approach[1:] >= c.dead_zone)
    else:  # standing now: walking off away from the path, or toward it
        away_at = walking[1:] & (approach[1:] <= -c.dead_zone)
        toward_at = walking[1:] & (approach[1:] >= c.dead_zone)

    events: dict[Intent, float] = {}
    if moving_now:
        stop = first_slow_time(track, t, horizon, c.dead_zone)
        if stop is not None:
            events[Intent.STOP] = stop - t
    for intent, at in ((Intent.TURN_AWAY, away_at), (Intent.START_CROSSING, toward_at)):
        hits = np.flatnonzero(at)
        if hits.size:
            events[intent] = float(taus[1 + hits[0]] - t)
    if not events:
        return IntentLabel(Intent.KEEP_GOING, None, case_now)
    first = min(events.values())
    intent = next(i for i in _PRECEDENCE if i in events and events[i] <= first + 1e-9)
    return IntentLabel(intent, events[intent], case_now)
