"""Several people in the simulated world: each a body, each with their own truth."""

from __future__ import annotations

import json
from dataclasses import replace

import gymnasium as gym
import mujoco
import numpy as np
import pytest

from sim.analysis.tracks import sweep_tracks
from sim.envs import ENV_ID
from sim.runs.record import record_run
from sim.runs.result import RunResult
from sim.runs.run_spec import RunSpec
from sim.runs.runner import run
from sim.scenario.spec import (
    CameraSpec,
    Occluder,
    PedestrianSpec,
    RoadLayout,
    RobotSpec,
    Scenario,
    SceneSpec,
)
from sim.scenario.walkers import HumanWalker
from sim.world.ground_truth import VISIBLE_GEOM_GROUPS, first_hits
from sim.world.world import World
from tests.rrd import column, rows_per_entity

ROBOT = RobotSpec(speed=0.0, camera=CameraSpec(320, 180))
STREET = SceneSpec(road=RoadLayout(buildings=False))
# The scripted person stands 10 m ahead on the robot's line; a bystander 5 m ahead on the
# same line stands between them and the camera.
FAR = PedestrianSpec(x=10.0, y=0.0, heading_deg=90.0, speed=0.0)
NEAR = PedestrianSpec(x=5.0, y=0.0, heading_deg=90.0, speed=0.0, name="near")


def scenario(*bystanders: PedestrianSpec, scene: SceneSpec = STREET) -> Scenario:
    return Scenario(
        name="people", pedestrian=FAR, robot=ROBOT, scene=scene, duration=0.2,
        bystanders=bystanders,
    )  # fmt: skip


def first_truth(sc: Scenario):  # noqa: ANN201 - a GroundTruth
    with World(sc, render=False) as world:
        return world.reset().truth


def test_each_person_has_a_truth_of_their_own_the_scripted_first() -> None:
    truth = first_truth(scenario(NEAR))
    assert [p.name for p in truth.people] == ["ped", "near"]
    assert truth.pedestrian is truth.people[0]
    far, near = truth.people
    assert far.position_robot[0] == pytest.approx(10.0)
    assert near.position_robot[0] == pytest.approx(5.0)
    # The nearer person looks taller and their footprint is where they stand.
    assert near.apparent_height > 1.5 * far.apparent_height
    assert near.footprint_world.mean(axis=0) == pytest.approx([5.0, 0.0])


def test_a_person_in_front_hides_the_one_behind() -> None:
    alone = first_truth(scenario()).pedestrian.visibility
    behind = first_truth(scenario(NEAR))
    far, near = behind.people
    assert alone is not None and far.visibility is not None and near.visibility is not None
    assert alone.hidden == 0.0 and alone.visible > 0.9
    assert far.visibility.hidden_by["person"] > 0.5  # mostly behind the near person
    assert near.visibility.hidden == 0.0
    # The visible part's box lies inside the whole body's.
    u0, v0, u1, v1 = far.visibility.box
    bu0, bv0, bu1, bv1 = far.box
    assert bu0 - 1 <= u0 and u1 <= bu1 + 1 and bv0 - 1 <= v0 and v1 <= bv1 + 1


def test_a_parked_car_hides_by_its_kind_and_the_frame_edge_counts_apart() -> None:
    car = SceneSpec(road=RoadLayout(buildings=False), occluders=(Occluder.parked_car(6.0, 0.0),))
    seen = first_truth(scenario(scene=car)).pedestrian.visibility
    assert seen is not None
    assert seen.hidden_by["parked car"] > 0.2 and seen.hidden_by["person"] == 0.0
    aside = PedestrianSpec(x=2.0, y=2.5, heading_deg=0.0, speed=0.0, name="aside")
    edge = first_truth(scenario(aside)).people[1].visibility
    assert edge is not None and edge.outside_frame > 0.2


def test_two_people_with_one_name_are_refused() -> None:
    with pytest.raises(ValueError, match="share a name"):
        scenario(NEAR, NEAR)


def test_a_run_with_several_people_records_each_and_names_the_first_threat() -> None:
    """The scripted person stands still ahead; a bystander walks into the robot's path."""
    walker = PedestrianSpec(x=1.0, y=1.5, heading_deg=-90.0, speed=1.5, name="walker")
    sc = replace(scenario(walker), robot=replace(ROBOT, speed=1.0), duration=0.6)
    result = run(RunSpec(id="people/0", scenario=sc, ablation=False, stop_at_contact=False))
    assert [p.name for p in result.people] == ["ped", "walker"]
    assert [p.scripted for p in result.people] == [True, False]
    assert all(len(p.collision) == result.frames for p in result.people)
    assert result.first_threat == "walker"  # on course within the horizon, the other never
    assert result.people[1].collision[-1] == 1 and not any(result.people[0].collision)
    line = result.to_json()
    assert line["first_threat"] == "walker" and len(line["people"]) == 2
    assert RunResult.from_json(json.loads(json.dumps(line))).people == result.people


