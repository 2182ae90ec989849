"""The several-people families (scenarios/families/small/people/) and their sweeps: each
file loads and its first draws build with everyone apart; in a collision family's first
draw the scripted person is the one the robot meets, in the near miss nobody is."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

from sim.runs.sweep import expand_spec, load_spec
from sim.scenario.files import load, read_people
from sim.scenario.people import planned_path
from sim.scenario.spec import Scenario
from sim.world.world import World
from tests.paths import SCENARIOS

FAMILIES = sorted((SCENARIOS / "families" / "small" / "people").glob("*.toml"))
PEOPLE_FILES = [
    SCENARIOS / "people" / f"{name}.toml"
    for name in ("pavement_two", "pavement_three", "pavement_four",
                 *(f"group_of_{n}" for n in range(2, 7)))
]  # fmt: skip
GAP = 0.15  # m: the least room between two people's footprints the files promise


def test_the_four_families_are_there() -> None:
    assert [p.stem for p in FAMILIES] == [
        "child_beside_adult", "far_crosser_hidden", "group_step_out", "nearmiss_kerb_wait"
    ]  # fmt: skip


@cache
def first_draws(path: Path) -> tuple[str, tuple[Scenario, ...]]:
    f = load(path)
    draws = [params for _, params in zip(range(2), f.runs(), strict=False)]
    return f.kind, tuple(f.scenario(params, name=f.name) for params in draws)


def least_gap(s: Scenario) -> float:
    """The least room between any two people's footprints over the run, their paths as
    written (squares along the axes: every path here walks along or across the road)."""
    times = np.arange(0.0, s.duration + 1e-9, s.dt)
    xy = [planned_path(p, s).positions_at(times) for p in s.people]
    least = np.inf
    for k in range(len(s.people)):
        for j in range(k):
            half = (s.people[j].footprint + s.people[k].footprint) / 2
            least = min(least, float(np.max(np.abs(xy[j] - xy[k]) - half, axis=1).min()))
    return least


@pytest.mark.parametrize("path", FAMILIES, ids=lambda p: p.stem)
def test_each_family_loads_and_its_first_draws_build_with_everyone_apart(path: Path) -> None:
    kind, draws = first_draws(path)
    assert kind in ("collision", "near-miss") and len(draws) == 2
    for s in draws:
        assert len(s.people) >= 2
        assert least_gap(s) >= GAP


def collisions(s: Scenario) -> dict[str, float]:
    """Each person the truth says collides within the horizon, at the first such frame,
    until the scripted person's contact ends the run (as a sweep's run ends)."""
    found: dict[str, float] = {}
    with World(s, render=False) as world:
        step = world.reset()
        while True:
            for person in step.truth.people:
                if person.collision:
                    found.setdefault(person.name, step.time)
            if step.truth.pedestrian.contact or step.time + s.dt > s.duration + 1e-9:
                return found
            step = world.step()


@pytest.mark.parametrize("path", FAMILIES, ids=lambda p: p.stem)
def test_the_scripted_person_alone_meets_the_robot_in_a_collision_familys_first_draw(
    path: Path,
) -> None:
    kind, (s, _) = first_draws(path)
    scripted = s.people[0].name
    met = collisions(s)
    if kind == "collision":
        assert s.robot.speed > 0
        assert list(met) == [scripted]
    else:
        assert met == {}


def test_the_people_files_load_with_unique_names() -> None:
    for path in PEOPLE_FILES:
        names = [entry["name"] for entry in read_people(path)]
        assert len(set(names)) == len(names) >= 1
    groups = [[e["name"] for e in read_people(p)] for p in PEOPLE_FILES[3:]]
    assert [len(g) for g in groups] == [1, 2, 3, 4, 5]
    assert all(g == groups[-1][: len(g)] for g in groups)  # each size the first of the six


def test_the_sweeps_expand_and_the_baseline_has_the_runs_its_readers_are_told() -> None:
    pavement = expand_spec(load_spec(SCENARIOS / "sweeps" / "people-pavement.toml"))
    assert len(pavement) == 120 and {len(r.scenario.people) for r in pavement} == {3, 4, 5}
    baseline = expand_spec(load_spec(SCENARIOS / "sweeps" / "people-baseline.toml"))
    assert len(baseline) == 101  # docs/people/families.md and scenarios/README.md say so
    groups = [len(r.scenario.people) for r in baseline if r.family == "group-step-out-small"]
    assert sorted(set(groups)) == [2, 3, 4, 5, 6]
