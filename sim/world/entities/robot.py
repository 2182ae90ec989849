"""The robot carrying the camera: highway-env's vehicle, its MuJoCo body and camera, its pitch.

highway-env owns its motion (sim.world.robot.Robot). In MuJoCo it is a mocap body on the
ground at its reference point, x forward, carrying the camera at the CameraModel's
mounting, so CameraModel.project of a robot-frame point lands on the pixel where MuJoCo
draws it. Its box is in a geom group the robot camera does not draw.

Nose dip: with a RobotSpec.pitch gain the body pitches with the applied acceleration (a
damped second-order response, integrated each step). The camera is rendered at the real
pitch (turned about its own centre) and the truth's image positions use it
(`true_camera`); the pipeline's EgoState keeps the nominal CameraModel, as a car's camera
calibration does not know the momentary dip.
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np
from highway_env.road.road import Road

from monopic.camera import CameraModel
from sim.geometry.frames import Pose2D, wrap_angle, yaw_quat
from sim.scenario.spec import RobotSpec
from sim.world.entities.base import Entity, Moment
from sim.world.ground_truth import RobotState
from sim.world.robot import Robot

ROBOT_START = Pose2D(0.0, 0.0, 0.0)  # the world origin, heading east along the road
ROBOT_GEOM_GROUP = 3  # the robot's own body is hidden from its camera
PITCH_SUBSTEP = 0.005  # s, integration step of the body's pitch response


def camera_quat(camera: CameraModel) -> np.ndarray:
    """Orientation of the MuJoCo camera in the robot body.

    MuJoCo cameras look along their -z with y up; the optical frame of CameraModel has
    x right, y down, z forward. So MuJoCo's x = optical x, y = -optical y, z = -optical z.
    """
    opt = camera.axes  # rows: optical x, y, z in the robot frame
    mat = np.column_stack([opt[0], -opt[1], -opt[2]]).reshape(-1)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat)
    return quat


class RobotBody(Entity):
    """The camera robot. `spec` None: a camera on a stand that only a still scene poses."""

    name = "robot"

    def __init__(self, camera: CameraModel, spec: RobotSpec | None = None) -> None:
        self.camera = camera
        self.spec = spec
        self.vehicle: Robot | None = None
        self.pitch = 0.0  # rad, the body's momentary nose-down pitch (RobotSpec.pitch)
        self._pitch_rate = 0.0
        self.yaw_rate = 0.0
        self._yaw = ROBOT_START.yaw
        self.pose = Pose2D(0.0, 0.0, 0.0)  # where MuJoCo last put it

    @property
    def camera_name(self) -> str:
        return self.prefix + "camera"

    # -- MJCF -------------------------------------------------------------------------

    def build(self, spec: mujoco.MjSpec) -> None:
        body = spec.worldbody.add_body(name=self.name, mocap=True)
        body.add_geom(
            name=self.prefix + "chassis",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[0.3, 0.25, 0.15],
            pos=[-0.3, 0, 0.2],
            rgba=[0.9, 0.6, 0.1, 1],
            group=ROBOT_GEOM_GROUP,
            contype=0,
            conaffinity=0,
        )
        cam = self.camera
        body.add_camera(
            name=self.camera_name,
            pos=cam.position.tolist(),
            quat=camera_quat(cam).tolist(),
            fovy=cam.vertical_fov_deg,
        )

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._mocap = int(model.body(self.name).mocapid[0])
        self.camera_id = int(model.camera(self.camera_name).id)

    # -- motion -----------------------------------------------------------------------

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        if self.spec is None:
            raise RuntimeError("a robot without a RobotSpec cannot drive")
        self.vehicle = Robot(road, self.spec, ROBOT_START)
        road.vehicles.append(self.vehicle)
        self.pitch, self._pitch_rate, self.yaw_rate = 0.0, 0.0, 0.0
        self._yaw = self.vehicle.world_pose.yaw

    def act(self, acceleration: float) -> None:
        """The longitudinal acceleration (m/s^2) for the next step."""
        assert self.vehicle is not None
        self.vehicle.act(acceleration)

    def after_step(self, dt: float) -> None:
        """After highway-env's step: the yaw rate of the step and the pitch response."""
        assert self.vehicle is not None and self.spec is not None
        yaw = self.vehicle.world_pose.yaw
        self.yaw_rate = wrap_angle(yaw - self._yaw) / dt
        self._yaw = yaw
        self._advance_pitch(dt, float(self.vehicle.applied_acceleration))

    def _advance_pitch(self, dt: float, acceleration: float) -> None:
        """Integrate the pitch response to `acceleration` (m/s^2) over one step."""
        assert self.spec is not None
        spec = self.spec.pitch
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

    @property
    def true_camera(self) -> CameraModel:
        """The camera as it really points now: the nominal one turned by the body's pitch."""
        if self.pitch == 0.0:
            return self.camera
        return replace(self.camera, pitch=self.camera.pitch + self.pitch)

    # -- MuJoCo -----------------------------------------------------------------------

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        """The reference point at the moment's robot pose, on the ground; turned by the
        pitch about the camera's centre when the body pitches."""
        pose = moment.robot
        self.pose = pose
        if self.pitch == 0.0:
            data.mocap_pos[self._mocap] = (pose.x, pose.y, 0.0)
            data.mocap_quat[self._mocap] = yaw_quat(pose.yaw)
            return
        yaw = pose.yaw
        q_yaw = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
        q_pitch = np.array([math.cos(self.pitch / 2), 0.0, math.sin(self.pitch / 2), 0.0])
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, q_yaw, q_pitch)
        c = self.camera.position
        s, k = math.sin(self.pitch), math.cos(self.pitch)
        pitched = np.array([k * c[0] + s * c[2], c[1], -s * c[0] + k * c[2]])  # R_y c
        d = c - pitched  # keep the camera centre where the unpitched body puts it
        cy, sy = math.cos(yaw), math.sin(yaw)
        data.mocap_pos[self._mocap] = (
            pose.x + cy * d[0] - sy * d[1],
            pose.y + sy * d[0] + cy * d[1],
            d[2],
        )
        data.mocap_quat[self._mocap] = quat

    def camera_world(self, data: mujoco.MjData) -> np.ndarray:
        """The camera's centre in the world frame (after the scene's kinematics)."""
        return data.cam_xpos[self.camera_id].copy()

    # -- truth ------------------------------------------------------------------------

    def state(self, time: float) -> RobotState:
        """The robot's own state now (what it knows about itself, plus its pose)."""
        assert self.vehicle is not None and self.spec is not None
        pose = self.vehicle.world_pose
        return RobotState(
            time=time,
            position=np.array([pose.x, pose.y]),
            yaw=pose.yaw,
            speed=float(self.vehicle.speed),
            acceleration=float(self.vehicle.applied_acceleration),
            yaw_rate=self.yaw_rate,
            length=self.spec.length,
            width=self.spec.width,
        )
