"""A parked car: a box body, a cabin and wheels in MuJoCo, an obstacle on highway-env's road.

It hides what is behind it from the camera (the truth's occlusion is a ray test against
every drawn geom) and shows in the top-down view; the robot never collides with it.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from highway_env.road.road import Road

from sim.geometry.frames import yaw_quat
from sim.scenario.spec import Occluder
from sim.world.entities.base import Entity, Moment, Sight
from sim.world.robot import occluder_obstacle
from sim.world.street import add_box, add_material


class ParkedCar(Entity):
    """One parked car where the scenario puts it (static)."""

    kind = "parked car"

    def __init__(self, occluder: Occluder, name: str) -> None:
        self.occluder = occluder
        self.name = name

    def build(self, spec: mujoco.MjSpec) -> None:
        """A car-like box: a body, a narrower cabin on top, four wheels."""
        occ, prefix = self.occluder, self.prefix
        paint = add_material(spec, prefix + "paint", (*occ.colour, 1.0), specular=0.4,
                             shininess=0.5)  # fmt: skip
        glass = add_material(
            spec, prefix + "glass", (0.15, 0.18, 0.22, 1.0), specular=0.6, shininess=0.8
        )
        lower = 0.55 * occ.height
        clearance = 0.18
        add_box(
            spec,
            prefix + "body",
            (occ.x, occ.y, clearance + (lower - clearance) / 2),
            (occ.length / 2, occ.width / 2, (lower - clearance) / 2),
            paint,
            occ.yaw,
        )
        cab_len = 0.55 * occ.length
        back = -0.08 * occ.length
        cx = occ.x + math.cos(occ.yaw) * back
        cy = occ.y + math.sin(occ.yaw) * back
        add_box(
            spec,
            prefix + "cabin",
            (cx, cy, lower + (occ.height - lower) / 2),
            (cab_len / 2, occ.width / 2 - 0.08, (occ.height - lower) / 2),
            glass,
            occ.yaw,
        )
        # Wheels hint at a car from low camera heights and fill the gap under the body.
        for j, (fx, fy) in enumerate(((0.33, 0.47), (0.33, -0.47), (-0.33, 0.47), (-0.33, -0.47))):
            dx, dy = fx * occ.length, fy * occ.width
            wx = occ.x + math.cos(occ.yaw) * dx - math.sin(occ.yaw) * dy
            wy = occ.y + math.sin(occ.yaw) * dx + math.cos(occ.yaw) * dy
            spec.worldbody.add_geom(
                name=f"{prefix}wheel_{j}",
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                pos=[wx, wy, 0.32],
                size=[0.32, 0.11, 0],
                quat=_wheel_quat(occ.yaw).tolist(),
                rgba=[0.08, 0.08, 0.08, 1],
                contype=0,
                conaffinity=0,
                group=0,
            )

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        road.objects.append(occluder_obstacle(road, self.occluder))

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        """It stands where it was built."""

    def truth(self, model: mujoco.MjModel, data: mujoco.MjData, sight: Sight) -> Occluder:
        """Where it stands and its size (it never moves)."""
        return self.occluder


def _wheel_quat(yaw: float) -> np.ndarray:
    """Orientation of a wheel cylinder: axis along the car's lateral direction."""
    # Cylinder axis is local z; turn it to the car's y axis: yaw, then 90 deg about x.
    qz = yaw_quat(yaw)
    qx = np.array([math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0])
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, qz, qx)
    return out
