"""The MuJoCo world: street, sun and sky, a robot carrying the camera, one pedestrian.

Built in code with mujoco.MjSpec. Frames (see sim.geometry.frames): world x east, y north, z up,
ground at z = 0, headings in radians counter-clockwise from east.

The robot and the pedestrian are placed, not simulated: whoever owns the motion (a
scenario, later highway-env through World.step) calls `set_camera_pose` and
`set_pedestrian` once per frame, then renders and reads `truth()`. The robot is a mocap
body carrying the camera at the CameraModel's mounting (height, forward offset, pitch,
field of view), so CameraModel.project of a robot-frame point lands on the pixel where
MuJoCo draws it. The sun's shadow map follows the camera so shadows stay sharp where
the camera looks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np

from monopic.camera import CameraModel
from sim.geometry.frames import Pose2D, yaw_quat
from sim.scenario.spec import CameraSpec, MannequinSpec, Scenario, SceneSpec
from sim.world.body import PedestrianTruth, make_truth
from sim.world.gait import Gait, MannequinPose
from sim.world.mannequin import Mannequin, build_mannequin
from sim.world.street import build_street

PEDESTRIAN_PREFIX = "ped/"
CAMERA_NAME = "robot/camera"
ROBOT_GEOM_GROUP = 3  # the robot's own body is hidden from its camera
SCENE_EXTENT = 100.0  # m; MuJoCo's clip planes and shadow box are fractions of this
NEAR_CLIP = 0.05  # m
FAR_CLIP = 400.0  # m


def default_camera() -> CameraModel:
    """The robot's default camera (sim.scenario.presets, through CameraSpec)."""
    return CameraSpec().model()


@dataclass(frozen=True)
class SceneConfig:
    """Everything static about a scene; poses change per frame through Scene's setters."""

    camera: CameraModel = field(default_factory=default_camera)
    pedestrian: MannequinSpec = field(default_factory=MannequinSpec)
    # The scenario's street, parked cars, sun and sky (SceneSpec holds their defaults).
    # Overcast (shadows False) also halves the render time on software GL: the shadow
    # pass is half of it (bench/simulator.py).
    spec: SceneSpec = field(default_factory=SceneSpec)
    # How it is drawn: the same for every scenario.
    shadow_size: int = 768  # shadow map texels per side (1024: +4 ms a frame, same detections)
    shadow_half_extent: float = 20.0  # m, half-size of the sharp-shadow region
    shadow_centre_ahead: float = 12.0  # m ahead of the robot where that region is centred
    msaa_samples: int = 0  # multisampling doubles the render time and does not change detection
    # Tessellation of MuJoCo's primitive shapes. Software GL (llvmpipe) pays per vertex
    # twice (shadow pass + colour pass): MuJoCo's defaults (28 slices, 16 stacks, 4 quads)
    # cost 67 ms a frame, these 47 ms, with limbs still round at 2 m (bench/simulator.py).
    sphere_slices: int = 12
    sphere_stacks: int = 8
    box_quads: int = 1

    @classmethod
    def of(cls, scenario: Scenario) -> SceneConfig:
        """The scene a scenario describes, seen by its robot's camera."""
        return cls(scenario.robot.camera.model(), scenario.pedestrian.looks, scenario.scene)

    def __post_init__(self) -> None:
        cam = self.camera
        if abs(cam.fx - cam.fy) > 1e-6 * cam.fx:
            raise ValueError("the simulated camera needs square pixels (fx == fy)")
        if abs(cam.cx - cam.width / 2) > 1e-6 or abs(cam.cy - cam.height / 2) > 1e-6:
            raise ValueError("the simulated camera needs its principal point at the image centre")


@dataclass(frozen=True)
class PedestrianState:
    """Where the pedestrian stands and how it moves at this frame."""

    x: float
    y: float
    yaw: float
    gait_phase: float = 0.0
    speed: float = 0.0


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


def sun_direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Unit vector the sunlight travels along (from the sun towards the ground)."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    towards_sun = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    return -towards_sun


def build_spec(config: SceneConfig) -> mujoco.MjSpec:
    """The whole scene as an MjSpec (compile it to get the model)."""
    spec = mujoco.MjSpec()
    spec.modelname = "monopic_street"
    cam = config.camera
    vis = spec.visual
    vis.global_.offwidth = cam.width
    vis.global_.offheight = cam.height
    vis.quality.shadowsize = config.shadow_size
    vis.quality.offsamples = config.msaa_samples
    vis.quality.numslices = config.sphere_slices
    vis.quality.numstacks = config.sphere_stacks
    vis.quality.numquads = config.box_quads
    spec.stat.extent = SCENE_EXTENT
    spec.stat.center = [0.0, 0.0, 0.0]
    vis.map.znear = NEAR_CLIP / SCENE_EXTENT
    vis.map.zfar = FAR_CLIP / SCENE_EXTENT
    vis.map.shadowclip = config.shadow_half_extent / SCENE_EXTENT
    # Overcast: more sky light from everywhere, a weak sun that casts nothing.
    vis.headlight.ambient = [0.32, 0.32, 0.33] if config.spec.shadows else [0.5, 0.5, 0.52]
    vis.headlight.diffuse = [0.25, 0.25, 0.25] if config.spec.shadows else [0.3, 0.3, 0.3]
    vis.headlight.specular = [0.0, 0.0, 0.0]

    spec.add_texture(
        name="sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=[0.5, 0.68, 0.9],
        rgb2=[0.9, 0.93, 0.97],
        width=512,
        height=3072,
    )

    build_street(spec, config.spec.road, config.spec.occluders)

    # Sun: a directional light hung from a mocap anchor that the scene keeps ahead of
    # the robot; the anchor never rotates, so the light direction stays fixed in the world.
    anchor = spec.worldbody.add_body(name="sun_anchor", mocap=True)
    direction = sun_direction(config.spec.sun_azimuth_deg, config.spec.sun_elevation_deg)
    anchor.add_light(
        name="sun",
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        pos=(-60.0 * direction).tolist(),
        dir=direction.tolist(),
        castshadow=config.spec.shadows,
        diffuse=[0.78, 0.76, 0.72] if config.spec.shadows else [0.35, 0.35, 0.36],
        ambient=[0.12, 0.12, 0.13],
        specular=[0.15, 0.15, 0.15],
    )

    # Robot: a mocap body on the ground at its reference point, x forward, carrying the
    # camera. Its box is in a geom group the robot camera does not draw.
    robot = spec.worldbody.add_body(name="robot", mocap=True)
    robot.add_geom(
        name="robot/chassis",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.3, 0.25, 0.15],
        pos=[-0.3, 0, 0.2],
        rgba=[0.9, 0.6, 0.1, 1],
        group=ROBOT_GEOM_GROUP,
        contype=0,
        conaffinity=0,
    )
    robot.add_camera(
        name=CAMERA_NAME,
        pos=cam.position.tolist(),
        quat=camera_quat(cam).tolist(),
        fovy=cam.vertical_fov_deg,
    )

    build_mannequin(spec, config.pedestrian, PEDESTRIAN_PREFIX)
    return spec


