"""Crowds: JuPedSim moves a scenario's [crowd] together, around the planned people."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sim.scenario.crowd_motion import GROUP_REACH, RADIUS
from sim.scenario.families import street_bounds
from sim.scenario.files import ScenarioFileError, load
from sim.scenario.motion import people_tracks
from sim.scenario.path import pedestrian_path
from sim.scenario.spec import Scenario, scenario_text
from sim.world.world import World
from tests.paths import SCENARIOS
from tests.sim.test_scenario_file import error_of, write

CROSSING = SCENARIOS / "families/small/crowd/crowd_crossing.toml"
QUEUE = SCENARIOS / "families/small/crowd/kerb_queue.toml"


def scenario_of(path: Path, seed: int = 0, **params: object) -> Scenario:
    return load(path).scenario(params, "t", seed=seed)


def positions(s: Scenario, seed: int, step: float = 1 / 15) -> tuple[list[str], np.ndarray]:
    """Everyone's names and positions (frames, people, 2) over the run."""
    tracks = people_tracks(s, seed, s.duration + 1.0)
    times = np.arange(0.0, s.duration, step)
    return list(tracks), np.stack([t.positions_at(times) for t in tracks.values()], axis=1)


@pytest.mark.parametrize("seed", [0, 7])
def test_nobody_walks_through_anybody(seed: int) -> None:
    s = scenario_of(CROSSING, seed)
    names, xy = positions(s, seed)
    assert len(names) == 1 + 12 + 3
    d = np.linalg.norm(xy[:, :, None] - xy[:, None, :], axis=-1)
    d[:, np.arange(len(names)), np.arange(len(names))] = np.inf
    # Two of the model's discs (0.25 m) or a crowd member and a planned person's (0.2 m),
    # less the model's own slack: people brush, never overlap.
    assert d.min() > 2 * RADIUS - 0.1


def test_the_crowd_keeps_to_the_pavements_and_its_crossing() -> None:
    s = scenario_of(CROSSING, 3)
    names, xy = positions(s, 3)
    y_right, y_left = s.scene.road.edges
    _, _, y0, y1 = street_bounds(s.scene.road)
    x0, x1 = s.crowd.cross_region
    crowd = xy[:, 1:]
    on_pavement = (crowd[..., 1] <= y_right) | (crowd[..., 1] >= y_left)
    crossing = (x0 <= crowd[..., 0]) & (crowd[..., 0] <= x1)
    assert np.all(on_pavement | crossing)
    assert np.all((y0 <= crowd[..., 1]) & (crowd[..., 1] <= y1))
    assert np.any(~on_pavement), "the crossers cross"


def test_planned_people_keep_their_own_walks() -> None:
    s = scenario_of(CROSSING, 4)
    tracks = people_tracks(s, 4, s.duration)
    own = pedestrian_path(s.pedestrian, s.duration, 4)
    times = np.linspace(0, s.duration, 50)
    assert np.array_equal(tracks["crosser"].positions_at(times), own.positions_at(times))


def test_the_same_seed_the_same_crowd_another_seed_another() -> None:
    s = scenario_of(CROSSING)
    _, a = positions(s, 11)
    _, b = positions(s, 11)
    _, c = positions(s, 12)
    assert np.array_equal(a, b)
    assert not np.allclose(a[:, 1:], c[:, 1:])


def test_groups_walk_together() -> None:
    s = scenario_of(CROSSING, 2)
    s = replace(s, crowd=replace(s.crowd, groups=1.0, across=0, looks=s.crowd.looks[:12]))
    names, xy = positions(s, 2)
    crowd = xy[:, 1:]
    d = np.linalg.norm(crowd[:, :, None] - crowd[:, None, :], axis=-1)
    # A group: near each other at the start and still within reach at the end, walking
    # the same way.
    start, end = d[0], d[-1]
    together = (start <= GROUP_REACH) & (end <= GROUP_REACH + 0.5)
    np.fill_diagonal(together, False)
    assert together.sum() >= 2 * 3  # at least three pairs kept together
    ways = np.sign(crowd[-1, :, 0] - crowd[0, :, 0])
    j, k = np.nonzero(together)
    assert np.all(ways[j] == ways[k])


