"""The pedestrian's behaviour models: the Euro NCAP rail target and the human walker."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.errors import UserError
from sim.runs.sweep import run_scenario
from sim.scenario.files import load
from sim.scenario.path import pedestrian_path
from sim.scenario.plan import rail_track
from sim.scenario.spec import Anchor, Leg, PedestrianSpec, scenario_text
from sim.scenario.toml_table import FieldError, TomlTable
from sim.scenario.track import H, Track
from sim.scenario.walkers import WALKERS, HumanWalker, RailWalker, Walker, walker_from_table
from sim.world.world import World
from tests.paths import SCENARIOS

HUMAN = HumanWalker()


def speeds(track, t0: float, t1: float, dt: float = H) -> tuple[np.ndarray, np.ndarray]:
    times = np.arange(t0, t1, dt)
    p = track.positions_at(times)
    return times[:-1], np.hypot(*np.diff(p, axis=0).T) / dt


def test_the_rail_target_reaches_its_speed_over_the_acceleration_distance():
    spec = PedestrianSpec(x=0.0, y=0.0, heading_deg=90.0, speed=1.39, start_delay=1.0)
    track = rail_track(spec, acceleration_distance=1.0)
    ramp = 2 * 1.0 / 1.39  # s: constant acceleration from 0 to 1.39 m/s over 1 m
    assert track.state(1.0).position == pytest.approx([0.0, 0.0])
    assert track.state(1.0 + ramp).position == pytest.approx([0.0, 1.0], abs=1e-9)
    assert track.state(1.0 + ramp + 2.0).position == pytest.approx([0.0, 1.0 + 2 * 1.39])
    half = track.state(1.0 + ramp / 2).position[1]
    assert half == pytest.approx(0.25, abs=1e-3)  # a t^2 / 2: a quarter of the distance
    assert track.state(5.0).speed == pytest.approx(1.39)
    # Distance 0 is the plan itself: an instant start.
    assert rail_track(spec, 0.0).state(2.0).position == pytest.approx([0.0, 1.39])


def test_an_anchor_is_met_exactly_by_both_behaviours():
    anchor = Anchor(time=3.0, x=4.0, y=0.5)
    for behaviour in (RailWalker(), HUMAN):
        spec = PedestrianSpec(x=4.0, y=-3.0, heading_deg=90.0, speed=1.39, start_delay=0.5,
                              behaviour=behaviour, anchor=anchor)  # fmt: skip
        for seed in (0, 1, 2):
            track = pedestrian_path(spec, 6.0, seed)
            assert track.state(3.0).position == pytest.approx([4.0, 0.5], abs=1e-9)


def human_crossing(seed: int = 3) -> tuple[PedestrianSpec, object]:
    spec = PedestrianSpec(x=0.0, y=-4.0, heading_deg=90.0, speed=1.4, start_delay=1.0,
                          behaviour=HUMAN)  # fmt: skip
    return spec, pedestrian_path(spec, 8.0, seed)


def test_a_human_sets_off_over_steps_not_in_a_frame():
    spec, track = human_crossing()
    t, v = speeds(track, 0.0, 6.0, dt=0.1)
    assert np.all(v[t < 0.9] < 1e-9)  # standing first
    moving = np.flatnonzero(v > 0.05)
    start = t[moving[0]]
    at_speed = t[np.flatnonzero(v > 0.9 * 1.4)[0]]
    assert 1.0 <= at_speed - start <= 2.5  # about three steps, not one frame
    accel = np.abs(np.diff(v)) / 0.1
    assert accel.max() < 2.5  # m/s2: bounded, even with the stride's surge


def test_a_human_stops_exactly_where_the_plan_stops_and_over_about_a_second():
    spec = PedestrianSpec(x=0.0, y=-4.0, heading_deg=90.0, speed=1.4, start_delay=0.5,
                          legs=(Leg(at=2.5, speed=0.0),), behaviour=HUMAN)  # fmt: skip
    plan_stop = rail_track(spec, 0.0).state(2.5).position
    track = pedestrian_path(spec, 8.0, seed=1)
    end = track.state(7.0)
    assert end.speed == 0.0
    # The stop is on the plan's stopping line (the wander moves it sideways only).
    assert end.position[1] == pytest.approx(plan_stop[1], abs=0.03)
    t, v = speeds(track, 0.0, 7.0, dt=0.1)
    slowing = t[(v < 0.9 * 1.4) & (t > 2.0) & (v > 0.05)]
    assert slowing.max() - slowing.min() >= 0.5  # over steps, not a frame


def test_a_human_turns_along_an_arc_at_a_bounded_yaw_rate():
    walker = HumanWalker(lateral_wander=0.0, sway=0.0, surge=0.0)
    turn = (Leg(at=2.0, speed=1.4, turn_deg=-90.0),)
    spec = PedestrianSpec(x=0.0, y=-4.0, heading_deg=90.0, speed=1.4, legs=turn, behaviour=walker)
    track = pedestrian_path(spec, 6.0, seed=0)
    times = np.arange(0.0, 5.0, 0.05)
    yaws = np.unwrap([track.state(float(t)).yaw for t in times])
    rate = np.degrees(np.abs(np.diff(yaws))) / 0.05
    assert rate.max() <= 90.0 * 1.05  # the yaw-rate bound (a little for the speed wander)
    assert yaws[-1] - yaws[0] == pytest.approx(-math.pi / 2, abs=0.02)
    turning = times[1:][rate > 10.0]
    assert turning.max() - turning.min() >= 0.6  # a curve, not a corner


def test_the_wander_is_the_seeds_and_a_standing_person_does_not_drift():
    spec, a = human_crossing(seed=3)
    _, b = human_crossing(seed=3)
    _, c = human_crossing(seed=4)
    assert np.array_equal(a.positions, b.positions)
    assert not np.allclose(a.positions_at(np.array([4.0])), c.positions_at(np.array([4.0])))
    standing = a.positions_at(np.linspace(0.0, 0.8, 20))
    assert np.ptp(standing, axis=0) == pytest.approx([0.0, 0.0], abs=1e-12)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), t=st.floats(0.0, 7.9))
def test_a_tracks_state_is_its_pieces(seed: int, t: float):
    """Position at any time is the piece's start plus its velocity: the truth's straight pieces."""
    _, track = human_crossing(seed)
    k = int(np.searchsorted(track.times, t, side="right")) - 1
    expected = track.positions[k] + (t - track.times[k]) * track.velocities[k]
    assert track.state(t).position == pytest.approx(expected)
    nxt = min(k + 1, len(track.times) - 1)
    if nxt > k:  # continuous: a piece ends where the next begins
        end = track.positions[k] + (track.times[nxt] - track.times[k]) * track.velocities[k]
        assert end == pytest.approx(track.positions[nxt], abs=1e-9)


def first_overlap_brute_force(world: World, t_end: float) -> float | None:
    """The first time (1 ms steps) the robot, keeping its course, overlaps the pedestrian."""
    from highway_env import utils

    robot, ped = world.robot, world.pedestrian
    assert robot is not None and ped is not None
    for t in np.arange(0.0, t_end, 0.001):
        ghost = robot.polygon() + t * robot.velocity
        if utils.are_polygons_intersecting(ghost, ped.polygon_at(float(t)), np.zeros(2),
                                           np.zeros(2))[0]:  # fmt: skip
            return float(t)
    return None


@pytest.mark.parametrize(
    "file", ["families/small/cross_impact.toml", "cases/case4_oblique_left_toward.toml"]
)
def test_the_time_to_contact_of_a_human_walker_agrees_with_a_brute_force_search(file: str):
    f = load(SCENARIOS / file)
    scenario = f.scenario({"pedestrian.behaviour.model": "human", "robot.speed": 2.0}, "t", 5)
    with World(scenario, render=False) as world:
        truth = world.reset().truth
        brute = first_overlap_brute_force(world, scenario.duration)
        if brute is None:
            assert (
                truth.pedestrian.time_to_collision is None
                or truth.pedestrian.time_to_collision > scenario.duration
            )
        else:
            assert truth.pedestrian.time_to_collision == pytest.approx(brute, abs=0.0015)


@pytest.mark.parametrize(
    ("table", "expected"),
    [
        ('model = "robot"', "pedestrian.behaviour.model = 'robot': must be one of"),
        (
            'model = "human"\nstart_time = 0.0',
            "pedestrian.behaviour.start_time = 0.0: must be >= 0.2",
        ),
        ('model = "rail"\nstart_time = 1.0', "pedestrian.behaviour.start_time = 1.0: unknown key"),
        ('model = "rail"\nacceleration_distance = -1', "acceleration_distance = -1: must be >= 0"),
        ('model = "human"\nlateral_wander = 2.0', "lateral_wander = 2.0: must be <= 0.5"),
        (
            'model = "human"\nacceleration_distance = 1.0',
            "pedestrian.behaviour.acceleration_distance = 1.0: unknown key",
        ),
    ],
)
def test_bad_behaviour_values_are_one_line_naming_file_field_and_value(tmp_path, table, expected):
    text = (SCENARIOS / "families/small/cpna25.toml").read_text()
    text = text.replace("[path]", f"[pedestrian.behaviour]\n{table}\n\n[path]", 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(UserError) as err:
        load(path)
    message = str(err.value)
    assert message.startswith(str(path)) and expected in message and "\n" not in message


def test_every_collision_and_near_miss_family_has_a_human_version():
    """The behaviour is a parameter of every family: the same file, either walker."""
    for path in sorted((SCENARIOS / "families").glob("*/*.toml")):
        f = load(path)
        for model in ("rail", "human"):
            scenario = f.scenario({"pedestrian.behaviour.model": model}, f.name, 0)
            assert scenario.pedestrian.behaviour.model == model


# -- walker types -------------------------------------------------------------------------


@dataclass(frozen=True)
class StillWalker:
    """A walker type defined here, as a new module would: it stands where the plan starts,
    facing `facing_deg`, whatever the plan says."""

    model: ClassVar[str] = "still"
    facing_deg: float = 0.0

    @property
    def cues(self) -> bool:
        return False

    @property
    def start_distance(self) -> float:
        return 0.0

    def placed(self, acceleration_distance: float) -> StillWalker:
        return self

    def track(self, plan, t_end: float, seed: int) -> Track:
        yaw = [math.radians(self.facing_deg)]
        return Track(np.zeros(1), np.array([[plan.x, plan.y]]), np.zeros((1, 2)), yaw)

    def identity(self) -> str:
        return repr(self)

    @classmethod
    def from_table(cls, t: TomlTable) -> StillWalker:
        walker = cls(facing_deg=t.number("facing_deg", 0.0, low=-360.0, high=360.0))
        t.done()
        return walker


def with_behaviour(tmp_path: Path, table: str) -> Path:
    """cpna25 (a crossing, anchored at its impact point) with this [pedestrian.behaviour]."""
    text = (SCENARIOS / "families/small/cpna25.toml").read_text()
    path = tmp_path / "walker.toml"
    path.write_text(text.replace("[path]", f"[pedestrian.behaviour]\n{table}\n\n[path]", 1))
    return path


def test_a_registered_walker_type_is_chosen_by_model_and_walked_without_editing_the_path(
    tmp_path, monkeypatch
):
    monkeypatch.setitem(WALKERS, StillWalker.model, StillWalker)  # undone after the test
    assert isinstance(StillWalker(), Walker)
    f = load(with_behaviour(tmp_path, 'model = "still"\nfacing_deg = 45'))
    spec = f.base.pedestrian
    assert spec.behaviour == StillWalker(facing_deg=45.0)
    track = pedestrian_path(spec, 6.0, seed=0)
    anchor = spec.anchor
    assert anchor is not None
    # It stands, facing its own way, and is shifted to meet the placement's anchor.
    for t in (0.0, 2.0, anchor.time, 5.0):
        state = track.state(t)
        assert state.speed == 0.0 and state.yaw == pytest.approx(math.radians(45.0))
        assert state.position == pytest.approx([anchor.x, anchor.y])
    # Sweep keys pick it and set its keys as they do the others'; its identity is its repr.
    sweep = {"pedestrian.behaviour.model": "still", "pedestrian.behaviour.facing_deg": 90}
    swept = load(SCENARIOS / "families/small/cpna25.toml").scenario(sweep, "t", 0)
    assert swept.pedestrian.behaviour == StillWalker(facing_deg=90.0)
    assert "StillWalker(facing_deg=90.0)" in scenario_text(swept)
    with pytest.raises(UserError, match="must be one of rail, human, replay, still"):
        load(with_behaviour(tmp_path, 'model = "crowd"'))


def test_the_registry_is_back_without_the_walker_a_test_added():
    assert list(WALKERS) == ["rail", "human", "replay"]


def keys_read(walker: type) -> set[str]:
    """The keys of [pedestrian.behaviour] a walker type reads (its own, besides model)."""
    table = TomlTable(Path("w.toml"), "pedestrian.behaviour", {})
    walker.from_table(table)
    return table.seen


def test_the_rail_and_the_human_walker_share_nothing_but_the_interface():
    rail, human = keys_read(RailWalker), keys_read(HumanWalker)
    assert rail == {"acceleration_distance"} and len(human) == 15 and not rail & human
    assert not {f.name for f in fields(RailWalker)} & {f.name for f in fields(HumanWalker)}
    assert isinstance(RailWalker(), Walker) and isinstance(HumanWalker(), Walker)
    assert (RailWalker().cues, HumanWalker().cues) == (False, True)


@pytest.mark.parametrize(("model", "other"), [(RailWalker, HumanWalker), (HumanWalker, RailWalker)])
def test_each_walker_refuses_every_key_of_the_other_in_one_line(model, other):
    for key in sorted(keys_read(other)):
        value = getattr(other(), key)
        value = 1.0 if value is None else value
        table = TomlTable(
            Path("w.toml"), "pedestrian.behaviour", {"model": model.model, key: value}
        )
        with pytest.raises(FieldError) as err:
            walker_from_table(table)
        message = str(err.value)
        assert message.startswith(f"w.toml: pedestrian.behaviour.{key} = {value!r}: unknown key")
        assert "\n" not in message


def test_run_ids_digest_the_walker_as_the_one_record_of_earlier_versions_did():
    """The identity text keeps each run's id and seed: digests made before the walker types."""
    cases = [
        ("families/small/cpna25.toml", {}, "30a0e2ac"),
        ("families/small/cpna25.toml", {"pedestrian.behaviour.model": "human"}, "b6005a95"),
        ("families/small/cpfa50.toml", {"pedestrian.behaviour.model": "human"}, "58ebbd07"),
        ("cases/case5_perpendicular_right.toml", {"pedestrian.behaviour.model": "human"},
         "fa5e6eef"),
        ("families/car/cpla25.toml", {"pedestrian.behaviour.acceleration_distance": 0.7},
         "33a3d9de"),
        ("families/small/nearmiss_kerb_stop.toml",
         {"pedestrian.behaviour.model": "human", "pedestrian.behaviour.head_check_probability": 1.0,
          "pedestrian.behaviour.stop_lead": 0.0, "pedestrian.behaviour.turn_lead": 0.7},
         "d2d1adb3"),
    ]  # fmt: skip
    for file, extra, digest in cases:
        f = load(SCENARIOS / file)
        assert run_scenario(f, {**next(f.runs()), **extra})[2] == digest, (file, extra)
    # A human walker placed on a crossing writes the side's acceleration distance, as then.
    human = load(SCENARIOS / "families/small/cpfa50.toml").scenario(
        {"pedestrian.behaviour.model": "human"}, "t"
    )
    assert "Behaviour(model='human', acceleration_distance=1.5, start_time=1.8" in scenario_text(
        human
    )


