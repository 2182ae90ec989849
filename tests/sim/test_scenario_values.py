"""Scenario values that pass their type check but no street holds are refused with the
file, the dotted field and the value (sim.scenario.files)."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.scenario.files import ScenarioFileError, load

BASE = """
name = "t"
scale = "small"
duration = 3.0
[robot]
speed = {robot_speed}
[pedestrian]
speed = 1.4
"""
CASE = '[path]\nkind = "case"\ncase = 5\ndistance = 6.0\n'
CROSSING = (
    '[path]\nkind = "crossing"\nside = "near"\nimpact_point = 0.5\nimpact_time = 3.0\n'
    "approach = 3.0\n"  # m: the rail target accelerates over 1 m, so 3 m fit in 3 s
)
ALONG = '[path]\nkind = "longitudinal"\nimpact_point = 0.5\nimpact_time = 2.0\n'
EXPLICIT = '[path]\nkind = "explicit"\nx = 5.0\ny = -3.0\nheading_deg = 90.0\n'
PARKED = '[scene.parked_cars]\nplacement = "fixed"\n'
ROAD = "[scene.road]\n"

ABSURD = [
    # (robot speed, rest of the file, field, value, reason)
    (2.0, CASE + ROAD + "crosswalk_x = 1e12\n", "scene.road.crosswalk_x", 1e12, "off the road"),
    (2.0, CASE + ROAD + "crosswalk_x = -500.0\n", "scene.road.crosswalk_x", -500.0, "off the road"),
    (0.0, CROSSING + "standstill_distance = 1e12\n", "path.standstill_distance", 1e12, "<= 200"),
    (0.0, ALONG + "standstill_distance = 5000.0\n", "path.standstill_distance", 5000.0, "<= 200"),
    (2.0, EXPLICIT + "start_delay = 1e300\n", "path.start_delay", 1e300, "<= 3 s"),
    (2.0, EXPLICIT + "legs = [{at = 1e300, speed = 1.0}]\n", "path.legs[0].at", 1e300, "<= 3 s"),
    (2.0, CASE + PARKED + "y = 1e9\nx = [5.0]\n", "scene.parked_cars.y", 1e9, "off the street"),
    (2.0, CASE + PARKED + "y = -4.0\nx = [1e9]\n", "scene.parked_cars.x", [1e9], "off the road"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("robot_speed", "rest", "field", "value", "reason"),
    ABSURD,
    ids=[f"{case[2]}={case[3]}" for case in ABSURD],
)
def test_physically_absurd_values_are_refused_with_file_field_and_value(
    tmp_path: Path, robot_speed: float, rest: str, field: str, value: object, reason: str
) -> None:
    path = tmp_path / "absurd.toml"
    path.write_text(BASE.format(robot_speed=robot_speed) + rest)
    with pytest.raises(ScenarioFileError) as info:
        load(path)
    err = info.value
    assert (err.file, err.field, err.value) == (str(path), field, value)
    assert reason in err.reason and "\n" not in str(err)


def test_the_same_files_with_sensible_values_load(tmp_path: Path) -> None:
    sensible = [
        (2.0, CASE + "[scene.road]\ncrosswalk_x = -20.0\n"),
        (0.0, CROSSING + "standstill_distance = 12.0\n"),
        (2.0, EXPLICIT + "start_delay = 1.0\nlegs = [{at = 2.5, speed = 1.0}]\n"),
        (2.0, CASE + PARKED + "y = -4.0\nx = [5.0, 60.0]\n"),
    ]
    for k, (robot_speed, rest) in enumerate(sensible):
        path = tmp_path / f"ok{k}.toml"
        path.write_text(BASE.format(robot_speed=robot_speed) + rest)
        load(path)
