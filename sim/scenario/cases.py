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
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

from monopic.cases import GROUND_DEAD_ZONE_MPS, SECTOR_RATIO, Case
from sim.scenario import presets
from sim.scenario.families import PlacementError
from sim.scenario.spec import (
    Anchor,
    MannequinSpec,
    PedestrianSpec,
    RobotSpec,
    Scenario,
    SceneSpec,
)
from sim.scenario.walkers import RailWalker, Walker

OBLIQUE_RANGE_DEG = (
    math.degrees(math.atan(SECTOR_RATIO)),
    90 - math.degrees(math.atan(SECTOR_RATIO)),
)


def case_heading_deg(case: Case, angle_deg: float = 45.0, facing_deg: float = 180.0) -> float:
    """Walking direction of a case relative to the robot's heading, degrees CCW."""
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


def _param(
    default: float | None, low: float, high: float | None, unit: str, doc: str, **flags: bool
) -> Any:
    """A placement parameter: its default, its range (the one every entry point checks)."""
    return field(default=default, metadata={"low": low, "high": high, "unit": unit, "doc": doc,
                                            **flags})  # fmt: skip


@dataclass(frozen=True)
class CasePlacement:
    """Where and how the pedestrian walks one of the nine cases (see the module docstring).

    The one home of the placement's defaults and ranges: the record and closed-loop
    commands, scenario files (`path.kind = "case"`) and the benchmarks fill it, and its
    check names the parameter (PlacementError.field) so each can name its own key.
    """

    case: Case
    distance: float = _param(
        8.0, 0.0, 200.0, "m", "ahead of the robot's start where the path passes at meet_time"
    )
    lateral_offset: float = _param(0.0, -50.0, 50.0, "m", "to the left of that point")
    pedestrian_speed: float = _param(
        presets.PEDESTRIAN_SPEED,
        GROUND_DEAD_ZONE_MPS,
        presets.MAX_PEDESTRIAN_SPEED,
        "m/s",
        "walking speed (case 9 stands)",
    )
    robot_speed: float = _param(presets.ROBOT_SPEED, 0.0, 40.0, "m/s", "the robot's speed")
    angle_deg: float = _param(
        45.0,
        OBLIQUE_RANGE_DEG[0],
        OBLIQUE_RANGE_DEG[1],
        "degrees",
        "oblique cases: off the robot's heading",
        strict=True,
    )
    meet_time: float | None = _param(
        None, 0.0, None, "s", "when the path passes the point (default: mid-run)"
    )
    facing_deg: float = _param(
        180.0, -360.0, 360.0, "degrees", "case 9: which way the person faces (180: the camera)"
    )
    duration: float = _param(
        presets.DURATION_S, 0.0, presets.MAX_DURATION_S, "s", "run length", open_low=True
    )
    horizon: float = _param(
        presets.HORIZON_S, 0.0, presets.MAX_HORIZON_S, "s", "warning horizon", open_low=True
    )
    dt: float = _param(
        1.0 / presets.FPS,
        1.0 / presets.FPS_RANGE[1],
        1.0 / presets.FPS_RANGE[0],
        "s",
        "time per frame",
    )
    seed: int = _param(0, 0, 2**31 - 1, "", "world seed (gait phase)")

    def __post_init__(self) -> None:
        object.__setattr__(self, "case", Case(self.case))
        for f in fields(self):
            if f.name == "case" or not f.metadata:
                continue
            if f.name == "pedestrian_speed" and self.case is Case.STILL:
                continue  # a standing person has no walking speed
            if f.name == "angle_deg" and not (self.case.lateral and self.case.depth):
                continue  # only the obliques walk at an angle
            value = getattr(self, f.name)
            if value is None:
                continue
            problem = _out_of_range(
                value, f.metadata, self.duration if f.name == "meet_time" else None
            )
            if problem:
                raise PlacementError(f.name, value, problem)

    @property
    def walking_speed(self) -> float:
        return 0.0 if self.case is Case.STILL else float(self.pedestrian_speed)

    def scenario(
        self,
        looks: MannequinSpec | None = None,
        robot: RobotSpec | None = None,
        scene: SceneSpec | None = None,
        name: str | None = None,
        behaviour: Walker | None = None,
    ) -> Scenario:
        """The scenario: `robot` gives the robot's size, camera and limits (its speed is
        replaced by robot_speed); `looks` the mannequin (default adult)."""
        case, speed = self.case, self.walking_speed
        meet = self.duration / 2 if self.meet_time is None else float(self.meet_time)
        heading = case_heading_deg(case, self.angle_deg, self.facing_deg)
        h = math.radians(heading)
        pedestrian = PedestrianSpec(
            x=self.distance - speed * meet * math.cos(h),
            y=self.lateral_offset - speed * meet * math.sin(h),
            heading_deg=heading,
            speed=speed,
            looks=looks or MannequinSpec.adult(),
            behaviour=behaviour or RailWalker(),
            anchor=Anchor(meet, self.distance, self.lateral_offset) if speed > 0 else None,
        )
        return Scenario(
            name=name or f"case{int(case)}-{case.label.replace(' ', '-')}",
            pedestrian=pedestrian,
            robot=replace(robot or RobotSpec(), speed=self.robot_speed),
            scene=scene or SceneSpec(),
            family="cases",
            case=case,
            duration=self.duration,
            dt=self.dt,
            horizon=self.horizon,
            seed=self.seed,
        )


def _out_of_range(value: float, meta: Mapping[str, Any], high: float | None) -> str:
    """Why `value` is outside the parameter's range ('' when inside)."""
    low, high = meta["low"], meta["high"] if high is None else high
    unit = f" {meta['unit']}" if meta["unit"] else ""
    if not math.isfinite(value):
        return "must be a finite number"
    if meta.get("strict") and not low < value < high:
        return f"must lie strictly between {low:.1f} and {high:.1f}{unit}"
    if meta.get("open_low") and not value > low:
        return f"must be > {low:g}{unit}"
    if value < low:
        return f"must be >= {low:g}{unit}"
    if high is not None and value > high:
        return f"must be <= {high:g}{unit}"
    return ""


PLACEMENT_FIELDS = {f.name: f for f in fields(CasePlacement) if f.name != "case"}


def default_crossing() -> Scenario:
    """An adult crossing from the left into the robot's path: contact at 2.7 s unless it brakes."""
    placement = CasePlacement(
        Case.PERPENDICULAR_RIGHT, distance=6.0, robot_speed=2.0, meet_time=3.0, duration=5.0
    )
    return placement.scenario(name="crossing-from-left")
