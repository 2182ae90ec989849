"""Scenarios for the paper's eight motion cases and standing still, from a few parameters.

The robot starts at the world origin heading east (robot frame = world frame at t = 0).
The pedestrian walks a straight line at constant speed in the case's direction relative
to the robot's heading, and passes the point `distance` metres ahead of the robot's start
and `lateral_offset` metres to its left at `meet_time` (default: the middle of the run).
So the mannequin is about `distance` away in the middle of the run whatever the
direction, and a crossing with distance = robot_speed * meet_time is on a collision
course. Directions, CCW from the robot's heading:

    1 oblique right away  -angle        5 perpendicular right  -90
    2 oblique left away   +angle        6 perpendicular left   +90
    3 oblique right toward -(180-angle) 7 toward the camera    180
    4 oblique left toward  180-angle    8 away, along its path   0
    9 still: standing at the point, facing `facing_deg` (default 180: the camera)

The ground-truth label of every frame is then the intended case (tests/test_world.py):
the label uses the pedestrian's own ground velocity, which the robot's motion does not
change.
"""

from __future__ import annotations

import math
from dataclasses import replace

from monopic.cases import GROUND_DEAD_ZONE_MPS, SECTOR_RATIO, Case
from sim.scenario.spec import MannequinSpec, PedestrianSpec, RobotSpec, Scenario, SceneSpec

OBLIQUE_RANGE_DEG = (
    math.degrees(math.atan(SECTOR_RATIO)),
    90 - math.degrees(math.atan(SECTOR_RATIO)),
)


def case_heading_deg(case: Case, angle_deg: float = 45.0, facing_deg: float = 180.0) -> float:
    """Walking direction of a case relative to the robot's heading, degrees CCW."""
    lo, hi = OBLIQUE_RANGE_DEG
    if case.lateral != 0 and case.depth != 0 and not lo < angle_deg < hi:
        raise ValueError(
            f"an oblique case needs angle_deg strictly between {lo:.1f} and {hi:.1f} "
            f"degrees from the robot's heading, got {angle_deg}"
        )
    return {
        Case.OBLIQUE_RIGHT_AWAY: -angle_deg,
        Case.OBLIQUE_LEFT_AWAY: angle_deg,
        Case.OBLIQUE_RIGHT_TOWARD: -(180.0 - angle_deg),
        Case.OBLIQUE_LEFT_TOWARD: 180.0 - angle_deg,
        Case.PERPENDICULAR_RIGHT: -90.0,
        Case.PERPENDICULAR_LEFT: 90.0,
        Case.TOWARD: 180.0,
        Case.AWAY: 0.0,
        Case.STILL: facing_deg,
    }[case]


def place_case(
    case: Case,
    distance: float = 8.0,
    lateral_offset: float = 0.0,
    pedestrian_speed: float = 1.4,
    robot_speed: float = 2.0,
    angle_deg: float = 45.0,
    meet_time: float | None = None,
    facing_deg: float = 180.0,
    duration: float = 4.0,
    looks: MannequinSpec | None = None,
    robot: RobotSpec | None = None,
    scene: SceneSpec | None = None,
    horizon: float = 1.0,
    dt: float = 1.0 / 15.0,
    seed: int = 0,
    name: str | None = None,
) -> Scenario:
    """A scenario showing `case` (see the module docstring for the geometry).

    `robot` gives the robot's size, camera and limits (its speed is replaced by
    `robot_speed`); `looks` the mannequin (default adult).
    """
    case = Case(case)
    for label, value in (("distance", distance), ("lateral_offset", lateral_offset)):
        if not math.isfinite(value):
            raise ValueError(f"{label} must be finite, got {value}")
    if not (math.isfinite(robot_speed) and robot_speed >= 0):
        raise ValueError(f"robot_speed must be >= 0 m/s, got {robot_speed}")
    if case is Case.STILL:
        pedestrian_speed = 0.0
    elif not (math.isfinite(pedestrian_speed) and pedestrian_speed >= GROUND_DEAD_ZONE_MPS):
        raise ValueError(
            f"case {case.label!r} needs a walking speed of at least {GROUND_DEAD_ZONE_MPS} m/s "
            f"(below that the ground truth is 'still'), got {pedestrian_speed}"
        )
    meet = duration / 2 if meet_time is None else float(meet_time)
    if not (math.isfinite(meet) and meet >= 0):
        raise ValueError(f"meet_time must be >= 0 s, got {meet_time}")
    heading = case_heading_deg(case, angle_deg, facing_deg)
    h = math.radians(heading)
    x0 = distance - pedestrian_speed * meet * math.cos(h)
    y0 = lateral_offset - pedestrian_speed * meet * math.sin(h)
    pedestrian = PedestrianSpec(
        x=x0,
        y=y0,
        heading_deg=heading,
        speed=pedestrian_speed,
        looks=looks or MannequinSpec.adult(),
    )
    return Scenario(
        name=name or f"case{int(case)}-{case.label.replace(' ', '-')}",
        pedestrian=pedestrian,
        robot=replace(robot or RobotSpec(), speed=robot_speed),
        scene=scene or SceneSpec(),
        family="cases",
        case=case,
        duration=duration,
        dt=dt,
        horizon=horizon,
        seed=seed,
    )


def default_crossing() -> Scenario:
    """An adult crossing from the left into the robot's path: contact at 2.7 s unless it brakes."""
    return place_case(
        Case.PERPENDICULAR_RIGHT,
        distance=6.0,
        robot_speed=2.0,
        pedestrian_speed=1.4,
        meet_time=3.0,
        duration=5.0,
        name="crossing-from-left",
    )
