"""The one conversion between highway-env's frame and the simulator's world (MuJoCo) frame.

highway-env (checked in its source, v1.12.1) works in screen coordinates: the top-down
viewer maps a position (x, y) straight to a pixel (x right, y down, see
road.graphics.WorldSurface.pos2pix); lanes of a straight road are stacked at
y = lane_index * width and "LANE_RIGHT" increases the lane index
(vehicle.controller.ControlledVehicle.act); a lane's left line is at negative lateral
offset (road.graphics.LaneGraphics, side 0 = left at -width/2); headings are
atan2(vy, vx) (RoadObject.direction), so a positive heading turns from +x towards +y,
which is clockwise seen from above. In words: x along the road, y to the right of the
road's direction, heading clockwise from x, when seen from above.

The world frame (sim.geometry.frames) is x east, y north, z up, yaw counter-clockwise from east.
Both share x; highway-env's y is the world's -y, and its heading the world's -yaw. The
conversion is a reflection, hence its own inverse: `reflect` is the one function, the
named wrappers only say which way a call goes.
"""

from __future__ import annotations

import numpy as np

from sim.geometry.frames import Pose2D, wrap_angle

# Position and velocity vectors change by this matrix in either direction.
REFLECTION = np.array([[1.0, 0.0], [0.0, -1.0]])


def reflect(xy: np.ndarray, heading: float) -> tuple[np.ndarray, float]:
    """Mirror a planar position (or velocity) and a heading across the road's x axis.

    Turns world (x, y, yaw) into highway-env (x, y, heading) and back: the reflection is
    an involution, so one function serves both directions.
    """
    vec = np.asarray(xy, dtype=float) @ REFLECTION.T
    return vec, wrap_angle(-float(heading))


def world_to_highway(pose: Pose2D) -> tuple[np.ndarray, float]:
    """World pose -> highway-env (position (2,), heading)."""
    return reflect(np.array([pose.x, pose.y]), pose.yaw)


def highway_to_world(position: np.ndarray, heading: float) -> Pose2D:
    """highway-env position and heading -> world pose."""
    xy, yaw = reflect(position, heading)
    return Pose2D(float(xy[0]), float(xy[1]), yaw)
