"""Bodies as entities: a new kind of body is one class, and World touches no body's arrays."""

from __future__ import annotations

import ast
import inspect
from dataclasses import dataclass

import mujoco
import numpy as np
from highway_env.road.road import Road

import sim.world.world
from sim.scenario.spec import (
    CameraSpec,
    PedestrianSpec,
    RoadLayout,
    RobotSpec,
    Scenario,
    SceneSpec,
)
from sim.world.entities.base import Entity, Moment, Sight
from sim.world.world import World

SCENARIO = Scenario(
    name="toy",
    # The pedestrian stands well to the left, out of the box's way.
    pedestrian=PedestrianSpec(x=8.0, y=4.0, heading_deg=-90.0, speed=0.0),
    robot=RobotSpec(camera=CameraSpec(320, 180)),
    scene=SceneSpec(road=RoadLayout(buildings=False)),
    duration=1.0,
)


@dataclass(frozen=True)
class BoxTruth:
    position: np.ndarray  # world, the box's centre
    pixel: np.ndarray  # where the camera sees its centre


class MovingBox(Entity):
    """A magenta box that slides sideways across the road ahead: a kind of body that
    sim/world knows nothing of."""

    name = "toy"

    def __init__(self) -> None:
        self.y = 1.0

    def build(self, spec: mujoco.MjSpec) -> None:
        body = spec.worldbody.add_body(name=self.name, mocap=True)
        body.add_geom(
            name=self.prefix + "box",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[0.4, 0.4, 0.4],
            rgba=[1.0, 0.0, 1.0, 1.0],
            contype=0,
            conaffinity=0,
        )

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._mocap = int(model.body(self.name).mocapid[0])
        self._body = int(model.body(self.name).id)

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        self.y = 1.0

    def before_step(self, dt: float) -> None:
        self.y -= 1.0 * dt  # 1 m/s to the right

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        data.mocap_pos[self._mocap] = (moment.robot.x + 6.0, self.y, 0.4)

    def truth(self, model: mujoco.MjModel, data: mujoco.MjData, sight: Sight) -> BoxTruth:
        centre = data.xpos[self._body].copy()
        return BoxTruth(centre, sight.camera.project(sight.robot.pose.to_local(centre)))


def test_a_new_kind_of_body_is_rendered_and_in_the_truth() -> None:
    with World(SCENARIO, extra=(MovingBox(),)) as world, World(SCENARIO) as plain:
        first, bare = world.reset(), plain.reset()
        later = world.step()
        box, moved = first.truth.bodies["toy"], later.truth.bodies["toy"]
        assert "toy" not in bare.truth.bodies
        assert moved.position[1] < box.position[1]  # it slid to the right
        assert later.truth.pedestrian.speed == 0.0  # the scenario's pedestrian is still there
        assert first.frame is not None and bare.frame is not None
        u, v = np.round(box.pixel).astype(int)
        r, g, b = first.frame.image[v, u].astype(int)
        assert r > 2 * g and b > 2 * g  # magenta where the truth says the box is
        r0, g0, b0 = bare.frame.image[v, u].astype(int)
        assert not (r0 > 2 * g0 and b0 > 2 * g0)  # and not without it


def mujoco_fields() -> set[str]:
    """The names of MuJoCo's model and data arrays (qpos, mocap_pos, cam_xpos, geom_xpos...)."""
    model = mujoco.MjModel.from_xml_string("<mujoco/>")
    names: set[str] = set()
    for struct in (model, mujoco.MjData(model)):
        names |= {n for n in dir(struct) if isinstance(getattr(struct, n, None), np.ndarray)}
    return names


def test_world_reads_no_mujoco_array_itself() -> None:
    """World composes the bodies: it hands the model and data to each entity and the
    renderer, and never indexes, reads or writes a MuJoCo array or calls MuJoCo."""
    tree = ast.parse(inspect.getsource(sim.world.world))
    imported = {
        alias.name.split(".")[0]
        for node in ast.walk(tree)
        if isinstance(node, ast.Import | ast.ImportFrom)
        for alias in (
            node.names if isinstance(node, ast.Import) else [ast.alias(node.module or "")]
        )
    }
    assert "mujoco" not in imported
    fields = mujoco_fields()
    assert {"mocap_pos", "qpos", "cam_xpos", "geom_xpos"} <= fields
    called = {id(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}  # methods
    touched = sorted(
        ast.unparse(node)
        for node in ast.walk(tree)
        if isinstance(node, ast.Attribute)
        and node.attr in fields
        and id(node) not in called
        and not (isinstance(node.value, ast.Name) and node.value.id == "self")
    )
    assert touched == [], touched


def test_the_finder_sees_a_world_that_reaches_into_mujoco() -> None:
    source = "def f(self):\n    self.scene.data.mocap_pos[3] = (0, 0, 0)\n"
    tree = ast.parse(source)
    fields = mujoco_fields()
    touched = [
        ast.unparse(n) for n in ast.walk(tree) if isinstance(n, ast.Attribute) and n.attr in fields
    ]
    assert "self.scene.data.mocap_pos" in touched
