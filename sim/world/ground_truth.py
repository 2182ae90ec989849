"""Ground truth per frame: what the simulator knows that the pipeline must find out.

Each entity tells its own (sim.world.entities: the robot its RobotState, each pedestrian
a PersonTruth from highway-env's objects and its posed mannequin) and World composes them
into the frame's GroundTruth. Conventions:

- world frame as in sim.geometry.frames; robot frame as in monopic.camera (x forward, y left),
  taken at this frame's robot pose;
- velocities are the pedestrian's own motion over the ground (not relative to the robot)
  unless named `relative_`;
- the case is monopic.cases.case_from_ground_velocity of the pedestrian's mean own
  velocity over the next CASE_WINDOW seconds of its true path, in the robot's axes now;
  `case_now` the same of the own velocity now; the intent class (keep going, stop, turn
  away, start crossing) is what the true path does within the horizon against the
  robot's path (sim.world.intent);
- collision: the robot keeps its course (constant speed and heading) while the pedestrian
  follows its true path; both footprints are highway-env polygons (RoadObject.polygon)
  and "meet" means highway-env's separating-axis test (utils.are_polygons_intersecting)
  says they intersect. Between the path's breakpoints both move in straight lines, so
  the first contact time follows exactly from the same axes (see `contact_window`);
- occlusion: a MuJoCo ray from the camera to each landmark (mj_ray over the geoms the
  camera draws): a landmark is hidden when something other than the mannequin is hit
  first. `occluded` means more than half of the landmarks are hidden. This needs no
  rendering, so it is available in ground-truth-only runs.
- facing: `facing_yaw_view` is the pedestrian's heading relative to the line of sight
  from the camera (0: back to the camera, +-pi: facing it, +pi/2: walking to the
  camera's left); the shoulder line then leaves the image plane by
  beta = asin(sin(facing_yaw_view)) and the paper's phi it implies is 2 * beta in
  degrees (monopic/features/orientation.py): 0 square to the camera, +180 in left
  profile, -180 in right profile.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import mujoco
import numpy as np
from highway_env import utils

from monopic.camera import CameraModel
from monopic.cases import Case, case_from_ground_velocity
from sim.geometry.frames import Pose2D, wrap_angle
from sim.geometry.polygons import polygon_gap, rectangle
from sim.sensor.exposure import ExposureState
from sim.world.body import PedestrianTruth
from sim.world.intent import Intent
from sim.world.pedestrian import Pedestrian

CASE_WINDOW = 1.0  # s of future motion that defines the ground-truth case
OCCLUSION_TOLERANCE = 0.02  # m: a hit this close before the landmark does not hide it
TORSO_LANDMARKS = (11, 12, 23, 24)  # shoulders and hips: their mean is the body centre
VISIBLE_GEOM_GROUPS = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8)  # what the camera draws


@dataclass(frozen=True)
class RobotState:
    """The robot's own state at one frame (what it knows about itself, plus its pose)."""

    time: float
    position: np.ndarray  # (2,) world x, y of the reference point
    yaw: float  # rad, CCW from east
    speed: float  # m/s
    acceleration: float  # m/s^2 applied over the last step (after clipping)
    yaw_rate: float  # rad/s
    length: float
    width: float

    @property
    def pose(self) -> Pose2D:
        return Pose2D(float(self.position[0]), float(self.position[1]), self.yaw)

    def to_dict(self) -> dict[str, object]:
        return {
            "time": self.time,
            "x": float(self.position[0]),
            "y": float(self.position[1]),
            "yaw": self.yaw,
            "speed": self.speed,
            "acceleration": self.acceleration,
            "yaw_rate": self.yaw_rate,
            "length": self.length,
            "width": self.width,
        }


# What hides part of a body from the camera, by the kind of body that owns the geom the
# line of sight meets first (Entity.kind); "scene": the street, its buildings, any other.
HIDERS = ("person", "parked car", "scene")
SIGHT_SAMPLES = 12  # points a body geom contributes to the visibility estimate