# -- intent cues ---------------------------------------------------------------

NO_CUES = {"head_check_probability": 0.0, "turn_lead": 0.0, "stop_lead": 0.0}


def crossing_spec(**behaviour: float) -> PedestrianSpec:
    return PedestrianSpec(x=4.0, y=-4.0, heading_deg=90.0, speed=1.4, start_delay=2.0,
                          behaviour=HumanWalker(**behaviour))  # fmt: skip


def test_cues_off_reproduce_the_cue_free_walker_exactly():
    cued = pedestrian_path(crossing_spec(head_check_probability=1.0, turn_lead=0.5), 8.0, 7)
    plain = pedestrian_path(crossing_spec(**NO_CUES), 8.0, 7)
    # Cues turn the head and the shoulders; they never move the walker.
    assert np.array_equal(cued.positions, plain.positions)
    assert np.array_equal(cued.yaws, plain.yaws)
    assert np.all(plain.head_yaws == 0.0) and np.all(plain.torso_yaws == 0.0)
    assert np.abs(cued.head_yaws).max() > math.radians(30)


def test_a_head_check_looks_toward_the_traffic_before_stepping_off_and_at_a_stop():
    track = pedestrian_path(crossing_spec(head_check_probability=1.0), 8.0, 7)
    t, v = speeds(track, 0.0, 8.0, dt=0.05)
    set_off = t[np.flatnonzero(v > 0.05)[0]]
    before = np.arange(set_off - 1.0, set_off, 0.02)
    turned = [track.state(float(x)).head_yaw + track.state(float(x)).torso_yaw for x in before]
    # Facing north, the robot's traffic comes from the west: to the left (+).
    assert max(turned) == pytest.approx(math.radians(60.0), abs=math.radians(1.0))
    stop = PedestrianSpec(x=4.0, y=-4.0, heading_deg=90.0, speed=1.4, start_delay=1.0,
                          legs=(Leg(at=3.0, speed=0.0),),
                          behaviour=HumanWalker(head_check_probability=1.0,
                                                head_check_interval=0.0))  # fmt: skip
    track = pedestrian_path(stop, 8.0, 7)
    t, v = speeds(track, 0.0, 8.0, dt=0.05)
    arrived = t[np.flatnonzero(v > 0.05)[-1]]
    after = [track.state(float(x)).head_yaw for x in np.arange(arrived, arrived + 1.2, 0.02)]
    assert max(after) > math.radians(30)  # it looks at the kerb too: a cue is not a label


