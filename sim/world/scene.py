"""The MuJoCo scene: the street and sky, and a list of bodies (entities) in it.

Built in code with mujoco.MjSpec. Frames (see sim.geometry.frames): world x east, y north, z up,
ground at z = 0, headings in radians counter-clockwise from east.

Everything that is placed rather than part of the street is an entity
(sim.world.entities): the parked cars, the lighting's lights (the sun), the robot carrying
the camera, the pedestrians, and whatever a caller adds. The scene builds them into one
model in that order, binds each to its ids and, each frame, lets each place itself
(`place`) before it runs MuJoCo's kinematics once. Bodies are placed, not simulated:
whoever owns the motion (highway-env through World.step, or a still scene's caller)
says where they are.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import mujoco
import numpy as np

from monopic.camera import CameraModel
from sim.geometry.frames import Pose2D
from sim.scenario.spec import CameraSpec, MannequinSpec, Scenario, SceneSpec
from sim.world.entities.base import Entity, Moment
from sim.world.entities.parked_car import ParkedCar
from sim.world.entities.pedestrian import PedestrianBody
from sim.world.entities.robot import RobotBody
from sim.world.ground_truth import HIDERS
from sim.world.lighting import build_sky, lights
from sim.world.street import build_street

SCENE_EXTENT = 100.0  # m; MuJoCo's clip planes and shadow box are fractions of this
NEAR_CLIP = 0.05  # m
FAR_CLIP = 400.0  # m
NIGHT_GRID = 1.0  # m, the street's lit grid at night (sim.world.street)


def default_camera() -> CameraModel:
    """The robot's default camera (sim.scenario.presets, through CameraSpec)."""
    return CameraSpec().model()


@dataclass(frozen=True)
class SceneConfig:
    """Everything static about a scene; its bodies place themselves each frame."""

    camera: CameraModel = field(default_factory=default_camera)
    pedestrian: MannequinSpec = field(default_factory=MannequinSpec)
    # The scenario's street, parked cars and lighting (SceneSpec holds their defaults).
    spec: SceneSpec = field(default_factory=SceneSpec)
    # How it is drawn: the same for every scenario.
    shadow_size: int = 768  # shadow map texels per side (1024: +4 ms a frame, same detections)
    shadow_half_extent: float = 20.0  # m, half-size of the sharp-shadow region
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


def scene_entities(config: SceneConfig) -> list[Entity]:
    """The bodies a still scene has: its parked cars, its lights, a camera robot that does
    not drive and one standing pedestrian of the config's looks."""
    return [
        *parked_cars(config.spec),
        *lights(config.spec.lighting, config.spec.lamps, config.camera),
        RobotBody(config.camera),
        PedestrianBody(config.pedestrian),
    ]


def parked_cars(spec: SceneSpec) -> list[Entity]:
    """The scene's parked cars, each a body of its own."""
    return [ParkedCar(occ, f"parked_car_{k}") for k, occ in enumerate(spec.occluders)]


def build_spec(config: SceneConfig, entities: Sequence[Entity]) -> mujoco.MjSpec:
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
    build_sky(spec, config.spec.lighting)
    lit_grid = NIGHT_GRID if config.spec.lighting.night else None
    build_street(spec, config.spec.road, lit_grid)
    for entity in entities:
        entity.build(spec)
    return spec


@dataclass(frozen=True)
class SceneState:
    """Where every placed body was at one moment: MuJoCo's joint positions and mocap poses
    (copies), enough to put the scene back there or part of the way to another moment."""

    qpos: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray


PROBE_COLUMNS = 5  # ground probes across the image ...
PROBE_ROWS = 3  # ... in its lower rows, where the nearest ground is


