"""What a scenario family means: robot presets, looks, and NCAP-style placement.

Euro NCAP's pedestrian tests put the pedestrian so that, if nobody brakes, the front of
the vehicle strikes them at a chosen point across its width at a chosen time. Here that
is solved backwards: from the robot's speed, the impact time and the impact point the
pedestrian's start position (and, when it would otherwise start too far away, a standing
delay before it walks) follow exactly, so the ground-truth path meets the robot's
footprint where the family says. Everything is in the world frame of sim.geometry.frames with
the robot starting at the origin heading east (+x); right-hand traffic, so the nearside
is the robot's right (-y) and the far side its left (+y).

Impact point convention: a fraction of the robot's width measured from the edge the
pedestrian comes from (crossing) or from the robot's right edge (longitudinal). Values
in [0, 1] strike the front; values outside make a near miss (above 1: the pedestrian has
cleared the far edge when the robot passes; below 0: it has not reached the path yet).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum

from sim.scenario import presets
from sim.scenario.spec import (
    Anchor,
    CameraSpec,
    Leg,
    MannequinSpec,
    Occluder,
    PedestrianSpec,
    RoadLayout,
    RobotSpec,
)
from sim.scenario.walkers import RailWalker, Walker

# Clearance between the pedestrian and the kerb line when it stops or turns there.
KERB_STOP_GAP = 0.2  # m
# Euro NCAP AEB VRU test protocol: a crossing pedestrian target reaches its speed over
# 1.0 m (near side) or 1.5 m (far side) from standing.
ACCELERATION_DISTANCE = {"near": 1.0, "far": 1.5}  # m


class Scale(StrEnum):
    """The two robot sizes the families are written for."""

    CAR = "car"
    SMALL = "small"


@dataclass(frozen=True)
class ScalePreset:
    """Defaults a scenario file gets from its `scale`: robot, camera, road, horizon."""

    robot: RobotSpec
    road: RoadLayout
    horizon: float  # s, the warning horizon


# A small camera-carrying robot (0.6 m wide) on the right lane of a two-lane street, the
# paper's 1 s horizon. Robot, camera and horizon are sim.scenario.presets' defaults.
SMALL = ScalePreset(
    robot=RobotSpec(
        speed=presets.ROBOT_SPEED,
        width=presets.ROBOT_WIDTH,
        length=presets.ROBOT_LENGTH,
        camera=CameraSpec(),
        max_speed=3.0,
    ),
    road=RoadLayout(lanes=2, lane_width=3.5, center_y=1.75),
    horizon=presets.HORIZON_S,
)

# A family car (1.8 m x 4.5 m) in the middle lane of a three-lane street whose nearside
# lane is a parking lane. Its camera sits behind the windscreen (1.3 m high, 0.8 m ahead
# of the footprint's centre) with a narrower field of view than the small robot's, as
# automotive forward cameras have. The 2 s horizon lets a warning come at a time to
# collision of 1.7 s or more (Euro NCAP's timely forward collision warning).
CAR = ScalePreset(
    robot=RobotSpec(
        speed=8.33,
        width=1.8,
        length=4.5,
        camera=CameraSpec(
            vertical_fov_deg=45.0, mount_height=1.3, pitch_deg=2.0, mount_forward=0.8
        ),
        max_speed=20.0,
        max_deceleration=9.0,
    ),
    road=RoadLayout(lanes=3, lane_width=3.0, center_y=0.0),
    horizon=2.0,
)

SCALES: dict[Scale, ScalePreset] = {Scale.CAR: CAR, Scale.SMALL: SMALL}

BODIES = ("adult", "child")

# Clothing presets: overrides of MannequinSpec's colours and patterns.
CLOTHING: dict[str, dict[str, object]] = {
    "default": {},
    "dark": {
        "shirt": (0.07, 0.07, 0.08, 1.0),
        "trousers": (0.05, 0.05, 0.06, 1.0),
        "long_sleeves": True,
    },
    "bright": {"shirt": (0.95, 0.78, 0.1, 1.0), "trousers": (0.25, 0.3, 0.6, 1.0)},
    "light": {"shirt": (0.9, 0.9, 0.88, 1.0), "trousers": (0.72, 0.66, 0.52, 1.0)},
    "checker": {"shirt_pattern": "checker"},
}


def mannequin(body: str, clothing: str, height: float | None = None) -> MannequinSpec:
    """The mannequin for a body preset (adult 1.8 m, child 1.15 m) in a clothing preset."""
    maker = MannequinSpec.adult if body == "adult" else MannequinSpec.child
    looks = maker(**CLOTHING[clothing])
    return looks if height is None else replace(looks, height=height)


def street_bounds(road: RoadLayout) -> tuple[float, float, float, float]:
    """(x_min, x_max, y_min, y_max) of the walkable street: road, kerbs and pavements."""
    kerb = 0.15
    y_right, y_left = road.edges
    half = road.length / 2
    return -half, half, y_right - kerb - road.pavement_width, y_left + kerb + road.pavement_width


class Side(StrEnum):
    NEAR = "near"  # from the robot's right (the kerb side in right-hand traffic)
    FAR = "far"  # from its left, across the other lanes


class Then(StrEnum):
    """What a crossing pedestrian does after starting to walk."""

    WALK = "walk"  # keeps walking across
    STOP_AT_KERB = "stop-at-kerb"  # stops short of the kerb (a near miss)
    TURN_AWAY = "turn-away"  # turns at the kerb and walks off along the pavement (a near miss)
    HESITATE = "hesitate"  # slows at the kerb for a moment, then walks on across
    STAND = "stand"  # stands at the kerb facing the road and never crosses (a near miss)


# A hesitation at the kerb (assumed): the pedestrian slows to this speed for this long.
HESITATE_SPEED = 0.3  # m/s
HESITATE_TIME = 1.0  # s
# Where a turn-in walker walks along the pavement: this far behind the kerb line.
PAVEMENT_LINE = 1.0  # m


@dataclass(frozen=True)
class Crossing:
    """A pedestrian crossing the robot's path at right angles (CPNA, CPFA, CPNCO).

    The pedestrian's centre reaches the impact point's lateral position at `impact_time`,
    having walked `approach` metres from where it stood; the crossing line lies where the
    robot's front is at that time (a standing robot: `standstill_distance` ahead of it).
    """

    side: Side
    impact_point: float  # fraction of the width from the entering edge
    impact_time: float  # s from the start
    approach: float  # m walked from the start to the impact point's lateral position
    then: Then = Then.WALK
    standstill_distance: float = 4.0  # m between a standing robot's front and the line
    # Set: the pedestrian stands this far behind the kerb line (replaces `approach`).
    from_kerb: float | None = None
    hesitate_speed: float = HESITATE_SPEED
    hesitate_time: float = HESITATE_TIME


@dataclass(frozen=True)
class TurnIn:
    """A pedestrian walking along the pavement who turns into the road and crosses it.

    It walks on the pavement PAVEMENT_LINE behind the kerb of `side`, with the robot
    (`toward` False) or against it, turns a quarter turn at the crossing line and crosses
    so that the robot's front strikes it at `impact_point` at `impact_time`.
    """

    side: Side
    impact_point: float
    impact_time: float
    toward: bool = False
    standstill_distance: float = 4.0


@dataclass(frozen=True)
class Longitudinal:
    """A pedestrian walking along the robot's path (CPLA: away; or toward it).

    Walking away, the robot reaches the pedestrian at `impact_time` when it is faster;
    otherwise (or standing) the pedestrian starts `standstill_distance` ahead of the
    front and is never reached.
    """

    impact_point: float  # fraction of the width from the robot's right edge
    impact_time: float
    toward: bool = False
    standstill_distance: float = 4.0


class Along(StrEnum):
    """Which way a person on the pavement faces or walks."""

    AWAY = "away"  # east, with the robot
    TOWARD = "toward"  # west, against it
    ROAD = "road"  # across, facing the road (standing only)


# Where a person on the pavement stands by default: this far behind the kerb line, the
# middle of the default 3 m pavement.
PAVEMENT_FROM_KERB = 1.5  # m


@dataclass(frozen=True)
class Pavement:
    """A person on the pavement of `side`: at `x` at the start, `from_kerb` metres behind
    the kerb line (the road's edge), standing or walking along it; placed on the street,
    not against the robot (a bystander's placement: no anchor, no case)."""

    side: Side
    x: float
    from_kerb: float = PAVEMENT_FROM_KERB
    along: Along | None = None  # None: facing the road when standing, else walking away


class PlacementError(ValueError):
    """A placement that cannot be built; `field` names the offending path key."""

    def __init__(self, field: str, value: object, reason: str) -> None:
        super().__init__(f"{field} = {value!r}: {reason}")
        self.field = field
        self.value = value
        self.reason = reason


def time_to_walk(distance: float, speed: float, accel_distance: float) -> float:
    """Seconds a rail target takes to walk `distance` from standing: it accelerates at a
    constant rate over `accel_distance` to `speed` (accel_distance / speed longer than at
    speed throughout), then keeps it."""
    if distance <= accel_distance:  # still accelerating: distance = a t^2 / 2
        return 2 * (distance * accel_distance) ** 0.5 / speed
    return (distance + accel_distance) / speed


def crossing_line_x(
    robot: RobotSpec, footprint: float, impact_time: float, standstill: float
) -> float:
    """World x of the pedestrian's centre line when the robot's front touches it."""
    front = robot.length / 2
    if robot.speed > 0:
        return robot.speed * impact_time + front + footprint / 2
    return front + footprint / 2 + standstill


def place_crossing(
    c: Crossing, robot: RobotSpec, road: RoadLayout, speed: float, looks: MannequinSpec,
    footprint: float = presets.FOOTPRINT, behaviour: Walker | None = None,
) -> PedestrianSpec:  # fmt: skip
    """The pedestrian of a crossing (see Crossing), legs included for the near misses.

    The plan is the rail target's: standing, then accelerating over the walker's start
    distance (the rail target's own acceleration distance, else the protocol's for the
    side) and walking on at speed; it passes the impact point at impact_time (the anchor),
    having walked `approach` metres from where it stood. A human walker (start distance
    0) meets the same anchor its own way.
    """
    behaviour = (behaviour or RailWalker()).placed(ACCELERATION_DISTANCE[c.side.value])
    accel = behaviour.start_distance
    if not speed > 0:
        raise PlacementError("pedestrian.speed", speed, "a crossing pedestrian must walk (> 0 m/s)")
    if accel > c.approach:
        raise PlacementError(
            "path.approach", c.approach,
            f"shorter than the target's acceleration distance ({accel:g} m)",
        )  # fmt: skip
    direction = 1.0 if c.side is Side.NEAR else -1.0  # +1 walks north (to the robot's left)
    entering_edge = -direction * robot.width / 2
    y_impact = entering_edge + direction * c.impact_point * robot.width
    x_line = crossing_line_x(robot, footprint, c.impact_time, c.standstill_distance)
    y_right, y_left = road.edges
    kerb = y_right if direction > 0 else y_left
    y_stop = kerb - direction * (footprint / 2 + KERB_STOP_GAP)  # just short of the kerb
    if c.from_kerb is not None:
        c = replace(c, approach=(y_impact - (y_stop - direction * c.from_kerb)) * direction)
        if c.approach <= 0:
            raise PlacementError(
                "path.from_kerb", c.from_kerb, "the start is past the impact point"
            )
    if c.then is Then.STAND:  # it never walks: standing where it would set off, facing the road
        return PedestrianSpec(
            x=x_line, y=y_impact - direction * c.approach, heading_deg=90.0 * direction,
            speed=0.0, looks=looks, footprint=footprint, behaviour=behaviour,
        )  # fmt: skip
    walk_time = time_to_walk(c.approach, speed, accel)
    if c.then is Then.HESITATE:
        to_kerb = c.approach - (y_impact - y_stop) * direction
        slow_distance = c.hesitate_speed * c.hesitate_time
        if not (to_kerb > 0 and to_kerb + slow_distance < c.approach):
            raise PlacementError(
                "path.approach", c.approach,
                "the hesitation at the kerb must come after the start and before the impact point",
            )  # fmt: skip
        walk_time += c.hesitate_time - slow_distance / speed
    start_delay = c.impact_time - walk_time
    if start_delay < 0:
        raise PlacementError(
            "path.approach",
            c.approach,
            f"walking {c.approach} m at {speed:.3g} m/s takes {walk_time:.3g} s, longer than "
            f"impact_time {c.impact_time} s",
        )
    y0 = y_impact - direction * c.approach
    legs: tuple[Leg, ...] = ()
    if c.then is Then.HESITATE:
        at = start_delay + time_to_walk((y_stop - y0) * direction, speed, accel)
        legs = (Leg(at, c.hesitate_speed), Leg(at + c.hesitate_time, speed))
    elif c.then is not Then.WALK:
        to_kerb = (y_stop - y0) * direction
        if to_kerb <= 0:
            raise PlacementError(
                "path.approach",
                c.approach,
                f"the pedestrian starts past the kerb (y={y0:.2f} m), so it cannot {c.then} there",
            )
        at = start_delay + time_to_walk(to_kerb, speed, accel)
        # Turning away: a quarter turn to walk along the pavement in the robot's direction.
        turn = -90.0 * direction
        leg = Leg(at=at, speed=0.0) if c.then is Then.STOP_AT_KERB else Leg(at, speed, turn)
        legs = (leg,)
    return PedestrianSpec(
        x=x_line,
        y=y0,
        heading_deg=90.0 * direction,
        speed=speed,
        looks=looks,
        legs=legs,
        start_delay=start_delay,
        footprint=footprint,
        behaviour=behaviour,
        anchor=Anchor(c.impact_time, x_line, y_impact),
    )


def place_longitudinal(
    c: Longitudinal, robot: RobotSpec, speed: float, looks: MannequinSpec,
    footprint: float = presets.FOOTPRINT, behaviour: Walker | None = None,
) -> PedestrianSpec:  # fmt: skip
    """The pedestrian of a walk along the path (see Longitudinal), walking from the start."""
    y = -robot.width / 2 + c.impact_point * robot.width
    front = robot.length / 2 + footprint / 2
    meet = robot.speed * c.impact_time + front
    anchor = None
    if c.toward:
        x0 = meet + speed * c.impact_time
        anchor = Anchor(c.impact_time, meet, y)
    elif robot.speed > speed:
        x0 = meet - speed * c.impact_time
        anchor = Anchor(c.impact_time, meet, y)
    else:
        x0 = front + c.standstill_distance
    return PedestrianSpec(
        x=x0,
        y=y,
        heading_deg=180.0 if c.toward else 0.0,
        speed=speed,
        looks=looks,
        footprint=footprint,
        behaviour=behaviour or RailWalker(),
        anchor=anchor,
    )


def place_turn_in(
    c: TurnIn, robot: RobotSpec, road: RoadLayout, speed: float, looks: MannequinSpec,
    footprint: float = presets.FOOTPRINT, behaviour: Walker | None = None,
) -> PedestrianSpec:  # fmt: skip
    """The pedestrian of a turn-in (see TurnIn): walking from the start, one leg: the turn."""
    if not speed > 0:
        raise PlacementError("pedestrian.speed", speed, "a walking pedestrian needs > 0")
    direction = 1.0 if c.side is Side.NEAR else -1.0  # +1 crosses north
    entering_edge = -direction * robot.width / 2
    y_impact = entering_edge + direction * c.impact_point * robot.width
    x_line = crossing_line_x(robot, footprint, c.impact_time, c.standstill_distance)
    y_right, y_left = road.edges
    kerb = y_right if direction > 0 else y_left
    y_walk = kerb - direction * (footprint / 2 + KERB_STOP_GAP + PAVEMENT_LINE)
    t_turn = c.impact_time - (y_impact - y_walk) * direction / speed
    if t_turn <= 0:
        raise PlacementError(
            "path.impact_time", c.impact_time, "too early: it would turn before the run starts"
        )
    along = -1.0 if c.toward else 1.0  # with the robot: east
    heading = 180.0 if c.toward else 0.0
    turn = (90.0 * direction) * (1.0 if not c.toward else -1.0)
    return PedestrianSpec(
        x=x_line - along * speed * t_turn,
        y=y_walk,
        heading_deg=heading,
        speed=speed,
        looks=looks,
        legs=(Leg(t_turn, speed, turn),),
        footprint=footprint,
        behaviour=behaviour or RailWalker(),
        anchor=Anchor(c.impact_time, x_line, y_impact),
    )


def place_pavement(
    c: Pavement, road: RoadLayout, speed: float, looks: MannequinSpec,
    footprint: float = presets.FOOTPRINT, behaviour: Walker | None = None,
) -> PedestrianSpec:  # fmt: skip
    """The person of a Pavement placement: standing there (speed 0) or walking along the
    pavement at `speed` the whole run."""
    along = c.along or (Along.ROAD if speed == 0 else Along.AWAY)
    if along is Along.ROAD and speed > 0:
        raise PlacementError(
            "path.direction", along.value, "a person walking along the pavement walks away or "
            "toward (facing the road is for a person who stands: speed = 0)",
        )  # fmt: skip
    y_right, y_left = road.edges
    near = c.side is Side.NEAR
    y = y_right - c.from_kerb if near else y_left + c.from_kerb
    headings = {Along.AWAY: 0.0, Along.TOWARD: 180.0, Along.ROAD: 90.0 if near else -90.0}
    return PedestrianSpec(
        x=c.x,
        y=y,
        heading_deg=headings[along],
        speed=speed,
        looks=looks,
        footprint=footprint,
        behaviour=behaviour or RailWalker(),
    )


def parked_cars_around(x_line: float, y: float, gap: float) -> tuple[Occluder, Occluder]:
    """Two parked cars leaving `gap` metres free around the crossing line (CPNCO)."""
    length = Occluder.parked_car(0.0, 0.0).length
    offset = gap / 2 + length / 2
    return (
        Occluder.parked_car(x_line - offset, y, colour=(0.55, 0.1, 0.1)),
        Occluder(
            x=x_line + offset, y=y, length=4.9, width=1.9, height=1.8, colour=(0.2, 0.3, 0.45)
        ),
    )