def test_a_one_person_line_is_written_as_it_always_was() -> None:
    result = run(RunSpec(id="one/0", scenario=replace(scenario(), duration=0.2), ablation=False))
    line = result.to_json()
    assert result.people == [] and "people" not in line and "first_threat" not in line
    assert list(line) == list(RunResult.ORDER)


def test_the_recording_shows_each_person_under_their_name(tmp_path) -> None:  # noqa: ANN001
    rrd = tmp_path / "people.rrd"
    summary = record_run(replace(scenario(NEAR), duration=0.4), rrd)
    counts = rows_per_entity(rrd)
    for name in ("ped", "near"):
        assert counts[f"/world/people/{name}"] == summary.frames
        assert counts[f"/world/people/{name}/footprint"] == summary.frames
        assert counts[f"/camera/people_truth/{name}/box"] == summary.frames
    labels = column(rrd, "/camera/people_truth/ped/box", "Boxes2D:labels")
    assert "ped, 97% hidden" in str(labels[0])  # behind the near person
    alone = tmp_path / "alone.rrd"
    record_run(replace(scenario(), duration=0.2), alone)
    assert not any(e.startswith("/world/people") for e in rows_per_entity(alone))


def test_tracks_hold_every_person_named() -> None:
    spec = RunSpec(id="people/0", scenario=scenario(NEAR))
    tracks = sweep_tracks([spec])
    assert [t.person for t in tracks] == ["ped", "near"]
    assert tracks[1].positions[0] == pytest.approx([5.0, 0.0])


def test_the_gymnasium_info_carries_every_persons_truth() -> None:
    env = gym.make(ENV_ID, config={"scenario": scenario(NEAR)})
    try:
        _, info = env.reset(seed=0)
        people = info["truth"]["people"]
        assert [p["name"] for p in people] == ["ped", "near"]
        assert people[0]["visibility"]["hidden_by"]["person"] > 0.5
        _, _, _, _, info = env.step(np.zeros(1, dtype=np.float32))
        assert len(info["truth"]["people"]) == 2
    finally:
        env.close()


def test_human_bystanders_wander_each_their_own_way() -> None:
    human = HumanWalker()
    a = PedestrianSpec(x=6.0, y=3.0, heading_deg=0.0, speed=1.2, behaviour=human, name="a")
    b = replace(a, y=-3.0, name="b")
    with World(replace(scenario(a, b), duration=2.0), render=False) as world:
        steps = list(world.run())
    lateral = [[s.truth.people[k].position_world[1] for s in steps] for k in (1, 2)]
    wander_a = np.array(lateral[0]) - 3.0
    wander_b = np.array(lateral[1]) + 3.0
    assert np.abs(wander_a).max() > 0.001 and not np.allclose(wander_a, wander_b)


def test_lines_of_sight_tested_against_nearby_geoms_only_give_the_whole_scenes_answer() -> None:
    """first_hits leaves out the geoms that cannot be in the way; the hits are those of one
    mj_multiRay over every geom, for every person of a street with twelve."""
    bystanders = tuple(
        PedestrianSpec(x=4.0 + 1.5 * k, y=(-1) ** k * (0.6 + 0.4 * k), heading_deg=30.0 * k,
                       speed=0.0, name=f"b{k}")
        for k in range(11)
    )  # fmt: skip
    with World(scenario(*bystanders), render=False) as world:
        world.reset()
        model, data = world.scene.model, world.scene.data
        origin = world.robot_body.camera_world(data)
        for person in world.scene.pedestrians:
            points = person.sight_shapes.surface_points(data)
            geom, dist = first_hits(model, data, origin, points)
            rays = points - origin
            length = np.linalg.norm(rays, axis=1)
            whole_geom = np.full(len(points), -1, dtype=np.int32)
            whole_dist = np.full(len(points), -1.0)
            mujoco.mj_multiRay(
                model, data, origin, (rays / length[:, None]).reshape(-1),
                VISIBLE_GEOM_GROUPS, 1, -1, whole_geom, whole_dist, None, len(points),
                float(length.max()) + 1.0,
            )  # fmt: skip
            assert np.array_equal(geom, whole_geom) and np.array_equal(dist, whole_dist)
        assert (model.geom_group <= 3).all()  # every geom back in its own group
