"""The simulated world: one step advances highway-env, poses MuJoCo, renders, tells the truth.

highway-env owns the motion: the robot is a highway-env vehicle (sim.world.robot) on a
highway-env road, the pedestrian a highway-env road object walking its scenario path
(sim.world.pedestrian). MuJoCo only shows it: each step puts the camera robot and the
mannequin where highway-env says, renders the robot camera, and each body tells its
truth (sim.world.ground_truth). The scenario runner, the gymnasium
environment and the closed loop all call the same `World.step`.

Rendering: the MuJoCo renderer (an EGL context) is created lazily on the first frame, in
the process that steps the world; EGL contexts do not survive fork, so build Worlds
inside spawned workers from the (plain-data) Scenario. With `render=False` no renderer is
ever made and `WorldStep.frame` is None; everything else, the ground truth included
(occlusion is a ray test, not a mask), is the same, which makes ground-truth-only runs fast.

Composition: the world is a list of bodies (sim.world.entities: parked cars, the sun,
the robot, the pedestrian, and any `extra` a caller adds). Each step the world moves each
body's motion, lets each place itself in MuJoCo and asks each for its truth; it reads and
writes no MuJoCo array itself (the nose dip, the camera's pose and the pedestrian's
landmarks are their bodies' business).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace

import numpy as np
from highway_env.road.road import Road

from monopic.camera import CameraModel
from monopic.closing import Closing
from monopic.frame import EgoState, Frame
from sim.scenario.spec import Scenario, person_name
from sim.sensor.sensor import Sensor
from sim.world.entities.base import Entity, Moment, Sight
from sim.world.entities.crowd import CrowdDirector
from sim.world.entities.pedestrian import PedestrianBody
from sim.world.entities.robot import RobotBody
from sim.world.ground_truth import CASE_WINDOW, GroundTruth, PersonTruth, RobotState
from sim.world.lighting import lights
from sim.world.pedestrian import Pedestrian
from sim.world.render import Marker, RenderContext, SceneRenderer
from sim.world.robot import Robot, highway_road
from sim.world.scene import Scene, SceneConfig, parked_cars
from sim.world.shutter import Shutter

TTC_LOOKAHEAD = 10.0  # s: how far ahead the time to collision is searched


@dataclass(frozen=True)
class WorldStep:
    """One frame of the world: the camera frame (None without rendering) and the truth.

    `frame.ego` (and `ego`) is all the pipeline may know besides the pixels.
    """

    index: int
    time: float
    ego: EgoState
    truth: GroundTruth
    frame: Frame | None


def scenario_entities(scenario: Scenario, t_end: float) -> list[Entity]:
    """The bodies of a scenario's world, in the order the scene builds them: its parked
    cars, its lights, the robot and its people, the scripted one first (each walking
    `t_end` seconds ahead), the crowd's members after a CrowdDirector that gives them
    their walks."""
    people = [
        PedestrianBody(p.looks, p, name=person_name(p, k), t_end=t_end, scripted=k == 0)
        for k, p in enumerate(scenario.people)
    ]
    planned = len(scenario.planned)
    crowd = [CrowdDirector(scenario, people[planned:], t_end)] if scenario.crowd else []
    robot, camera = scenario.robot, scenario.robot.camera.model()
    return [
        *parked_cars(scenario.scene),
        *lights(
            scenario.scene.lighting,
            scenario.scene.lamps,
            camera,
            robot.headlamps,
            robot.length / 2,
        ),  # fmt: skip
        RobotBody(camera, robot),
        *crowd,
        *people,
    ]


class World(Closing):
    """A scenario brought to life; call reset() first, then step() once per frame."""

    def __init__(
        self,
        scenario: Scenario,
        render: bool = True,
        ttc_lookahead: float = TTC_LOOKAHEAD,
        render_context: RenderContext | None = None,
        extra: Sequence[Entity] = (),
    ) -> None:
        """`render_context`, when given, is lent to the renderer (sim.world.render: reusing one
        across worlds saves its shader compilation); otherwise the world makes its own.
        `extra`: more bodies for the scene (each an Entity), after the scenario's own."""
        if not ttc_lookahead >= scenario.horizon:
            raise ValueError("the time-to-collision lookahead must cover the horizon")
        self.scenario = scenario
        self.render_frames = render
        self.render_context = render_context
        self.ttc_lookahead = ttc_lookahead
        t_end = scenario.duration + ttc_lookahead + CASE_WINDOW + 1.0
        entities = [*scenario_entities(scenario, t_end), *extra]
        self.scene = Scene(SceneConfig.of(scenario), entities)
        self._geom_kinds = self.scene.geom_kinds()
        self.camera: CameraModel = self.scene.camera
        self._renderer: SceneRenderer | None = None
        # A real camera's sensor exposes each frame (sim.world.shutter); the ideal camera
        # (None) gives the renderer's frames as they are.
        sensor = scenario.robot.camera.sensor
        self.shutter: Shutter | None = None
        if sensor is not None and render:
            light = scenario.scene.lighting
            self.shutter = Shutter(
                Sensor(sensor, light.illuminance_lux, scenario.dt, scenario.seed),
                self.scene,
                photometric=light.night,
            )
        self._frame_time = 0.0
        self.road: Road | None = None
        self.time = 0.0
        self.index = 0
        self.seed = scenario.seed
        self.last: WorldStep | None = None

    @property
    def entities(self) -> list[Entity]:
        return self.scene.entities

    @property
    def robot_body(self) -> RobotBody:
        return self.scene.robot

    @property
    def robot(self) -> Robot | None:
        """The robot's highway-env vehicle (None before reset)."""
        return self.scene.robot.vehicle

    @property
    def pedestrian(self) -> Pedestrian | None:
        """The scenario's pedestrian's highway-env road object (None before reset)."""
        return self.scene.pedestrians[0].walker

    @property
    def pitch(self) -> float:
        """rad, the body's momentary nose-down pitch (RobotSpec.pitch)."""
        return self.scene.robot.pitch

    @property
    def true_camera(self) -> CameraModel:
        """The camera as it really points now: the nominal one turned by the body's pitch."""
        return self.scene.robot.true_camera

    # -- stepping ---------------------------------------------------------------------

    def reset(self, seed: int | None = None) -> WorldStep:
        """Back to the scenario's start; the seed (default the scenario's) sets the gait phase."""
        self.seed = self.scenario.seed if seed is None else int(seed)
        rng = np.random.default_rng(self.seed)
        self.road = highway_road(self.scenario.scene.road)
        for entity in self.entities:
            entity.reset(self.road, rng, self.seed)
        if self.shutter is not None:
            self.shutter.reset(self.seed)
        self.time, self.index = 0.0, 0
        return self._observe()

    def step(self, dt: float | None = None, action: float = 0.0) -> WorldStep:
        """Advance by dt (default the scenario's) with the robot accelerating at `action` m/s^2.

        Order: the robot takes the action, the bodies move on (the pedestrian walks),
        highway-env's road steps the robot's kinematics and its collision checks, the
        bodies react (the robot's pitch), then each body places itself in MuJoCo, the
        camera renders and each body's truth is read at the new time.
        """
        if self.road is None:
            raise RuntimeError("call World.reset() before World.step()")
        dt = self.scenario.dt if dt is None else float(dt)
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"time step must be positive, got {dt}")
        self.robot_body.act(float(action))
        for entity in self.entities:
            entity.before_step(dt)
        self.road.act()
        self.road.step(dt)
        for entity in self.entities:
            entity.after_step(dt)
        self.time = self.time + dt
        self.index += 1
        return self._observe()

    def run(self, policy: Callable[[WorldStep], float] | None = None) -> Iterator[WorldStep]:
        """The scenario's frames from reset(); `policy` maps each step to the next action."""
        step = self.reset()
        yield step
        for _ in range(self.scenario.frames - 1):
            step = self.step(action=policy(step) if policy else 0.0)
            yield step

    # -- rendering --------------------------------------------------------------------

    @property
    def renderer(self) -> SceneRenderer:
        """The robot camera's renderer, made on first use (sim.world.render says why)."""
        if self._renderer is None:
            self._renderer = SceneRenderer(self.scene, context=self.render_context)
        return self._renderer

    def render(self, markers: tuple[Marker, ...] = ()) -> np.ndarray:
        """The robot camera's image of the current state (RGB uint8), e.g. with test markers."""
        return self.renderer.render(markers)

    def pedestrian_mask(self) -> np.ndarray:
        """Pixels where the scenario's pedestrian is visible in the current image (bool, H x W)."""
        return self.renderer.mask(self.scene.geoms_of(self.scene.pedestrians[0]))

    def person_masks(self) -> dict[str, np.ndarray]:
        """Every person's visible pixels in the current image (bool, H x W) by their name
        (PersonTruth.name), from one segmentation render; other people and objects hide
        them as in the image."""
        people = self.scene.pedestrians
        masks = self.renderer.masks([self.scene.geoms_of(p) for p in people])
        return {p.name: mask for p, mask in zip(people, masks, strict=True)}

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # -- truth ------------------------------------------------------------------------

    def robot_state(self) -> RobotState:
        return self.robot_body.state(self.time)

    def _observe(self) -> WorldStep:
        robot = self.robot_state()
        self.scene.place(Moment(self.time, robot.pose))
        truth = self._ground_truth(robot)
        ego = EgoState(self.camera, robot.speed, robot.yaw_rate)
        frame = None
        if self.shutter is not None:
            interval = self.time - self._frame_time if self.index else 0.0
            image, exposure = self.shutter.capture(self.render, interval)
            truth = replace(truth, camera=exposure)
            frame = Frame(image, self.time, ego, self.index)
        elif self.render_frames:
            frame = Frame(self.render(), self.time, ego, self.index)
        self._frame_time = self.time
        self.last = WorldStep(self.index, self.time, ego, truth, frame)
        return self.last

    def _ground_truth(self, robot: RobotState) -> GroundTruth:
        """Each body's own truth, composed: the robot's, each pedestrian's, the others'."""
        body = self.robot_body
        assert body.vehicle is not None
        sight = Sight(
            time=self.time,
            robot=robot,
            camera=body.true_camera,
            camera_world=body.camera_world(self.scene.data),
            robot_polygon=body.vehicle.polygon(),
            robot_velocity=body.vehicle.velocity,
            horizon=self.scenario.horizon,
            lookahead=self.ttc_lookahead,
            geom_kind=self._geom_kinds,
        )
        people: list[PersonTruth] = []
        others: dict[str, object] = {}
        model, data = self.scene.model, self.scene.data
        for entity in self.entities:
            if entity is body:
                continue
            told = entity.truth(model, data, sight)
            if isinstance(told, PersonTruth):
                people.append(told)
            elif told is not None:
                others[entity.name] = told
        return GroundTruth(self.time, self.index, robot, tuple(people), others)
