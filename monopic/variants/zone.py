"""The zone the robot will occupy within the horizon, on the ground and on the image.

The robot is a rectangle (width x length) whose front edge is `front` metres ahead of its
reference point (the robot frame's origin). Over the horizon it sweeps forward at its own
speed (and turns at its yaw rate); a pedestrian on that swept area is in its way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from monopic.camera import CameraModel

PEDESTRIAN_RADIUS = 0.3  # m: the disc a pedestrian is taken to be when meeting the robot


@dataclass(frozen=True)
class RobotGeometry:
    """Footprint of the camera-carrying robot, metres."""

    width: float = 0.6
    length: float = 0.8
    front: float = 0.4  # front edge ahead of the reference point
    margin: float = 0.2  # safety margin added on each side of the swept zone
    min_reach: float = 1.0  # the zone reaches at least this far ahead, even when standing

    def __post_init__(self) -> None:
        for name in ("width", "length"):
            if not getattr(self, name) > 0:
                raise ValueError(f"robot {name} must be positive, got {getattr(self, name)}")


def swept_ground_zone(robot: RobotGeometry, speed: float, horizon: float) -> np.ndarray:
    """Ground polygon (4, 2) ahead of the robot it can reach within the horizon (straight)."""
    reach = max(speed * horizon, robot.min_reach)
    half = robot.width / 2 + robot.margin
    x0, x1 = robot.front, robot.front + reach
    return np.array([[x0, half], [x1, half], [x1, -half], [x0, -half]])


def image_zone(
    camera: CameraModel, robot: RobotGeometry, speed: float, horizon: float
) -> np.ndarray:
    """The swept ground zone projected on the image (polygon, pixels).

    Parts of the zone behind the camera's near clipping distance are cut off first, so the
    polygon is always finite.
    """
    zone = swept_ground_zone(robot, speed, horizon)
    near = camera.mount_forward + 0.05
    zone[:, 0] = np.maximum(zone[:, 0], near)
    pts = camera.project(np.column_stack([zone, np.zeros(len(zone))]))
    return pts


def default_image_zone(width: int, height: int) -> np.ndarray:
    """Fixed zone for a camera with unknown geometry, like the authors' static overlay.

    A trapezoid on the lower part of the frame, centred, as wide as the middle third at
    its top: where the path of a forward-looking robot appears.
    """
    return np.array(
        [
            [width * 0.35, height * 0.55],
            [width * 0.65, height * 0.55],
            [width * 0.85, height * 1.0],
            [width * 0.15, height * 1.0],
        ]
    )


def points_in_polygon(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Even-odd rule for (N, 2) points at once; False for non-finite points.

    Plain Python floats: the zones have 4 corners and a path 16 points, and on arrays that
    small numpy's per-call overhead was most of the time (8 against 28 us for a path, 2.5
    for one point: `bench/post_pose.py`). The crossing test is the vectorised one's, operation for
    operation, so the answers are the same (tests/monopic/test_after_pose_exact.py).
    """
    corners = np.asarray(polygon, dtype=float).tolist()
    edges = []  # (x1, y1, x2 - x1, y2 - y1, y2) from each corner to the next
    for k, (x1, y1) in enumerate(corners):
        x2, y2 = corners[(k + 1) % len(corners)]
        edges.append((x1, y1, x2 - x1, y2 - y1, y2))
    inside = []
    for x, y in np.asarray(points, dtype=float).reshape(-1, 2).tolist():
        odd = False
        if math.isfinite(x) and math.isfinite(y):
            for x1, y1, dx, dy, y2 in edges:
                # An edge crossing the point's row has dy != 0: no division by zero.
                if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * dx / dy:
                    odd = not odd
        inside.append(odd)
    return np.array(inside, dtype=bool)


def point_in_polygon(point: tuple[float, float], polygon: np.ndarray) -> bool:
    """Even-odd rule for one point; False for a non-finite point."""
    return bool(points_in_polygon(np.array([point], dtype=float), polygon)[0])


def robot_pose_at(speed: float, yaw_rate: float, tau: float) -> tuple[float, float, float]:
    """Robot pose (x, y, yaw) after tau seconds, in its frame at tau = 0 (constant turn)."""
    if abs(yaw_rate) < 1e-6:
        return speed * tau, 0.0, 0.0
    yaw = yaw_rate * tau
    r = speed / yaw_rate
    return r * math.sin(yaw), r * (1 - math.cos(yaw)), yaw


def meets_swept_footprint(
    start: tuple[float, float],
    end: tuple[float, float],
    robot: RobotGeometry,
    speed: float,
    yaw_rate: float,
    horizon: float,
    radius: float = PEDESTRIAN_RADIUS,
    steps: int = 20,
) -> float | None:
    """First time (s) a pedestrian moving linearly start->end over the horizon meets the robot.

    The pedestrian is a disc of `radius`; the robot a rectangle (plus margin) following
    its constant-turn path. None when they never meet within the horizon.
    """
    half_w = robot.width / 2 + robot.margin
    rear = robot.front - robot.length
    for k in range(steps + 1):
        tau = horizon * k / steps
        f = k / steps
        px = start[0] + (end[0] - start[0]) * f
        py = start[1] + (end[1] - start[1]) * f
        rx, ry, yaw = robot_pose_at(speed, yaw_rate, tau)
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = px - rx, py - ry
        lx, ly = c * dx + s * dy, -s * dx + c * dy  # pedestrian in the robot's body frame
        qx = min(max(lx, rear), robot.front)
        qy = min(max(ly, -half_w), half_w)
        if math.hypot(lx - qx, ly - qy) <= radius:
            return tau
    return None
