"""Ground truth of the pedestrian for one frame: where the body is, in the world and in the image.

Image positions come from monopic's CameraModel applied to the robot-frame positions, not
from the renderer, so the truth says where the camera model (what the pipeline knows)
puts each point; the projection test in tests/test_scene.py shows the renderer agrees
within a pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monopic.camera import CameraModel
from sim.geometry.frames import Pose2D


@dataclass(frozen=True)
class PedestrianTruth:
    """The pedestrian as the simulator knows it at one instant.

    Arrays: landmarks in BlazePose order (index = MediaPipe's landmark number, left/right
    the person's own); `_world` in the world frame, `_robot` in the robot frame of
    monopic.camera, `_px` image pixels (u right, v down; NaN behind the camera).
    `box` is the apparent box (u_min, v_min, u_max, v_max) of the whole body ignoring
    occlusion and the image border; `in_frame` says whether it overlaps the image.
    """

    position: np.ndarray  # world (x, y) of the mannequin's placement point
    yaw: float  # heading the person faces, rad CCW from east
    speed: float  # m/s along the heading
    gait_phase: float
    landmarks_world: np.ndarray  # (33, 3)
    landmarks_robot: np.ndarray  # (33, 3)
    landmarks_px: np.ndarray  # (33, 2)
    foot_world: np.ndarray  # (3,) midpoint between the feet, on the ground
    foot_robot: np.ndarray  # (3,)
    foot_px: np.ndarray  # (2,)
    box: tuple[float, float, float, float]
    in_frame: bool
    top_z: float  # highest point of the body above the ground, m

    @property
    def box_height(self) -> float:
        """Apparent height of the body in pixels."""
        return self.box[3] - self.box[1]


def image_box(
    camera: CameraModel, points_robot: np.ndarray
) -> tuple[tuple[float, float, float, float], bool]:
    """Apparent box of robot-frame surface points and whether it overlaps the image."""
    px = camera.project(points_robot)
    px = px[np.all(np.isfinite(px), axis=1)]
    if len(px) == 0:
        nan = float("nan")
        return (nan, nan, nan, nan), False
    u0, v0 = px.min(axis=0)
    u1, v1 = px.max(axis=0)
    overlaps = u1 > 0 and v1 > 0 and u0 < camera.width and v0 < camera.height
    return (float(u0), float(v0), float(u1), float(v1)), bool(overlaps)


def make_truth(
    camera: CameraModel,
    robot: Pose2D,
    placement: Pose2D,
    speed: float,
    gait_phase: float,
    landmarks_world: np.ndarray,
    foot_world: np.ndarray,
    surface_world: np.ndarray,
    top_z: float,
) -> PedestrianTruth:
    """Assemble the truth record from world-frame measurements of the posed mannequin."""
    lm_robot = robot.to_local(landmarks_world)
    foot_robot = robot.to_local(foot_world)
    box, in_frame = image_box(camera, robot.to_local(surface_world))
    return PedestrianTruth(
        position=np.array([placement.x, placement.y]),
        yaw=placement.yaw,
        speed=speed,
        gait_phase=gait_phase,
        landmarks_world=landmarks_world,
        landmarks_robot=lm_robot,
        landmarks_px=camera.project(lm_robot),
        foot_world=foot_world,
        foot_robot=foot_robot,
        foot_px=camera.project(foot_robot),
        box=box,
        in_frame=in_frame,
        top_z=top_z,
    )
