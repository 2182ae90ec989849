"""The camera-carrying robot as a highway-env vehicle, and the straight road it drives on.

highway-env owns the robot's kinematics (its bicycle model integrates position, heading
and speed), lanes and collision geometry. The robot only drives straight: the action is
its longitudinal acceleration, clipped to the scenario's limits, and it never reverses
(braking stops it and it stays stopped). Its reference point (the origin of monopic's
robot frame, where the camera mounting is measured from) is the centre of its footprint,
which is where highway-env keeps a vehicle's position; the pipeline's RobotGeometry for
this robot therefore has front = length / 2.
"""

from __future__ import annotations

import math

import numpy as np
from highway_env.road.lane import LineType, StraightLane
from highway_env.road.road import Road, RoadNetwork
from highway_env.vehicle.kinematics import Vehicle
from highway_env.vehicle.objects import Obstacle

from sim.geometry.frames import Pose2D
from sim.geometry.highway_frame import highway_to_world, world_to_highway
from sim.scenario.spec import Occluder, RoadLayout, RobotSpec

ROAD_NODES = ("west", "east")
EGO_COLOUR = (50, 200, 0)  # highway-env's ego green in its top-down view


def highway_road(layout: RoadLayout) -> Road:
    """The street of a RoadLayout as a highway-env road along the world x axis.

    Lanes are numbered as highway-env does, 0 the leftmost when driving east (the northern
    one in the world). Parked cars add themselves (sim.world.entities.parked_car).
    """
    net = RoadNetwork()
    _, y_left = layout.edges
    left_hw = -y_left  # highway-env y of the road's left (northern) edge
    half = layout.length / 2
    for k in range(layout.lanes):
        centre = left_hw + (k + 0.5) * layout.lane_width
        line_types = (
            LineType.CONTINUOUS_LINE if k == 0 else LineType.STRIPED,
            LineType.CONTINUOUS_LINE if k == layout.lanes - 1 else LineType.NONE,
        )
        lane = StraightLane(
            np.array([-half, centre]),
            np.array([half, centre]),
            width=layout.lane_width,
            line_types=line_types,
            speed_limit=30.0,
        )
        net.add_lane(*ROAD_NODES, lane)
    return Road(network=net, np_random=np.random.RandomState(0), record_history=False)


def occluder_obstacle(road: Road, occ: Occluder) -> Obstacle:
    """A parked-car occluder as a highway-env obstacle (drawn, never collided with)."""
    position, heading = world_to_highway(Pose2D(occ.x, occ.y, occ.yaw))
    obstacle = Obstacle.__new__(Obstacle)
    obstacle.LENGTH, obstacle.WIDTH = occ.length, occ.width  # before __init__ uses them
    Obstacle.__init__(obstacle, road, position, heading)
    obstacle.collidable = False
    obstacle.check_collisions = False
    return obstacle


class Robot(Vehicle):
    """A highway-env vehicle of the scenario robot's size that only drives straight."""

    def __init__(self, road: Road | None, spec: RobotSpec, pose: Pose2D) -> None:
        for name in ("max_acceleration", "max_deceleration", "max_speed", "length", "width"):
            value = getattr(spec, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"robot {name} must be positive, got {value}")
        if not (math.isfinite(spec.speed) and 0 <= spec.speed <= spec.max_speed):
            raise ValueError(f"robot speed must be in [0, {spec.max_speed}] m/s, got {spec.speed}")
        # Per-instance size and limits, set before Vehicle.__init__ derives the diagonal.
        self.LENGTH = spec.length
        self.WIDTH = spec.width
        self.MAX_SPEED = spec.max_speed
        self.MIN_SPEED = 0.0
        self.spec = spec
        position, heading = world_to_highway(pose)
        super().__init__(road, position, heading, spec.speed)
        self.action = {"steering": 0.0, "acceleration": 0.0}
        self.applied_acceleration = 0.0  # what the last step really used, after clipping
        self.color = EGO_COLOUR

    def act(self, action: dict | float | None = None) -> None:
        """Set the longitudinal acceleration (m/s^2); a highway-env action dict also works.

        None keeps the previous action, as highway-env's Road.act() calls it.
        """
        if action is None:
            return
        accel = action.get("acceleration", 0.0) if isinstance(action, dict) else action
        accel = float(accel)
        if not math.isfinite(accel):
            raise ValueError(f"robot acceleration must be finite, got {accel}")
        self.action = {"steering": 0.0, "acceleration": accel}

    def clip_actions(self) -> None:
        """highway-env's clipping, then the robot's limits; it never steers."""
        super().clip_actions()
        self.action["steering"] = 0.0
        self.action["acceleration"] = float(
            np.clip(
                self.action["acceleration"], -self.spec.max_deceleration, self.spec.max_acceleration
            )
        )

    def step(self, dt: float) -> None:
        """Integrate highway-env's kinematics over dt without reversing or overspeeding."""
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"time step must be positive, got {dt}")
        self.clip_actions()
        accel = self.action["acceleration"]
        # Reach exactly zero (or the top speed) within this step instead of passing it.
        accel = min(max(accel, -self.speed / dt), (self.MAX_SPEED - self.speed) / dt)
        self.action["acceleration"] = accel
        super().step(dt)
        self.speed = min(max(self.speed, 0.0), self.MAX_SPEED)
        self.applied_acceleration = accel

    @property
    def world_pose(self) -> Pose2D:
        """The robot's reference point and heading in the world frame."""
        return highway_to_world(self.position, self.heading)
