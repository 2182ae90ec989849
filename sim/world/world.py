"""The simulated world: one step advances highway-env, poses MuJoCo, renders, tells the truth.

highway-env owns the motion: the robot is a highway-env vehicle (sim.world.robot) on a
highway-env road, the pedestrian a highway-env road object walking its scenario path
(sim.world.pedestrian). MuJoCo only shows it: each step puts the camera robot and the
mannequin where highway-env says, renders the robot camera and reads the mannequin's
landmarks for the ground truth (sim.world.ground_truth). The scenario runner, the gymnasium
environment and the closed loop all call the same `World.step`.

Rendering: the MuJoCo renderer (an EGL context) is created lazily on the first frame, in
the process that steps the world; EGL contexts do not survive fork, so build Worlds
inside spawned workers from the (plain-data) Scenario. With `render=False` no renderer is
ever made and `WorldStep.frame` is None; everything else, the ground truth included
(occlusion is a ray test, not a mask), is the same, which makes ground-truth-only runs fast.

Nose dip: with a RobotSpec.pitch gain the body pitches with the applied acceleration
(a damped second-order response, integrated in each step). The camera is rendered at
the real pitch (turned about its own centre) and the truth's image positions use it
(`true_camera`); the pipeline's EgoState keeps the nominal CameraModel, as a car's
camera calibration does not know the momentary dip.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

import mujoco
import numpy as np
from highway_env.road.road import Road

from monopic.camera import CameraModel
from monopic.closing import Closing
from monopic.frame import EgoState, Frame
from sim.geometry.frames import Pose2D, wrap_angle
from sim.scenario.spec import Scenario
from sim.scenario.track import PathState
from sim.world.body import PedestrianTruth, image_box
from sim.world.ground_truth import (
    CASE_WINDOW,
    TORSO_LANDMARKS,
    GroundTruth,
    RobotState,
    case_label,
    facing_angles,
    head_yaws,
    in_image,
    occluded_landmarks,
    polygons_intersect,
    time_to_contact,
)
from sim.world.intent import intent_label
from sim.world.pedestrian import Pedestrian
from sim.world.render import Marker, RenderContext, SceneRenderer
from sim.world.robot import Robot, highway_road
from sim.world.scene import Scene, SceneConfig

ROBOT_START = Pose2D(0.0, 0.0, 0.0)  # the world origin, heading east along the road
TTC_LOOKAHEAD = 10.0  # s: how far ahead the time to collision is searched
PITCH_SUBSTEP = 0.005  # s, integration step of the body's pitch response


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


class World(Closing):
    """A scenario brought to life; call reset() first, then step() once per frame."""

    def __init__(
        self,
        scenario: Scenario,
        render: bool = True,
        ttc_lookahead: float = TTC_LOOKAHEAD,
        render_context: RenderContext | None = None,
    ) -> None:
        """`render_context`, when given, is lent to the renderer (sim.world.render: reusing one
        across worlds saves its shader compilation); otherwise the world makes its own."""
        if not ttc_lookahead >= scenario.horizon:
            raise ValueError("the time-to-collision lookahead must cover the horizon")
        self.scenario = scenario
        self.render_frames = render
        self.render_context = render_context
        self.ttc_lookahead = ttc_lookahead
        self.scene = Scene(SceneConfig.of(scenario))
        self.camera: CameraModel = self.scene.camera
        self._renderer: SceneRenderer | None = None
        self.road: Road | None = None
        self.robot: Robot | None = None
        self.pedestrian: Pedestrian | None = None
        self.time = 0.0
        self.index = 0
        self.seed = scenario.seed
        self._yaw_rate = 0.0
        self.pitch = 0.0  # rad, the body's momentary nose-down pitch (RobotSpec.pitch)
        self._pitch_rate = 0.0
        self._robot_mocap = int(self.scene.model.body("robot").mocapid[0])
        self.last: WorldStep | None = None

    # -- stepping ---------------------------------------------------------------------

    def reset(self, seed: int | None = None) -> WorldStep:
        """Back to the scenario's start; the seed (default the scenario's) sets the gait phase."""
        self.seed = self.scenario.seed if seed is None else int(seed)
        rng = np.random.default_rng(self.seed)
        self.road = highway_road(self.scenario.scene.road, self.scenario.scene.occluders)
        self.robot = Robot(self.road, self.scenario.robot, ROBOT_START)
        self.road.vehicles.append(self.robot)
        self.pedestrian = Pedestrian(
            self.road,
            self.scenario.pedestrian,
            self.scene.gait,
            t_end=self.scenario.duration + self.ttc_lookahead + CASE_WINDOW + 1.0,
            seed=self.seed,
        )
        self.pedestrian.reset(gait_phase=float(rng.uniform()))
        self.road.objects.append(self.pedestrian)
        self.time, self.index, self._yaw_rate = 0.0, 0, 0.0
        self.pitch, self._pitch_rate = 0.0, 0.0
        return self._observe()

    def step(self, dt: float | None = None, action: float = 0.0) -> WorldStep:
        """Advance by dt (default the scenario's) with the robot accelerating at `action` m/s^2.

        Order: the robot takes the action, the pedestrian walks, highway-env's road steps
        the robot's kinematics and its collision checks, then MuJoCo is posed, the camera
        renders and the ground truth is read at the new time.
        """
        if self.robot is None or self.pedestrian is None or self.road is None:
            raise RuntimeError("call World.reset() before World.step()")
        dt = self.scenario.dt if dt is None else float(dt)
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"time step must be positive, got {dt}")
        yaw_before = self.robot.world_pose.yaw
        self.robot.act(float(action))
        self.pedestrian.step(dt)
        self.road.act()
        self.road.step(dt)
        self._yaw_rate = wrap_angle(self.robot.world_pose.yaw - yaw_before) / dt
        self._advance_pitch(dt, float(self.robot.applied_acceleration))
        self.time = self.pedestrian.time
        self.index += 1
        return self._observe()

    def run(self, policy: Callable[[WorldStep], float] | None = None) -> Iterator[WorldStep]:
        """The scenario's frames from reset(); `policy` maps each step to the next action."""
        step = self.reset()
        yield step
        for _ in range(self.scenario.frames - 1):
            step = self.step(action=policy(step) if policy else 0.0)
            yield step

    # -- the body's pitch ---------------------------------------------------------------

    @property
    def true_camera(self) -> CameraModel:
        """The camera as it really points now: the nominal one turned by the body's pitch."""
        if self.pitch == 0.0:
            return self.camera
        return replace(self.camera, pitch=self.camera.pitch + self.pitch)

    def _advance_pitch(self, dt: float, acceleration: float) -> None:
        """Integrate the pitch response to `acceleration` (m/s^2) over one step."""
        spec = self.scenario.robot.pitch
        if spec.gain == 0.0:
            return
        target = math.radians(spec.gain * -acceleration)  # braking: nose down (+)
        omega = 2 * math.pi * spec.frequency
        n = max(1, math.ceil(dt / PITCH_SUBSTEP))
        h = dt / n
        for _ in range(n):  # semi-implicit Euler: stable for these stiffnesses
            accel = omega**2 * (target - self.pitch) - 2 * spec.damping * omega * self._pitch_rate
            self._pitch_rate += h * accel
            self.pitch += h * self._pitch_rate

    def _pose_pitched_camera(self, x: float, y: float, yaw: float) -> None:
        """Turn the MuJoCo robot body by the pitch about the camera's centre."""
        scene = self.scene
        q_yaw = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
        q_pitch = np.array([math.cos(self.pitch / 2), 0.0, math.sin(self.pitch / 2), 0.0])
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, q_yaw, q_pitch)
        c = self.camera.position
        s, k = math.sin(self.pitch), math.cos(self.pitch)
        pitched = np.array([k * c[0] + s * c[2], c[1], -s * c[0] + k * c[2]])  # R_y c
        d = c - pitched  # keep the camera centre where the unpitched body puts it
        cy, sy = math.cos(yaw), math.sin(yaw)
        scene.data.mocap_pos[self._robot_mocap] = (
            x + cy * d[0] - sy * d[1],
            y + sy * d[0] + cy * d[1],
            d[2],
        )
        scene.data.mocap_quat[self._robot_mocap] = quat
        mujoco.mj_kinematics(scene.model, scene.data)
        mujoco.mj_camlight(scene.model, scene.data)

    def _seen_by(self, body: PedestrianTruth, camera: CameraModel) -> PedestrianTruth:
        """The body's image positions through `camera` (the real, pitched one)."""
        scene = self.scene
        surface = scene.mannequin.surface_points(scene.data)
        box, in_frame = image_box(camera, scene.world_to_robot(surface))
        return replace(
            body,
            landmarks_px=camera.project(body.landmarks_robot),
            foot_px=camera.project(body.foot_robot),
            box=box,
            in_frame=in_frame,
        )

    # -- rendering --------------------------------------------------------------------

    def render(self, markers: tuple[Marker, ...] = ()) -> np.ndarray:
        """The robot camera's image of the current state (RGB uint8), e.g. with test markers."""
        if self._renderer is None:
            self._renderer = SceneRenderer(self.scene, context=self.render_context)
        return self._renderer.render(markers)

    def pedestrian_mask(self) -> np.ndarray:
        """Pixels where the pedestrian is visible in the current image (bool, H x W)."""
        if self._renderer is None:
            self._renderer = SceneRenderer(self.scene, context=self.render_context)
        return self._renderer.pedestrian_mask()

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # -- truth ------------------------------------------------------------------------

    def robot_state(self) -> RobotState:
        assert self.robot is not None
        pose = self.robot.world_pose
        return RobotState(
            time=self.time,
            position=np.array([pose.x, pose.y]),
            yaw=pose.yaw,
            speed=float(self.robot.speed),
            acceleration=float(self.robot.applied_acceleration),
            yaw_rate=self._yaw_rate,
            length=self.scenario.robot.length,
            width=self.scenario.robot.width,
        )

    def _observe(self) -> WorldStep:
        assert self.robot is not None and self.pedestrian is not None
        robot = self.robot_state()
        ped = self.pedestrian.state
        self.scene.set_camera_pose(robot.pose.x, robot.pose.y, robot.pose.yaw)
        if self.pitch != 0.0:
            self._pose_pitched_camera(robot.pose.x, robot.pose.y, robot.pose.yaw)
        self.scene.set_pedestrian(
            ped.position[0],
            ped.position[1],
            ped.yaw,
            self.pedestrian.gait_phase,
            ped.speed,
            sway=self.pedestrian.body_sways,
            head_yaw=ped.head_yaw,
            torso_yaw=ped.torso_yaw,
        )
        truth = self._ground_truth(robot, ped)
        ego = EgoState(self.camera, robot.speed, robot.yaw_rate)
        frame = Frame(self.render(), self.time, ego, self.index) if self.render_frames else None
        self.last = WorldStep(self.index, self.time, ego, truth, frame)
        return self.last

    def _ground_truth(self, robot: RobotState, ped: PathState) -> GroundTruth:
        assert self.robot is not None and self.pedestrian is not None
        scenario, scene, camera = self.scenario, self.scene, self.true_camera
        pose = robot.pose
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)

        def axes(v: np.ndarray) -> np.ndarray:  # world vector -> robot axes
            return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])

        def local(p: np.ndarray) -> np.ndarray:  # world point -> robot frame
            return pose.to_local(np.array([p[0], p[1], 0.0]))[:2]

        path = self.pedestrian.path
        robot_velocity = robot.speed * np.array([c, s])
        ahead = path.state(self.time + CASE_WINDOW).position
        case, case_velocity = case_label((ahead - ped.position) / CASE_WINDOW, pose.yaw)
        future = path.state(self.time + scenario.horizon).position
        intent = intent_label(path, self.time, pose, scenario.horizon)

        robot_polygon = self.robot.polygon()
        contact = polygons_intersect(robot_polygon, self.pedestrian.polygon())
        ttc = time_to_contact(
            robot_polygon, self.robot.velocity, self.pedestrian, self.time, self.ttc_lookahead
        )

        body = scene.truth()
        if camera is not self.camera:
            body = self._seen_by(body, camera)
        centre_px = camera.project(body.landmarks_robot[list(TORSO_LANDMARKS)].mean(axis=0))
        camera_world = scene.data.cam_xpos[scene.camera_id].copy()
        hidden = occluded_landmarks(
            scene.model, scene.data, camera_world, body.landmarks_world, scene.mannequin.geom_ids
        )
        visible = in_image(camera, body.landmarks_px) & ~hidden
        # The shoulders face the walking direction turned by the walker's cue (if any).
        shoulders = ped.yaw + ped.torso_yaw
        facing, facing_view, beta, phi = facing_angles(pose, camera, ped.position, shoulders)
        head_from_shoulders, head_from_camera = head_yaws(body.landmarks_world, camera_world)
        return GroundTruth(
            time=self.time,
            index=self.index,
            robot=robot,
            position_world=ped.position.copy(),
            velocity_world=ped.velocity,
            heading_world=ped.yaw,
            speed=ped.speed,
            position_robot=local(ped.position),
            velocity_robot=axes(ped.velocity),
            relative_velocity_robot=axes(ped.velocity - robot_velocity),
            heading_robot=wrap_angle(ped.yaw - pose.yaw),
            case=case,
            case_velocity_robot=case_velocity,
            case_now=intent.case_now,
            intent=intent.intent,
            intent_time=intent.time,
            horizon=scenario.horizon,
            future_position_world=future,
            future_position_robot=local(future),
            contact=contact,
            collision=ttc is not None and ttc <= scenario.horizon,
            time_to_collision=ttc,
            body=body,
            centre_px=centre_px,
            landmarks_occluded=hidden,
            visible_fraction=float(visible.mean()),
            occluded=bool(hidden.mean() > 0.5),
            facing_yaw=facing,
            facing_yaw_view=facing_view,
            beta=beta,
            phi=phi,
            head_yaw_shoulders=head_from_shoulders,
            head_yaw_camera=head_from_camera,
        )