class Scene:
    """A compiled street scene with a posable camera robot and pedestrian."""

    def __init__(self, config: SceneConfig | None = None) -> None:
        self.config = config or SceneConfig()
        self.spec = build_spec(self.config)
        self.model = self.spec.compile()
        self.data = mujoco.MjData(self.model)
        self.mannequin = Mannequin(self.model, self.config.pedestrian, PEDESTRIAN_PREFIX)
        self.gait = Gait(height=self.config.pedestrian.height)
        self._robot_mocap = int(self.model.body("robot").mocapid[0])
        self._sun_mocap = int(self.model.body("sun_anchor").mocapid[0])
        self.camera_id = int(self.model.camera(CAMERA_NAME).id)
        self.robot_pose = Pose2D(0.0, 0.0, 0.0)
        self.pedestrian = PedestrianState(x=5.0, y=0.0, yaw=math.pi)
        self.set_camera_pose(0.0, 0.0, 0.0)
        self.set_pedestrian(5.0, 0.0, math.pi)

    @property
    def camera(self) -> CameraModel:
        """The camera model the pipeline is given (intrinsics and mounting)."""
        return self.config.camera

    def set_camera_pose(self, x: float, y: float, yaw: float) -> None:
        """Put the robot's reference point at world (x, y) on the ground, heading `yaw`."""
        self.robot_pose = Pose2D(float(x), float(y), float(yaw))
        self.data.mocap_pos[self._robot_mocap] = (x, y, 0.0)
        self.data.mocap_quat[self._robot_mocap] = yaw_quat(yaw)
        ahead = self.config.shadow_centre_ahead
        self.data.mocap_pos[self._sun_mocap] = (
            x + ahead * math.cos(yaw),
            y + ahead * math.sin(yaw),
            0.0,
        )
        self._update()

    def set_pedestrian(
        self,
        x: float,
        y: float,
        yaw: float,
        gait_phase: float = 0.0,
        speed: float = 0.0,
        pose: MannequinPose | None = None,
        sway: bool = True,
        head_yaw: float = 0.0,
        torso_yaw: float = 0.0,
    ) -> None:
        """Stand the pedestrian at world (x, y) facing `yaw`.

        The body pose comes from the gait at `gait_phase` and `speed` (idle stance when
        the speed is about zero) unless `pose` is given. Advance the phase between
        frames with `self.gait.advance(phase, speed, dt)`. `sway` False: the placement
        itself sways (a human walker's track), so the pelvis does not sway again.
        `torso_yaw` turns the shoulders from the walking direction and `head_yaw` the head
        from the shoulders (radians, + to the left): a human walker's intent cues.
        """
        self.pedestrian = PedestrianState(
            float(x), float(y), float(yaw), float(gait_phase), float(speed)
        )
        body_pose = pose if pose is not None else self.gait.pose(gait_phase, speed)
        if not sway:
            body_pose = replace(body_pose, sway=0.0)
        if head_yaw or torso_yaw:
            body_pose = replace(
                body_pose,
                waist_yaw=body_pose.waist_yaw + torso_yaw,
                neck_yaw=body_pose.neck_yaw + head_yaw,
            )
        self.mannequin.place(self.model, self.data, x, y, yaw, body_pose)
        self._update()

    def _update(self) -> None:
        """Recompute body, camera and light poses after a placement."""
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def truth(self) -> PedestrianTruth:
        """Ground truth of the pedestrian as currently placed."""
        ped = self.pedestrian
        return make_truth(
            camera=self.camera,
            robot=self.robot_pose,
            placement=Pose2D(ped.x, ped.y, ped.yaw),
            speed=ped.speed,
            gait_phase=ped.gait_phase,
            landmarks_world=self.mannequin.landmarks(self.data),
            foot_world=self.mannequin.foot_point(self.data),
            surface_world=self.mannequin.surface_points(self.data),
            top_z=self.mannequin.top_height(self.data),
        )

    def world_to_robot(self, points_world: np.ndarray) -> np.ndarray:
        """World points (..., 3) in the robot frame of monopic.camera."""
        return self.robot_pose.to_local(points_world)

    def project(self, points_world: np.ndarray) -> np.ndarray:
        """World points (..., 3) to pixels through the camera model."""
        return self.camera.project(self.world_to_robot(points_world))