def test_the_queue_waits_then_crosses_together() -> None:
    s = scenario_of(QUEUE, 5)
    release = s.crowd.release
    s = replace(s, duration=release + 3.5)
    names, xy = positions(s, 5, step=0.1)
    queue = xy[:, 1 + s.crowd.along :]
    y_right = s.scene.road.edges[0]
    times = np.arange(0.0, s.duration, 0.1)
    waiting = (times > release - 2.0) & (times < release)
    assert np.all(queue[waiting, :, 1] < y_right + 0.1), "nobody leaves the kerb early"
    # Each sets off (steps onto the road) within 2.5 s of the release, one after another.
    on_road = queue[..., 1] > y_right + 0.3
    first = np.array([times[np.argmax(col)] if col.any() else np.inf for col in on_road.T])
    assert np.all(first >= release) and np.all(first <= release + 2.5)


def test_crowd_members_show_a_human_walkers_cues() -> None:
    s = scenario_of(CROSSING, 1)
    tracks = people_tracks(s, 1, s.duration)
    heads = [t.head_yaws for name, t in tracks.items() if name.startswith("crowd-")]
    assert any(h is not None and np.abs(h).max() > math.radians(20) for h in heads)
    quiet = replace(s.crowd.cues, head_check_probability=0.0, turn_lead=0.0, stop_lead=0.0)
    s = replace(s, crowd=replace(s.crowd, cues=quiet))
    tracks = people_tracks(s, 1, s.duration)
    heads = [t.head_yaws for name, t in tracks.items() if name.startswith("crowd-")]
    assert all(np.abs(h).max() < math.radians(1) for h in heads)


def test_a_scenario_without_a_crowd_keeps_its_identity() -> None:
    s = scenario_of(CROSSING)
    assert "crowd=" in scenario_text(s)
    assert "crowd=" not in scenario_text(replace(s, crowd=None))


def test_a_crowd_larger_than_its_pavement_is_one_line(tmp_path: Path) -> None:
    text = (
        CROSSING.read_text()
        .replace("along = 12", "along = 40")
        .replace("region = [-2.0, 30.0]", "region = [0.0, 10.0]")
    )
    err = error_of(write(tmp_path, text))
    assert err.field == "crowd.along" and "holds at most" in str(err)
    assert "\n" not in str(err)


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("groups = 0.7", "groups = 1.5", "crowd.groups"),
        ("region = [-2.0, 30.0]", "region = [30.0, -2.0]", "crowd.region"),
        ("groups = 0.7", "grups = 0.7", "crowd.grups"),
        ("across = 3", "across = -1", "crowd.across"),
    ],
)
def test_bad_crowd_values_are_one_line(tmp_path: Path, old: str, new: str, field: str) -> None:
    err = error_of(write(tmp_path, CROSSING.read_text().replace(old, new)))
    assert isinstance(err, ScenarioFileError) and err.field == field


def test_the_world_walks_the_crowd_it_works_out() -> None:
    s = scenario_of(QUEUE, 6)
    tracks = people_tracks(s, 6, s.duration + 10.0)
    with World(s, render=False) as world:
        step = world.reset(seed=6)
        for _ in range(10):
            step = world.step()
        truth = step.truth
        assert [p.name for p in truth.people] == list(tracks)
        for person in truth.people:
            want = tracks[person.name].state(world.time).position
            assert np.allclose(person.position_world, want, atol=1e-9)


def test_the_readme_gives_the_crowds_defaults() -> None:
    from sim.scenario.spec import Crowd
    from tests.sim.test_presets import README, keyed, number, readme_tables

    rows = keyed(readme_tables(README.read_text())["[crowd]"])
    base = Crowd()
    for key in ("along", "across", "queue", "release", "groups", "speed", "speed_spread"):
        assert number(rows[key]["default"]) == pytest.approx(float(getattr(base, key))), key
    s = scenario_of(CROSSING)
    assert s.crowd is not None and s.crowd.speed == base.speed
    assert sum(looks.height < 1.5 for looks in s.crowd.looks) == s.crowd.count // 10