@dataclass(frozen=True)
class Visibility:
    """How much of a body's surface the camera sees, from points sampled on it (its share
    hidden by each kind of body, and outside the image), and the box of what it sees.

    Shares are of the sampled points (SIGHT_SAMPLES on each geom of the body, evenly over
    directions), so a small far body is judged as finely as a near one; they sum to 1 with
    `visible`. A point behind the body's own front is not counted as hidden: the body
    hiding itself is what every view of a person does, not occlusion."""

    visible: float
    hidden_by: dict[str, float]  # HIDERS -> share
    outside_frame: float
    box: tuple[float, float, float, float]  # px (u0, v0, u1, v1) of the visible points; NaN

    @property
    def hidden(self) -> float:
        return float(sum(self.hidden_by.values()))

    def to_dict(self) -> dict[str, object]:
        return {
            "visible": self.visible,
            "hidden_by": dict(self.hidden_by),
            "outside_frame": self.outside_frame,
            "box": _plain(np.array(self.box)),
        }


HIDDEN_GROUP = 5  # a geom group no ray test here sees (first_hits parks the others in it)


def first_hits(
    model: mujoco.MjModel, data: mujoco.MjData, origin: np.ndarray, points: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The first geom the camera draws on each line from `origin` to a point, and how far
    along it (-1 and -1: none): one mj_multiRay.

    MuJoCo tests every ray against every geom, so with many people the cost grows with the
    square of the crowd. Only geoms whose bounding sphere reaches into the cone around the
    lines (and no farther than the farthest point) can be hit; the others are moved to a
    group the test does not see for the call and put back after, so the answer is the one
    the whole scene gives (bench.simulator's people rows measure it)."""
    origin = np.asarray(origin, dtype=float)
    rays = np.asarray(points, dtype=float) - origin
    n = len(rays)
    hit_geom = np.full(n, -1, dtype=np.int32)
    hit_dist = np.full(n, -1.0)
    if n == 0:
        return hit_geom, hit_dist
    dist = np.linalg.norm(rays, axis=1)
    unit = rays / np.maximum(dist, 1e-9)[:, None]
    axis = unit.mean(axis=0)
    axis /= max(float(np.linalg.norm(axis)), 1e-12)
    spread = float(np.arccos(np.clip(unit @ axis, -1.0, 1.0)).max())
    centres = data.geom_xpos - origin
    reach = np.linalg.norm(centres, axis=1)
    radius = model.geom_rbound
    inside = reach <= radius
    sphere = np.arcsin(np.clip(radius / np.maximum(reach, 1e-12), 0.0, 1.0))
    off_axis = np.arccos(np.clip((centres @ axis) / np.maximum(reach, 1e-12), -1.0, 1.0))
    near = off_axis <= spread + sphere + 1e-6
    candidate = (radius <= 0) | inside | (near & (reach - radius <= float(dist.max()) + 1e-6))
    groups = model.geom_group.copy()
    try:
        model.geom_group[~candidate] = HIDDEN_GROUP
        mujoco.mj_multiRay(
            model, data, origin, unit.reshape(-1), VISIBLE_GEOM_GROUPS, 1, -1, hit_geom,
            hit_dist, None, n, float(dist.max()) + 1.0,
        )  # fmt: skip
    finally:
        model.geom_group[:] = groups
    return hit_geom, hit_dist


def visibility(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    camera: CameraModel,
    robot: Pose2D,
    camera_world: np.ndarray,
    points_world: np.ndarray,
    own_geoms: np.ndarray,
    geom_kind: np.ndarray,
) -> Visibility:
    """The Visibility of a body whose surface points are `points_world` (N, 3).

    One MuJoCo ray per point from the camera (first_hits, over the geoms the camera
    draws); the first geom hit decides: another body's (by its kind, `geom_kind[geom]`
    an index into HIDERS), or the body's own or nothing (seen, if inside the image)."""
    px = camera.project(robot.to_local(points_world))
    with np.errstate(invalid="ignore"):
        inside = in_image(camera, px)
    dist = np.linalg.norm(np.asarray(points_world, dtype=float) - camera_world, axis=1)
    hit_geom, hit_dist = first_hits(model, data, camera_world, points_world)
    blocked = (hit_dist >= 0) & (hit_dist < dist - OCCLUSION_TOLERANCE)
    blocked &= ~np.isin(hit_geom, own_geoms)
    kinds = np.where(blocked, geom_kind[np.clip(hit_geom, 0, None)], -1)
    shares = {name: float(np.mean(inside & (kinds == k))) for k, name in enumerate(HIDERS)}
    seen = inside & ~blocked
    box = (math.nan,) * 4
    if seen.any():
        (u0, v0), (u1, v1) = px[seen].min(axis=0), px[seen].max(axis=0)
        box = (float(u0), float(v0), float(u1), float(v1))
    return Visibility(float(seen.mean()), shares, float(1.0 - inside.mean()), box)


@dataclass(frozen=True)
class PersonTruth:
    """Everything true about one pedestrian at one frame (PedestrianBody.truth)."""

    name: str  # the pedestrian's entity name ("ped" for a scenario's one pedestrian)
    # The pedestrian on its path (the footprint's centre), world frame.
    position_world: np.ndarray  # (2,)
    velocity_world: np.ndarray  # (2,)
    heading_world: float  # rad, CCW from east
    speed: float
    # The same in the robot frame now (x forward, y left); velocity is own ground motion.
    position_robot: np.ndarray  # (2,)
    velocity_robot: np.ndarray  # (2,)
    relative_velocity_robot: np.ndarray  # (2,) pedestrian minus robot velocity
    heading_robot: float  # rad, relative to the robot's heading
    # The next CASE_WINDOW seconds and the horizon.
    case: Case
    case_velocity_robot: np.ndarray  # (2,) mean own velocity over the case window
    case_now: Case  # the case of the own velocity now
    intent: Intent  # what the true path does within the horizon (sim.world.intent)
    intent_time: float | None  # s from now until it does it; None for keep going
    horizon: float
    future_position_world: np.ndarray  # (2,) where the path is at time + horizon
    future_position_robot: np.ndarray  # (2,) that point in the robot frame now
    # Collision (footprints, robot keeping its course).
    contact: bool  # footprints intersect now
    collision: bool  # they meet within the horizon (contact now included)
    time_to_collision: float | None  # s to the first contact, None if none in the lookahead
    # Image.
    body: PedestrianTruth  # landmarks world/robot/px, foot point, box, in_frame
    centre_px: np.ndarray  # (2,) projection of the torso centre
    landmarks_occluded: np.ndarray  # (33,) bool: line of sight blocked by another object
    visible_fraction: float  # landmarks inside the image and not occluded
    occluded: bool
    # Facing.
    facing_yaw: float  # rad, heading relative to the camera's optical axis
    facing_yaw_view: float  # rad, heading relative to the line of sight
    beta: float  # rad, shoulder line out of the image plane, in [-pi/2, pi/2]
    phi: float  # deg, the paper's facing angle this implies (2 * beta)
    # Where the head looks (from the posed mannequin: nose ahead of the ears' midpoint).
    head_yaw_shoulders: float = 0.0  # rad, head turned from the shoulders' facing (+ left)
    head_yaw_camera: float = math.nan  # rad, head facing from the line to the camera (0: at it)
    # The square the person occupies on the ground: corners (4, 2), world frame.
    footprint_world: np.ndarray = field(default_factory=lambda: np.full((4, 2), np.nan))
    # How much of the body the camera sees (sim.world.ground_truth.Visibility).
    visibility: Visibility | None = None

    @property
    def landmarks_px(self) -> np.ndarray:
        return self.body.landmarks_px

    @property
    def foot_px(self) -> np.ndarray:
        return self.body.foot_px

    @property
    def box(self) -> tuple[float, float, float, float]:
        return self.body.box

    @property
    def in_frame(self) -> bool:
        return self.body.in_frame

    @property
    def apparent_height(self) -> float:
        """True apparent height of the whole body in pixels (ignoring occlusion)."""
        return self.body.box_height

    def to_dict(self, full: bool = False) -> dict[str, object]:
        """Plain JSON-ready values (NaN as None); `full` adds the name, the footprint and
        the visibility (what a person among several is told by)."""
        extra: dict[str, object] = {}
        if full:
            extra = {
                "name": self.name,
                "footprint_world": _plain(self.footprint_world),
                "visibility": None if self.visibility is None else self.visibility.to_dict(),
            }
        return {
            **extra,
            "position_world": _plain(self.position_world),
            "velocity_world": _plain(self.velocity_world),
            "heading_world": self.heading_world,
            "speed": self.speed,
            "position_robot": _plain(self.position_robot),
            "velocity_robot": _plain(self.velocity_robot),
            "relative_velocity_robot": _plain(self.relative_velocity_robot),
            "heading_robot": self.heading_robot,
            "case": int(self.case),
            "case_velocity_robot": _plain(self.case_velocity_robot),
            "case_now": int(self.case_now),
            "intent": self.intent.value,
            "intent_time": self.intent_time,
            "horizon": self.horizon,
            "future_position_world": _plain(self.future_position_world),
            "future_position_robot": _plain(self.future_position_robot),
            "contact": bool(self.contact),
            "collision": bool(self.collision),
            "time_to_collision": self.time_to_collision,
            "landmarks_px": _plain(self.body.landmarks_px),
            "foot_px": _plain(self.body.foot_px),
            "centre_px": _plain(self.centre_px),
            "box": _plain(np.array(self.body.box)),
            "in_frame": bool(self.body.in_frame),
            "apparent_height": _plain(np.array(self.apparent_height)),
            "landmarks_occluded": [bool(v) for v in self.landmarks_occluded],
            "visible_fraction": self.visible_fraction,
            "occluded": bool(self.occluded),
            "facing_yaw": self.facing_yaw,
            "facing_yaw_view": self.facing_yaw_view,
            "beta": self.beta,
            "phi": self.phi,
            "head_yaw_shoulders": self.head_yaw_shoulders,
            "head_yaw_camera": self.head_yaw_camera,
        }


@dataclass(frozen=True)
class GroundTruth:
    """Everything true at one frame: the robot's, each pedestrian's and every other body's
    truth, each told by its own entity (sim.world.entities)."""

    time: float
    index: int
    robot: RobotState
    people: tuple[PersonTruth, ...]  # the scenario's pedestrian first
    # The other bodies' truth by entity name (a parked car, a test's toy); None: nothing.
    bodies: Mapping[str, object] = field(default_factory=dict)
    # A real camera's exposure of this frame (sim.sensor); None: the ideal camera.
    camera: ExposureState | None = None

    @property
    def pedestrian(self) -> PersonTruth:
        """The scenario's pedestrian (the one its warnings are judged against)."""
        return self.people[0]

    def to_dict(self) -> dict[str, object]:
        """Plain JSON-ready values (NaN as None), e.g. for gym infos and dataset lines: the
        robot and the scripted pedestrian at the top level (as with one person), and with
        several people `people`, each person's in the scene's order."""
        out = {
            "time": self.time,
            "index": self.index,
            "robot": self.robot.to_dict(),
            **self.pedestrian.to_dict(),
        }
        if len(self.people) > 1:
            out["people"] = [p.to_dict(full=True) for p in self.people]
        if self.camera is not None:
            out["camera"] = self.camera.to_dict()
        return out


def _plain(values: np.ndarray) -> object:
    """Nested lists of floats with None for non-finite values."""
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0:
        return float(arr) if math.isfinite(float(arr)) else None
    return [_plain(v) for v in arr]


def contact_window(
    poly_a: np.ndarray,
    vel_a: np.ndarray,
    poly_b: np.ndarray,
    vel_b: np.ndarray,
    t_max: float,
) -> tuple[float, float] | None:
    """Times in [0, t_max] when two convex polygons moving at constant velocities overlap.

    Polygons are closed point lists as RoadObject.polygon() returns them. This is
    highway-env's separating-axis test (the edge normals of both polygons, projections by
    utils.project_polygon, touching counts as intersecting) solved for time: along each
    axis the projections overlap during one interval of t; the polygons overlap when all
    axes do. None when they never overlap in [0, t_max].
    """
    lo, hi = 0.0, float(t_max)
    rel = np.asarray(vel_a, dtype=float) - np.asarray(vel_b, dtype=float)
    for polygon in (poly_a, poly_b):
        for p1, p2 in zip(polygon, polygon[1:], strict=False):
            normal = np.array([-p2[1] + p1[1], p2[0] - p1[0]])
            normal /= np.linalg.norm(normal)
            min_a, max_a = utils.project_polygon(poly_a, normal)
            min_b, max_b = utils.project_polygon(poly_b, normal)
            r = float(normal @ rel)
            # Overlap on this axis: min_b - max_a <= r t <= max_b - min_a.
            if abs(r) < 1e-12:
                if min_b - max_a > 0 or max_b - min_a < 0:
                    return None
                continue
            t0, t1 = (min_b - max_a) / r, (max_b - min_a) / r
            if r < 0:
                t0, t1 = t1, t0
            lo, hi = max(lo, t0), min(hi, t1)
            if lo > hi:
                return None
    return lo, hi


def time_to_contact(
    robot_polygon: np.ndarray,
    robot_velocity: np.ndarray,
    pedestrian: Pedestrian,
    now: float,
    lookahead: float,
) -> float | None:
    """Seconds from `now` until the footprints first meet, None if not within `lookahead`.

    The robot's footprint translates at `robot_velocity` (it keeps its course); the
    pedestrian follows its Track, one straight piece at a time. Everything is in
    highway-env's frame, which only mirrors the world, so distances and contacts agree.
    Pieces whose footprints cannot come within reach (their centres farther apart than
    both footprints' circumradii plus what the piece moves them) are skipped before the
    exact separating-axis test: a human walker has a piece every 10 ms.
    """
    track = pedestrian.path
    cuts = np.array([now, *track.breakpoints_between(now, now + lookahead), now + lookahead])
    starts, lengths = cuts[:-1], np.diff(cuts)
    # Centres at each piece's start, in highway-env's frame (y mirrored), and the pieces'
    # relative velocities.
    ped = track.positions_at(starts) * np.array([1.0, -1.0])
    ped_velocity = track.velocities[np.searchsorted(track.times, starts, side="right") - 1]
    ped_velocity = ped_velocity * np.array([1.0, -1.0])
    robot_centre = robot_polygon[:-1].mean(axis=0)
    robot_at = robot_centre + (starts - now)[:, None] * np.asarray(robot_velocity)
    reach = (
        np.max(np.linalg.norm(robot_polygon[:-1] - robot_centre, axis=1))
        + pedestrian.diagonal / 2
        + 1e-6
    )
    gap = np.linalg.norm(ped - robot_at, axis=1)
    drift = np.linalg.norm(ped_velocity - np.asarray(robot_velocity), axis=1) * lengths
    for k in np.flatnonzero(gap - drift <= reach):
        t0 = float(starts[k])
        offset = t0 - now
        window = contact_window(
            robot_polygon + offset * robot_velocity,
            robot_velocity,
            pedestrian.polygon_at(t0),
            pedestrian.highway_velocity_at(t0),
            float(lengths[k]),
        )
        if window is not None:
            return offset + window[0]
    return None


def polygons_intersect(poly_a: np.ndarray, poly_b: np.ndarray) -> bool:
    """highway-env's static intersection test of two footprints."""
    zero = np.zeros(2)
    return bool(utils.are_polygons_intersecting(poly_a, poly_b, zero, zero)[0])


def occluded_landmarks(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    camera_world: np.ndarray,
    points_world: np.ndarray,
    own_geoms: np.ndarray,
) -> np.ndarray:
    """Per point: is the line of sight from the camera blocked by a geom not in own_geoms?"""
    own = set(int(g) for g in own_geoms)
    hidden = np.zeros(len(points_world), dtype=bool)
    geom_id = np.zeros(1, dtype=np.int32)
    origin = np.asarray(camera_world, dtype=float)
    for k, point in enumerate(np.asarray(points_world, dtype=float)):
        ray = point - origin
        dist = float(np.linalg.norm(ray))
        if dist < 1e-9:
            continue
        hit = mujoco.mj_ray(model, data, origin, ray / dist, VISIBLE_GEOM_GROUPS, 1, -1, geom_id)
        if 0 <= hit < dist - OCCLUSION_TOLERANCE and int(geom_id[0]) not in own:
            hidden[k] = True
    return hidden


def facing_angles(
    robot: Pose2D, camera: CameraModel, position: np.ndarray, heading: float
) -> tuple[float, float, float, float]:
    """(facing_yaw, facing_yaw_view, beta, phi_deg) of a pedestrian seen by the camera."""
    cam = robot.to_world(camera.position)
    bearing = math.atan2(position[1] - cam[1], position[0] - cam[0])
    facing = wrap_angle(heading - robot.yaw)
    facing_view = wrap_angle(heading - bearing)
    beta = math.asin(max(-1.0, min(1.0, math.sin(facing_view))))
    return facing, facing_view, beta, 2.0 * math.degrees(beta)


def in_image(camera: CameraModel, px: np.ndarray) -> np.ndarray:
    """Per pixel (N, 2): finite and inside the image."""
    u, v = px[:, 0], px[:, 1]
    with np.errstate(invalid="ignore"):
        return (
            np.isfinite(u)
            & np.isfinite(v)
            & (u >= 0)
            & (v >= 0)
            & (u < camera.width)
            & (v < camera.height)
        )


def case_label(velocity_world: np.ndarray, robot_yaw: float) -> tuple[Case, np.ndarray]:
    """The case of a world ground velocity seen in the robot's axes, and that velocity."""
    c, s = math.cos(robot_yaw), math.sin(robot_yaw)
    vx, vy = float(velocity_world[0]), float(velocity_world[1])
    forward, left = c * vx + s * vy, -s * vx + c * vy
    return case_from_ground_velocity(forward, left), np.array([forward, left])


def footprints(truth: GroundTruth, pedestrian_size: float) -> tuple[np.ndarray, np.ndarray]:
    """The robot's and the pedestrian's footprints (world frame) at one frame."""
    r, p = truth.robot, truth.pedestrian
    robot = rectangle(r.position, r.yaw, r.length, r.width)
    ped = rectangle(p.position_world, p.heading_world, pedestrian_size, pedestrian_size)
    return robot, ped


def footprint_gap(truth: GroundTruth, pedestrian_size: float) -> float:
    """Metres between the robot's and the pedestrian's footprints (0 in contact)."""
    return polygon_gap(*footprints(truth, pedestrian_size))


def pedestrian_passed(truth: GroundTruth, robot_length: float, footprint: float) -> bool:
    """The pedestrian is behind the robot, clear of it: nothing more can happen in this run."""
    clearance = robot_length / 2 + footprint
    return bool(truth.pedestrian.position_robot[0] < -clearance)


NOSE, LEFT_EAR, RIGHT_EAR, LEFT_SHOULDER, RIGHT_SHOULDER = 0, 7, 8, 11, 12


def head_yaws(landmarks_world: np.ndarray, camera_world: np.ndarray) -> tuple[float, float]:
    """(head from the shoulders, head from the line to the camera), radians, + to the left.

    The head faces from the ears' midpoint to the nose; the shoulders face square to the
    line from the right shoulder to the left one. Both on the ground plane.
    """
    ears = (landmarks_world[LEFT_EAR, :2] + landmarks_world[RIGHT_EAR, :2]) / 2
    head = landmarks_world[NOSE, :2] - ears
    across = landmarks_world[LEFT_SHOULDER, :2] - landmarks_world[RIGHT_SHOULDER, :2]
    head_yaw = math.atan2(head[1], head[0])
    shoulders_yaw = math.atan2(-across[0], across[1])  # rotate right-to-left by -90 deg
    to_camera = camera_world[:2] - ears
    return (
        wrap_angle(head_yaw - shoulders_yaw),
        wrap_angle(head_yaw - math.atan2(to_camera[1], to_camera[0])),
    )