def _pixels(
    cam: CameraModel, position: np.ndarray, rotation: np.ndarray, points: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World points through a MuJoCo camera at `position`, `rotation` (its axes as columns:
    x right, y up, looking down -z): pixels and whether each is in front and in the image."""
    local = (points - position) @ rotation
    depth = -local[:, 2]
    safe = np.where(depth > 0.5, depth, 1.0)
    u = cam.cx + cam.fx * local[:, 0] / safe
    v = cam.cy - cam.fy * local[:, 1] / safe
    inside = (depth > 0.5) & (u >= 0) & (u < cam.width) & (v >= 0) & (v < cam.height)
    return np.stack([u, v], axis=1), inside


def _ground_probes(cam: CameraModel, position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Where rays through a grid of the image's lower pixels meet the ground (z = 0)."""
    u = np.linspace(0.0, cam.width - 1.0, PROBE_COLUMNS)
    v = np.linspace(cam.height - 1.0, 0.75 * cam.height, PROBE_ROWS)
    uu, vv = np.meshgrid(u, v)
    rays_cam = np.stack(
        [(uu.ravel() - cam.cx) / cam.fx, -(vv.ravel() - cam.cy) / cam.fy, -np.ones(uu.size)],
        axis=1,
    )
    rays = rays_cam @ rotation.T
    down = rays[:, 2] < -1e-6
    t = -position[2] / np.where(down, rays[:, 2], -1.0)
    return (position + t[:, None] * rays)[down]


class Scene:
    """A compiled street scene with its bodies; exactly one of them is the camera robot.

    `entities` None: the still scene of `scene_entities(config)`.
    """

    def __init__(
        self, config: SceneConfig | None = None, entities: Sequence[Entity] | None = None
    ) -> None:
        self.config = config or SceneConfig()
        self.entities = list(scene_entities(self.config) if entities is None else entities)
        names = [e.name for e in self.entities]
        if len(set(names)) != len(names):
            raise ValueError(f"two bodies of the scene share a name: {names}")
        robots = [e for e in self.entities if isinstance(e, RobotBody)]
        if len(robots) != 1:
            raise ValueError(f"a scene needs exactly one camera robot, got {len(robots)}")
        self.robot: RobotBody = robots[0]
        self.pedestrians = [e for e in self.entities if isinstance(e, PedestrianBody)]
        self.spec = build_spec(self.config, self.entities)
        self.model = self.spec.compile()
        self.data = mujoco.MjData(self.model)
        for entity in self.entities:
            entity.bind(self.model, self.data)
        for ped in self.pedestrians:  # a still scene's people stand in front of the robot
            ped.pose_at(self.model, self.data, 5.0, 0.0, math.pi)
        self.place(Moment(0.0, Pose2D(0.0, 0.0, 0.0)))

    @property
    def camera(self) -> CameraModel:
        """The camera model the pipeline is given (intrinsics and mounting)."""
        return self.config.camera

    @property
    def robot_pose(self) -> Pose2D:
        return self.robot.pose

    def place(self, moment: Moment) -> None:
        """Every body places itself for `moment`, then MuJoCo's kinematics (bodies, camera
        and lights) runs once."""
        for entity in self.entities:
            entity.place(self.model, self.data, moment)
        self.update()

    def set_camera_pose(self, x: float, y: float, yaw: float) -> None:
        """A still scene: put the robot's reference point at world (x, y) heading `yaw`
        (the lights that follow it move with it)."""
        self.place(Moment(0.0, Pose2D(float(x), float(y), float(yaw))))

    def update(self) -> None:
        """Recompute body, camera and light poses after bodies were placed."""
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def geom_kinds(self) -> np.ndarray:
        """Per geom: the kind of body that owns it, an index into ground_truth.HIDERS
        (people, parked cars; the street and anything else the last)."""
        kinds = np.full(self.model.ngeom, len(HIDERS) - 1, dtype=int)
        for entity in self.entities:
            if entity.kind in HIDERS:
                kinds[entity.geom_ids(self.model)] = HIDERS.index(entity.kind)
        return kinds

    def geoms_of(self, entity: Entity) -> np.ndarray:
        """The geom ids of one body (for a segmentation mask, an occlusion test)."""
        return entity.geom_ids(self.model)

    # -- between two moments (the exposure window: sim.world.shutter) -------------------

    def snapshot(self) -> SceneState:
        """The placed state now, to come back to or blend from."""
        d = self.data
        return SceneState(d.qpos.copy(), d.mocap_pos.copy(), d.mocap_quat.copy())

    def blend(self, a: SceneState, b: SceneState, w: float) -> None:
        """Put every body `w` of the way from state `a` to state `b` (0: a, 1: b) and run
        the kinematics: positions and joint angles linearly, orientations by normalised
        linear blending of their quaternions (within a frame they turn by a few degrees,
        where it and the spherical blend agree to far below a pixel)."""
        d = self.data
        d.qpos[:] = a.qpos + w * (b.qpos - a.qpos)
        for adr in self._quat_slots:
            q = d.qpos[adr : adr + 4]
            q /= np.linalg.norm(q)
        d.mocap_pos[:] = a.mocap_pos + w * (b.mocap_pos - a.mocap_pos)
        qa, qb = a.mocap_quat, b.mocap_quat
        sign = np.where(np.sum(qa * qb, axis=1, keepdims=True) < 0, -1.0, 1.0)
        q = qa + w * (sign * qb - qa)
        d.mocap_quat[:] = q / np.linalg.norm(q, axis=1, keepdims=True)
        self.update()

    @cached_property
    def _quat_slots(self) -> list[int]:
        """qpos addresses of the free and ball joints' quaternions."""
        m = self.model
        slots = []
        for j in range(m.njnt):
            kind = m.jnt_type[j]
            if kind == mujoco.mjtJoint.mjJNT_FREE:
                slots.append(int(m.jnt_qposadr[j]) + 3)
            elif kind == mujoco.mjtJoint.mjJNT_BALL:
                slots.append(int(m.jnt_qposadr[j]))
        return slots

    def image_motion(self, a: SceneState, b: SceneState) -> float:
        """The largest image motion (pixels) from state `a` to `b` of what the camera sees:
        every geom's centre and the ground along the lower image, each through the camera
        as it was then. Leaves the scene at `b`."""
        cam, cid, data = self.camera, self.robot.camera_id, self.data
        seen = []
        for state in (a, b):
            self.blend(state, state, 1.0)
            seen.append((data.cam_xpos[cid].copy(), data.cam_xmat[cid].reshape(3, 3).copy(),
                         data.geom_xpos.copy()))  # fmt: skip
        ground = _ground_probes(cam, seen[1][0], seen[1][1])
        (uv_a, ok_a), (uv_b, ok_b) = (
            _pixels(cam, pos, mat, np.vstack([geoms, ground])) for pos, mat, geoms in seen
        )
        ok = ok_a & ok_b
        return float(np.max(np.linalg.norm(uv_b[ok] - uv_a[ok], axis=1))) if ok.any() else 0.0

    def world_to_robot(self, points_world: np.ndarray) -> np.ndarray:
        """World points (..., 3) in the robot frame of monopic.camera."""
        return self.robot_pose.to_local(points_world)

    def project(self, points_world: np.ndarray) -> np.ndarray:
        """World points (..., 3) to pixels through the camera model."""
        return self.camera.project(self.world_to_robot(points_world))
