"""Scenario files with several people: [[pedestrians]] entries, people files added by a
sweep spec's include, a person's keys by index, and one line for each mistake naming the
file, the person and the value."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from sim.runs.sweep import expand_spec, load_spec, run_scenario
from sim.scenario.files import ScenarioFileError, load
from sim.scenario.path import pedestrian_path
from sim.world.world import World
from tests.paths import SCENARIOS
from tests.sim.test_presets import keyed, readme_tables
from tests.sim.test_scenario_file import error_of, write

# The scripted person crosses from the nearside 6 m ahead of a standing small robot.
SCRIPTED = """
[pedestrian]
speed = 1.4
[pedestrian.behaviour]
model = "human"
[path]
kind = "crossing"
side = "near"
impact_point = 0.5
impact_time = 3.0
approach = 3.0
standstill_distance = 6.0
"""
TOP = 'name = "t"\nscale = "small"\nduration = 4.0\n[robot]\nspeed = 0.0\n'
# Two bystanders: one standing on the near pavement, one walking along the far one.
BYSTANDERS = """
[[pedestrians]]
name = "waiting"
speed = 0.0
[pedestrians.path]
kind = "pavement"
side = "near"
x = 3.0
[[pedestrians]]
name = "walker"
body = "child"
speed = 1.0
[pedestrians.path]
kind = "pavement"
side = "far"
x = 10.0
direction = "toward"
"""
PAIR = SCENARIOS / "people" / "pavement_pair.toml"


def test_a_pedestrian_table_and_the_same_person_listed_build_equal_scenarios(
    tmp_path: Path,
) -> None:
    listed = SCRIPTED.replace("[pedestrian]", "[[pedestrians]]").replace(
        "[pedestrian.behaviour]", "[pedestrians.behaviour]"
    ).replace("[path]", "[pedestrians.path]")  # fmt: skip
    table = load(write(tmp_path, TOP + SCRIPTED, "table.toml")).base
    as_entry = load(write(tmp_path, TOP + listed, "listed.toml"))
    assert as_entry.base == table and as_entry.base.bystanders == ()
    # The scripted person's keys mean them in either form.
    assert as_entry.scenario({"pedestrian.speed": 1.2}, "t") == as_entry.scenario(
        {"pedestrians.0.speed": 1.2}, "t"
    )
    # With neither [path] nor [[pedestrians]] a file has nobody: refused as it always was.
    err = error_of(write(tmp_path, TOP, "nobody.toml"))
    assert err.field == "path.kind" and "missing" in str(err)


def test_bystanders_from_the_file_reach_the_scenario_with_their_names(tmp_path: Path) -> None:
    s = load(write(tmp_path, TOP + SCRIPTED + BYSTANDERS)).base
    assert [p.name for p in s.bystanders] == ["waiting", "walker"]
    assert s.people[0] is s.pedestrian and s.pedestrian.name == ""
    waiting, walker = s.bystanders
    near, far = s.scene.road.edges
    assert (waiting.x, waiting.y, waiting.heading_deg, waiting.speed) == (3.0, near - 1.5, 90, 0)
    assert (walker.x, walker.y, walker.heading_deg) == (10.0, far + 1.5, 180.0)
    assert walker.looks.height == pytest.approx(1.15)
    track = pedestrian_path(walker, s.duration)
    assert track.state(2.0).position == pytest.approx([8.0, far + 1.5])


def test_the_scripted_persons_path_is_the_same_with_and_without_bystanders(
    tmp_path: Path,
) -> None:
    alone = load(write(tmp_path, TOP + SCRIPTED, "alone.toml")).base
    crowd = load(write(tmp_path, TOP + SCRIPTED + BYSTANDERS, "crowd.toml")).base
    assert crowd.pedestrian == alone.pedestrian
    times = np.linspace(0.0, alone.duration, 97)
    a = pedestrian_path(alone.pedestrian, alone.duration, alone.seed).positions_at(times)
    b = pedestrian_path(crowd.pedestrian, crowd.duration, crowd.seed).positions_at(times)
    assert np.array_equal(a, b)


def test_each_person_has_a_truth_of_their_own(tmp_path: Path) -> None:
    s = load(write(tmp_path, TOP + SCRIPTED + BYSTANDERS)).base
    with World(s, render=False) as world:
        truth = world.reset().truth
    assert [p.name for p in truth.people] == ["ped", "waiting", "walker"]
    assert truth.pedestrian is truth.people[0]
    assert truth.people[1].footprint_world.mean(axis=0) == pytest.approx(
        [s.bystanders[0].x, s.bystanders[0].y]
    )


def test_a_swept_person_key_changes_only_that_person(tmp_path: Path) -> None:
    sweep = '[sweep]\nsampling = "grid"\n[sweep.parameters]\n"pedestrians.2.speed" = [0.5, 1.5]\n'
    file = load(write(tmp_path, TOP + SCRIPTED + BYSTANDERS + sweep))
    runs = [file.scenario(params, "t") for params in file.runs()]
    assert [r.people[2].speed for r in runs] == [0.5, 1.5]
    for run in runs:
        assert run.people[:2] == file.base.people[:2]
        assert run.people[2].name == "walker" and run.people[2].x == 10.0


def test_an_include_adds_people_files_to_a_family_and_keeps_other_run_ids(
    tmp_path: Path,
) -> None:
    family = SCENARIOS / "families" / "small" / "cpnco50.toml"
    plain = f'name = "p"\n[[include]]\nfiles = ["{family}"]\nsampling = "base"\n'
    crowd = plain + (
        f'[[include]]\nfiles = ["{family}"]\nsampling = "base"\npeople = "{PAIR}"\n'
        '[include.parameters]\n"pedestrians.2.speed" = [0.8, 1.6]\n'
    )
    alone = expand_spec(load_spec(write(tmp_path, plain, "plain.toml")))
    runs = expand_spec(load_spec(write(tmp_path, crowd, "crowd.toml")))
    assert [r.id for r in runs[:1]] == [r.id for r in alone]
    added = runs[1:]
    assert len(added) == 2
    for run, speed in zip(added, (0.8, 1.6), strict=True):
        assert [p.name for p in run.scenario.bystanders] == ["waiting", "stroller"]
        assert run.scenario.bystanders[1].speed == speed
        assert run.scenario.pedestrian == alone[0].scenario.pedestrian
        # The run records the people file from the scenario file, as a rerun rebuilds it.
        assert run.params["people"] == os.path.relpath(PAIR, family.parent)
        _, probe, digest = run_scenario(load(family), run.params)
        assert run.id.endswith(f"-{digest}") and probe.bystanders == run.scenario.bystanders


def test_the_shipped_people_and_example_files_load_with_their_people() -> None:
    example = load(SCENARIOS / "examples" / "cpna25_bystanders.toml")
    assert [p.name for p in example.base.people] == ["", "waiting-1", "waiting-2"]
    for params in example.runs():  # every draw of its sweep builds
        assert len(example.scenario(params, "t").bystanders) == 2
    cpna = load(SCENARIOS / "families" / "car" / "cpna25.toml").base
    assert example.base.pedestrian == cpna.pedestrian
    car = SCENARIOS / "families" / "car" / "cpnco50.toml"
    s = load(car).scenario({"people": os.path.relpath(PAIR, car.parent)}, "t")
    assert [p.name for p in s.bystanders] == ["waiting", "stroller"]


# -- one line for each mistake --------------------------------------------------------

PARKED = '[scene.parked_cars]\nplacement = "fixed"\ny = -3.2\nx = [20.0]\n'


def one_line(err: Exception, path: Path, field: str, *parts: str) -> str:
    text = str(err)
    assert "\n" not in text, text
    assert text.startswith(f"{path}: {field} = "), text
    for part in parts:
        assert part in text, (part, text)
    return text


def test_a_person_walking_into_a_parked_car(tmp_path: Path) -> None:
    walks = BYSTANDERS.replace('x = 3.0', 'x = 14.0\ndirection = "away"').replace(
        'name = "waiting"\nspeed = 0.0', 'name = "waiting"\nspeed = 1.5'
    )  # fmt: skip
    path = write(tmp_path, TOP + SCRIPTED + walks + PARKED)
    err = error_of(path)
    assert err.field == "pedestrians.1.path"
    text = one_line(err, path, "pedestrians.1.path", "person 1 ('waiting'", "parked car")
    assert err.value["x"] == pytest.approx(20.0 - 2.25 - 0.25, abs=0.2)  # at the car's back
    assert "{t = " in text


def test_a_person_starting_inside_another(tmp_path: Path) -> None:
    scripted = load(write(tmp_path, TOP + SCRIPTED, "alone.toml")).base.pedestrian
    inside = BYSTANDERS + (
        f'[[pedestrians]]\nname = "twin"\nspeed = 0.0\n[pedestrians.path]\nkind = "explicit"\n'
        f"x = {scripted.x + 0.2}\ny = {scripted.y}\nheading_deg = 0.0\n"
    )
    path = write(tmp_path, TOP + SCRIPTED + inside)
    err = error_of(path)
    one_line(err, path, "pedestrians.3.path", "person 3 ('twin'", "person 0 ('ped'", "t = 0")
    assert err.value == {"x": round(scripted.x + 0.2, 2), "y": round(scripted.y, 2)}


def test_two_people_with_one_name(tmp_path: Path) -> None:
    path = write(tmp_path, TOP + SCRIPTED + BYSTANDERS.replace('"walker"', '"waiting"'))
    err = error_of(path)
    one_line(err, path, "pedestrians.2.name", "'waiting'", "person 1")
    # An unnamed person's name counts: person 2 is "ped2" unless named.
    path = write(tmp_path, TOP + SCRIPTED + BYSTANDERS.replace('"waiting"', '"ped2"').replace(
        'name = "walker"\n', ""), "default.toml")  # fmt: skip
    one_line(error_of(path), path, "pedestrians.1.name", "'ped2'", "person 2")


def test_a_key_for_a_person_the_file_does_not_have(tmp_path: Path) -> None:
    sweep = '[sweep]\n[sweep.parameters]\n"pedestrians.3.speed" = [1.0]\n'
    path = write(tmp_path, TOP + SCRIPTED + BYSTANDERS + sweep)
    one_line(
        error_of(path), path, "sweep.parameters.pedestrians.3.speed", "1.0", "no person 3",
        "the file has 3 people (0 'ped', 1 'waiting', 2 'walker')",
    )  # fmt: skip
    family = SCENARIOS / "families" / "small" / "cpna25.toml"
    spec = write(
        tmp_path,
        f'name = "p"\n[[include]]\nfiles = ["{family}"]\nsampling = "base"\n'
        '[include.parameters]\n"pedestrians.1.speed" = [1.0]\n',
        "spec.toml",
    )
    with pytest.raises(ScenarioFileError) as info:
        expand_spec(load_spec(spec))
    one_line(info.value, family, "pedestrians.1.speed", "the file has 1 person (0 'ped')")


def test_an_added_persons_mistake_names_their_people_file(tmp_path: Path) -> None:
    people = write(tmp_path, BYSTANDERS.replace("x = 10.0", "x = 500.0"), "people.toml")
    path = write(tmp_path, 'people = "people.toml"\n' + TOP + SCRIPTED, "s.toml")
    err = error_of(path)
    one_line(err, path, "pedestrians.2.path", "'walker'", f"pedestrians[1] of {people}",
             "leaves the street")  # fmt: skip
    bad = write(tmp_path, BYSTANDERS.replace("speed = 1.0", "speed = -1.0"), "people.toml")
    one_line(error_of(path), path, "pedestrians.2.speed", "-1.0", f"pedestrians[1] of {bad}")
    write(tmp_path, "oops = 1\n" + BYSTANDERS, "people.toml")
    with pytest.raises(ScenarioFileError, match=r"people.toml: oops = 1: unknown key"):
        load(path)
    missing = write(tmp_path, 'people = "nobody.toml"\n' + TOP + SCRIPTED, "m.toml")
    one_line(error_of(missing), missing, "people", "no such people file")


def test_the_readme_documents_each_persons_keys_as_the_scripted_persons() -> None:
    tables = readme_tables((SCENARIOS / "README.md").read_text(encoding="utf-8"))
    (title,) = [t for t in tables if t.startswith("`[[pedestrians]]`")]
    entry, scripted = keyed(tables[title]), keyed(tables["[pedestrian]"])
    assert set(entry) == {*scripted, "[pedestrians.behaviour]", "[pedestrians.path]"}
    for key in ("body", "height", "clothing", "speed", "footprint"):
        assert entry[key]["default"] == scripted[key]["default"], key
        assert entry[key]["range / values"].startswith(
            scripted[key]["range / values"].split(";")[0].split(":")[0]
        ), key
    assert math.isfinite(float(entry["speed"]["default"]))


def test_the_readmes_several_people_example_loads_as_written(tmp_path: Path) -> None:
    text = (SCENARIOS / "README.md").read_text(encoding="utf-8")
    (example,) = [
        block.split("```", 1)[0]
        for block in text.split("```toml\n")[1:]
        if block.startswith('name = "cpna-25-car-bystanders"')
    ]
    s = load(write(tmp_path, example)).base
    assert [p.name for p in s.people] == ["", "waiting-1", "waiting-2"]
    with pytest.raises(ScenarioFileError, match=r"no person 3: the file has 3 people \(0 'ped', "
                       r"1 'waiting-1', 2 'waiting-2'\)"):  # fmt: skip
        load(write(tmp_path, example)).scenario({"pedestrians.3.speed": 1.0}, "t")