def test_the_head_then_the_shoulders_lead_a_turn():
    quiet = HumanWalker(head_check_probability=0.0, turn_lead=0.5, lateral_wander=0.0, sway=0.0)
    turn = (Leg(at=2.0, speed=1.4, turn_deg=90.0),)
    spec = PedestrianSpec(x=0.0, y=-4.0, heading_deg=0.0, speed=1.4, legs=turn, behaviour=quiet)
    track = pedestrian_path(spec, 6.0, 0)
    times = np.arange(0.0, 4.0, 0.01)
    line = np.unwrap([track.state(float(t)).footprint_yaw for t in times])
    starts = times[np.flatnonzero(np.abs(line - line[0]) > math.radians(2))[0]]
    head = np.array([track.state(float(t)).head_yaw + track.state(float(t)).torso_yaw
                     for t in times])  # fmt: skip
    torso = np.array([track.state(float(t)).torso_yaw for t in times])
    head_starts = times[np.flatnonzero(head > math.radians(2))[0]]
    torso_starts = times[np.flatnonzero(torso > math.radians(2))[0]]
    assert head_starts < torso_starts < starts  # head first, then the shoulders, then the path
    assert starts - head_starts == pytest.approx(0.5, abs=0.15)


def test_the_truth_reads_the_head_yaw_off_the_posed_body():
    spec = crossing_spec(head_check_probability=1.0, head_check_interval=0.0)
    from sim.scenario.spec import Scenario

    scenario = Scenario(name="look", pedestrian=spec, duration=4.0)
    with World(scenario, render=False) as world:
        seen = [(s.truth.pedestrian.head_yaw_shoulders, world.pedestrian.state.head_yaw)  # type: ignore[union-attr]
                for s in world.run()]  # fmt: skip
    measured, commanded = np.array(seen).T
    assert np.abs(commanded).max() > math.radians(30)
    assert np.abs(measured - commanded).max() < math.radians(4)  # the gait's counter-rotation
