"""Scenario files: every shipped file loads; every mistake names the file, field and value;
the NCAP placement makes the ground truth meet the robot where and when the file says."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from monopic.cases import Case
from monopic.errors import UserError
from sim.runs.sweep import expand_spec, load_spec
from sim.scenario.files import ScenarioFileError, load
from sim.world.world import World
from tests.paths import ETH_UCY, SCENARIOS

SCENARIO_FILES = sorted([*SCENARIOS.glob("cases/*.toml"), *SCENARIOS.glob("families/**/*.toml")])
# Families replaying real walks read them from the shared data; without it they cannot load.
if not (ETH_UCY / "biwi_hotel.txt").is_file():
    SCENARIO_FILES = [p for p in SCENARIO_FILES if "shared:eth-ucy" not in p.read_text()]

BASE = """
name = "t"
scale = "small"
duration = 3.0
[robot]
speed = 2.0
[pedestrian]
speed = 1.4
[path]
kind = "case"
case = 5
distance = 6.0
"""


def write(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def error_of(path: Path) -> ScenarioFileError:
    with pytest.raises(ScenarioFileError) as info:
        load(path)
    return info.value


def test_all_shipped_scenario_files_load_and_name_their_case_or_kind() -> None:
    assert len([p for p in SCENARIO_FILES if p.parent.name == "cases"]) == 9
    assert len(SCENARIO_FILES) >= 9 + 20
    for path in SCENARIO_FILES:
        file = load(path)
        assert file.kind in ("case", "collision", "near-miss")
        if file.kind == "case":
            assert file.base.case is not None


def test_shipped_sweeps_expand_into_valid_runs_with_unique_ids() -> None:
    demo = expand_spec(load_spec(SCENARIOS / "sweeps" / "demo.toml"))
    large = expand_spec(load_spec(SCENARIOS / "sweeps" / "large.toml"))
    families = len(list((SCENARIOS / "families").glob("*/*.toml")))
    assert families >= 28  # Euro NCAP-style, near-miss and intent families at two scales
    assert len({r.family for r in demo}) == families + 1  # the cases and every family
    assert len(large) >= 500
    for runs in (demo, large):
        assert len({r.id for r in runs}) == len(runs)
    # Expansion is deterministic: the same spec gives the same runs (resume relies on it).
    again = expand_spec(load_spec(SCENARIOS / "sweeps" / "demo.toml"))
    assert [(r.id, r.scenario.seed) for r in again] == [(r.id, r.scenario.seed) for r in demo]


@pytest.mark.parametrize(
    ("edit", "field", "value", "reason"),
    [
        (("[robot]", "[robot]\nsped = 2.0"), "robot.sped", "2.0", "unknown key"),
        (("speed = 2.0", 'speed = "fast"'), "robot.speed", "'fast'", "must be a number"),
        (("speed = 2.0", "speed = -1.0"), "robot.speed", "-1.0", ">= 0"),
        (("speed = 1.4", "speed = nan"), "pedestrian.speed", "nan", "finite"),
        (("duration = 3.0", "duration = 3.0\nhorizon = 0"), "horizon", "0", "> 0"),
        (("duration = 3.0", "duration = 3.0\nbogus = 1"), "bogus", "1", "unknown key"),
        (("case = 5", "case = 12"), "path.case", "12", "integer in [1, 9]"),
        (("case = 5", "case = 5\nimpact_point = 0.5"), "path.impact_point", "0.5", "unknown key"),
        (('kind = "case"', 'kind = "teleport"'), "path.kind", "'teleport'", "must be one of"),
        (("scale = \"small\"", "scale = \"bus\""), "scale", "'bus'", "must be one of"),
        (("[robot]", "[robot.camera]\nwidth = 10.5\n[robot]"), "robot.camera.width", "10.5",
         "integer"),
        (("speed = 2.0", "speed = 2.9\nmax_speed = 2.5"), "robot.speed", "2.9", "<= 2.5"),
        (("[path]", "[scene]\nlighting = 'dusk'\n[path]"), "scene.lighting", "'dusk'", "one of"),
    ],
)  # fmt: skip
def test_each_bad_value_is_named_with_file_field_and_value(
    tmp_path: Path, edit: tuple[str, str], field: str, value: str, reason: str
) -> None:
    path = write(tmp_path, BASE.replace(*edit, 1))
    err = error_of(path)
    text = str(err)
    assert err.field == field
    assert text.startswith(f"{path}: {field} = {value}: "), text
    assert reason in text
    assert "\n" not in text


def test_a_path_that_leaves_the_street_is_rejected_with_the_point(tmp_path: Path) -> None:
    walk_north = 'kind = "explicit"\nx = 5.0\ny = 0.0\nheading_deg = 90.0'
    text = BASE.replace('kind = "case"\ncase = 5\ndistance = 6.0', walk_north)
    text = text.replace("speed = 1.4", "speed = 3.0")
    err = error_of(write(tmp_path, text))
    assert err.field == "path"
    assert "leaves the street" in str(err) and "y = " in str(err)


def test_robot_driving_off_the_road_and_parked_cars_in_its_path(tmp_path: Path) -> None:
    text = BASE.replace("duration = 3.0", "duration = 60.0").replace(
        "speed = 2.0", "speed = 2.0\nmax_speed = 3.0"
    )
    err = error_of(write(tmp_path, text))
    assert err.field == "robot.speed" and "off the end of the road" in str(err)
    cars = BASE + '[scene.parked_cars]\nplacement = "fixed"\ny = 0.5\nx = [5.0]\n'
    err = error_of(write(tmp_path, cars, "cars.toml"))
    assert err.field == "scene.parked_cars.y" and "robot's path" in str(err)


def test_crossing_that_cannot_reach_the_impact_in_time(tmp_path: Path) -> None:
    text = BASE.replace(
        'kind = "case"\ncase = 5\ndistance = 6.0',
        'kind = "crossing"\nside = "near"\nimpact_point = 0.5\nimpact_time = 1.0\napproach = 3.0',
    )
    err = error_of(write(tmp_path, text))
    assert err.field == "path.approach" and "longer than impact_time" in str(err)


def test_sweep_parameters_are_checked_on_load(tmp_path: Path) -> None:
    unknown = BASE + '[sweep]\n[sweep.parameters]\n"robot.sped" = [1.0]\n'
    err = error_of(write(tmp_path, unknown))
    assert err.field == "sweep.parameters.robot.sped" and "unknown key" in str(err)
    bad_value = BASE + '[sweep]\n[sweep.parameters]\n"robot.speed" = [1.0, -2.0]\n'
    err = error_of(write(tmp_path, bad_value, "b.toml"))
    assert err.field == "sweep.parameters.robot.speed" and "= -2.0" in str(err)
    no_steps = BASE + '[sweep]\n[sweep.parameters]\n"robot.speed" = { min = 0, max = 2 }\n'
    err = error_of(write(tmp_path, no_steps, "c.toml"))
    assert "steps" in str(err)


def test_not_toml_and_missing_file_name_the_file(tmp_path: Path) -> None:
    bad = write(tmp_path, "name = 'x\n")
    with pytest.raises(UserError, match=rf"^{bad}: not valid TOML"):
        load(bad)
    with pytest.raises(UserError, match="no such scenario file"):
        load(tmp_path / "missing.toml")


def test_grid_and_random_sampling(tmp_path: Path) -> None:
    grid = BASE + (
        '[sweep]\nsampling = "grid"\n[sweep.parameters]\n"robot.speed" = [0.0, 1.0]\n'
        '"path.distance" = { min = 5.0, max = 7.0, steps = 3 }\n'
    )
    combos = list(load(write(tmp_path, grid)).runs())
    assert len(combos) == 6
    assert {c["path.distance"] for c in combos} == {5.0, 6.0, 7.0}
    rand = BASE + (
        '[sweep]\nsampling = "random"\nruns = 20\nseed = 3\n[sweep.parameters]\n'
        '"robot.speed" = { min = 0.5, max = 1.5 }\n"pedestrian.clothing" = ["dark", "bright"]\n'
    )
    first = list(load(write(tmp_path, rand, "r.toml")).runs())
    assert first == list(load(tmp_path / "r.toml").runs())  # seeded: same draws
    assert len(first) == 20 and all(0.5 <= c["robot.speed"] <= 1.5 for c in first)
    assert {c["pedestrian.clothing"] for c in first} == {"dark", "bright"}


@pytest.mark.parametrize(
    ("file", "params"),
    [
        ("families/car/cpna25.toml", {"robot.speed": 11.11, "path.impact_time": 4.6}),
        ("families/car/cpfa50.toml", {"robot.speed": 8.33, "path.impact_time": 4.3}),
        ("families/small/cpnco50.toml", {"robot.speed": 2.0, "path.impact_time": 4.5}),
        ("families/small/cpla25.toml", {"robot.speed": 3.0, "path.impact_time": 3.0}),
        ("families/small/cross_impact.toml", {"path.impact_point": 0.1, "path.side": "far"}),
        ("families/car/cross_impact.toml", {"path.impact_point": 0.9, "robot.speed": 5.56}),
    ],
)
@pytest.mark.parametrize("model", ["rail", "human"])
def test_ncap_placement_meets_the_robot_at_the_impact_time(
    file: str, params: dict, model: str
) -> None:
    """The truth's footprints first touch at impact_time, on the front at the impact point,
    whichever way the pedestrian walks there (the rail target or a human walker)."""
    f = load(SCENARIOS / file)
    scenario = f.scenario({**params, "pedestrian.behaviour.model": model}, "t", 0)
    assert scenario.pedestrian.behaviour.model == model
    impact = params.get("path.impact_time", f.data["path"]["impact_time"])
    with World(scenario, render=False) as world:
        truth = world.reset().truth
        assert truth.pedestrian.time_to_collision == pytest.approx(impact, abs=1e-6)
        # Where the pedestrian is at contact, across the robot's width.
        side = params.get("path.side", f.data["path"].get("side", "near"))
        share = params.get("path.impact_point", f.data["path"]["impact_point"])
        ped = world.pedestrian.path.state(impact).position  # type: ignore[union-attr]
        width = scenario.robot.width
        entering = -width / 2 if side == "near" or "cpla" in file else width / 2
        across = abs(ped[1] - entering) / width
        assert across == pytest.approx(share, abs=1e-6)
        assert ped[0] - scenario.pedestrian.footprint / 2 == pytest.approx(
            scenario.robot.speed * impact + scenario.robot.length / 2, abs=1e-6
        )


@pytest.mark.parametrize(
    "file",
    ["families/car/nearmiss_clears.toml", "families/small/nearmiss_kerb_stop.toml",
     "families/car/nearmiss_turn_away.toml", "families/car/cpna25.toml"],
)  # fmt: skip
def test_near_misses_and_a_standing_robot_never_meet_the_pedestrian(file: str) -> None:
    f = load(SCENARIOS / file)
    speed = 0.0 if "cpna" in file else f.base.robot.speed
    scenario = f.scenario({"robot.speed": speed}, "t", 0)
    with World(scenario, render=False) as world:
        truth = world.reset().truth
        assert (
            truth.pedestrian.time_to_collision is None
            or truth.pedestrian.time_to_collision > scenario.duration
        )
    if "cpna" in file:
        assert scenario.case is Case.PERPENDICULAR_LEFT
    assert math.isfinite(scenario.horizon)


def test_overcast_lighting_turns_the_shadow_pass_off(tmp_path: Path) -> None:
    sunny = load(write(tmp_path, BASE, "sunny.toml")).base
    overcast = load(write(tmp_path, BASE + '[scene]\nlighting = "overcast"\n', "o.toml")).base
    assert sunny.scene.lighting.shadows and not overcast.scene.lighting.shadows
    assert (sunny.scene.lighting.name, overcast.scene.lighting.name) == ("noon", "overcast")
    with World(overcast, render=False) as world:
        assert not world.scene.model.light_castshadow.any()
    with World(sunny, render=False) as world:
        assert world.scene.model.light_castshadow.any()
