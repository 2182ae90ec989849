"""A pedestrian: the mannequin MuJoCo draws, the walk highway-env carries, the person's truth.

The walk is a highway-env road object following the scenario path (sim.world.pedestrian);
the body is the mannequin (sim.world.mannequin) posed by the gait (sim.world.gait) where the
walk is. Without a walk (a still scene: dataset clips, tests) the body is posed directly
with `pose_at`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np
from highway_env.road.road import Road

from monopic.camera import CameraModel
from sim.geometry.frames import Pose2D, wrap_angle
from sim.geometry.polygons import rectangle
from sim.scenario.path import person_seed
from sim.scenario.spec import MannequinSpec, PedestrianSpec
from sim.scenario.track import Track
from sim.world.body import PedestrianTruth, make_truth
from sim.world.entities.base import Entity, Moment, Sight
from sim.world.gait import Gait, MannequinPose
from sim.world.ground_truth import (
    CASE_WINDOW,
    SIGHT_SAMPLES,
    TORSO_LANDMARKS,
    PersonTruth,
    case_label,
    facing_angles,
    head_yaws,
    in_image,
    occluded_landmarks,
    polygons_intersect,
    time_to_contact,
    visibility,
)
from sim.world.intent import intent_label
from sim.world.mannequin import GeomShapes, Mannequin, build_mannequin
from sim.world.pedestrian import Pedestrian


class PedestrianBody(Entity):
    """One person: `looks` for the mannequin; `walk` (the scenario's pedestrian) and
    `t_end` (how far ahead the walk is worked out) for a run."""

    kind = "person"

    def __init__(
        self,
        looks: MannequinSpec,
        walk: PedestrianSpec | None = None,
        *,
        name: str = "ped",
        t_end: float = 30.0,
        scripted: bool = True,
    ) -> None:
        self.name = name
        self.looks = looks
        self.walk = walk
        self.t_end = t_end
        self.scripted = scripted  # the person the run's warnings are judged against
        # A walk worked out with others (a crowd's member: follow), else None: their own.
        self.given_path: Track | None = None
        self.gait = Gait(height=looks.height)
        self.walker: Pedestrian | None = None
        # Where the body was last stood (the truth's placement, gait phase and speed).
        self.placement = Pose2D(5.0, 0.0, math.pi)
        self.gait_phase = 0.0
        self.speed = 0.0

    # -- MJCF -------------------------------------------------------------------------

    def build(self, spec: mujoco.MjSpec) -> None:
        build_mannequin(spec, self.looks, self.prefix)

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self.mannequin = Mannequin(model, self.looks, self.prefix)
        # A coarser sample of the surface than the apparent box's, for what is hidden.
        self.sight_shapes = GeomShapes.of(model, self.mannequin.geom_ids, n=SIGHT_SAMPLES)

    def geom_ids(self, model: mujoco.MjModel) -> np.ndarray:
        return self.mannequin.geom_ids

    # -- motion -----------------------------------------------------------------------

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        """The walk from its start; its rng draws the gait phase, and the run's seed a human
        walker's wander: the scripted person's from the seed itself (as with one person),
        each other person's from the seed and their name, so no two wander alike."""
        if self.walk is None:
            raise RuntimeError(f"pedestrian {self.name!r} has no walk to start")
        seed = person_seed(seed, self.name, self.scripted)
        self.walker = Pedestrian(
            road, self.walk, self.gait, t_end=self.t_end, seed=seed, path=self.given_path
        )
        self.walker.reset(gait_phase=float(rng.uniform()))
        road.objects.append(self.walker)

    def follow(self, path: Track) -> None:
        """Walk `path` from the next reset on (a crowd's member: the crowd model moves
        everyone together, sim.world.entities.crowd)."""
        self.given_path = path

    def before_step(self, dt: float) -> None:
        assert self.walker is not None
        self.walker.step(dt)

    # -- MuJoCo -----------------------------------------------------------------------

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        """Where the walk is now; a body without a walk stays where it was stood."""
        if self.walker is None:
            return
        state = self.walker.state
        self.pose_at(
            model,
            data,
            state.position[0],
            state.position[1],
            state.yaw,
            self.walker.gait_phase,
            state.speed,
            sway=self.walker.body_sways,
            head_yaw=state.head_yaw,
            torso_yaw=state.torso_yaw,
        )

    def pose_at(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
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
        """Stand the person at world (x, y) facing `yaw`.

        The body pose comes from the gait at `gait_phase` and `speed` (idle stance when
        the speed is about zero) unless `pose` is given. Advance the phase between
        frames with `self.gait.advance(phase, speed, dt)`. `sway` False: the placement
        itself sways (a human walker's track), so the pelvis does not sway again.
        `torso_yaw` turns the shoulders from the walking direction and `head_yaw` the head
        from the shoulders (radians, + to the left): a human walker's intent cues.
        """
        self.placement = Pose2D(float(x), float(y), float(yaw))
        self.gait_phase, self.speed = float(gait_phase), float(speed)
        body_pose = pose if pose is not None else self.gait.pose(gait_phase, speed)
        if not sway:
            body_pose = replace(body_pose, sway=0.0)
        if head_yaw or torso_yaw:
            body_pose = replace(
                body_pose,
                waist_yaw=body_pose.waist_yaw + torso_yaw,
                neck_yaw=body_pose.neck_yaw + head_yaw,
            )
        self.mannequin.place(model, data, x, y, yaw, body_pose)

    # -- truth ------------------------------------------------------------------------

    def seen(self, data: mujoco.MjData, camera: CameraModel, robot: Pose2D) -> PedestrianTruth:
        """The posed body in the world and through `camera` on the robot at `robot`."""
        return make_truth(
            camera=camera,
            robot=robot,
            placement=self.placement,
            speed=self.speed,
            gait_phase=self.gait_phase,
            landmarks_world=self.mannequin.landmarks(data),
            foot_world=self.mannequin.foot_point(data),
            surface_world=self.mannequin.surface_points(data),
            top_z=self.mannequin.top_height(data),
        )

    def truth(self, model: mujoco.MjModel, data: mujoco.MjData, sight: Sight) -> PersonTruth:
        """Everything true about this person now (sim.world.ground_truth says how each
        figure is defined)."""
        walker = self.walker
        assert walker is not None
        robot, camera, now = sight.robot, sight.camera, sight.time
        pose = robot.pose
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)

        def axes(v: np.ndarray) -> np.ndarray:  # world vector -> robot axes
            return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])

        def local(p: np.ndarray) -> np.ndarray:  # world point -> robot frame
            return pose.to_local(np.array([p[0], p[1], 0.0]))[:2]

        ped = walker.state
        path = walker.path
        robot_velocity = robot.speed * np.array([c, s])
        ahead = path.state(now + CASE_WINDOW).position
        case, case_velocity = case_label((ahead - ped.position) / CASE_WINDOW, pose.yaw)
        future = path.state(now + sight.horizon).position
        intent = intent_label(path, now, pose, sight.horizon)

        contact = polygons_intersect(sight.robot_polygon, walker.polygon())
        ttc = time_to_contact(
            sight.robot_polygon, sight.robot_velocity, walker, now, sight.lookahead
        )

        body = self.seen(data, camera, pose)
        centre_px = camera.project(body.landmarks_robot[list(TORSO_LANDMARKS)].mean(axis=0))
        hidden = occluded_landmarks(
            model, data, sight.camera_world, body.landmarks_world, self.mannequin.geom_ids
        )
        visible = in_image(camera, body.landmarks_px) & ~hidden
        # The shoulders face the walking direction turned by the walker's cue (if any).
        shoulders = ped.yaw + ped.torso_yaw
        facing, facing_view, beta, phi = facing_angles(pose, camera, ped.position, shoulders)
        head_from_shoulders, head_from_camera = head_yaws(body.landmarks_world, sight.camera_world)
        seen = visibility(
            model, data, camera, pose, sight.camera_world,
            self.sight_shapes.surface_points(data), self.mannequin.geom_ids, sight.geom_kind,
        )  # fmt: skip
        size = self.walk.footprint if self.walk is not None else math.nan
        footprint = rectangle(ped.position, ped.footprint_yaw, size, size)
        return PersonTruth(
            name=self.name,
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
            horizon=sight.horizon,
            future_position_world=future,
            future_position_robot=local(future),
            contact=contact,
            collision=ttc is not None and ttc <= sight.horizon,
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
            footprint_world=footprint,
            visibility=seen,
        )
