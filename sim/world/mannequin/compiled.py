"""A compiled mannequin: where its state lives in the model, and how to pose and measure it.

The builder only describes the person; once the scene is compiled, this finds the
mannequin's joints, landmark sites and geoms by name, poses it from a `MannequinPose`
and stands it on the ground, and answers the ground truth's questions (landmarks, the
point between the feet, the highest point, surface points) without searching again.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sim.geometry.frames import yaw_quat
from sim.scenario.spec import MannequinSpec
from sim.world.gait import JOINT_FIELDS, MannequinPose
from sim.world.mannequin.landmarks import N_LANDMARKS, landmark_site
from sim.world.mannequin.proportions import Proportions
from sim.world.mannequin.shapes import GeomShapes


class Mannequin:
    """A compiled mannequin: where its state lives in the model and how to pose it."""

    def __init__(self, model: mujoco.MjModel, look: MannequinSpec, prefix: str) -> None:
        self.look = look
        self.prefix = prefix
        self.proportions = Proportions.of(look.height)
        root = model.joint(prefix + "root")
        self.root_qpos = int(root.qposadr[0])
        self.joint_qpos = np.array(
            [int(model.joint(prefix + name).qposadr[0]) for name in JOINT_FIELDS]
        )
        self.landmark_sites = np.array(
            [model.site(landmark_site(prefix, i)).id for i in range(N_LANDMARKS)]
        )
        root_body = model.body(prefix + "pelvis").id
        bodies = [i for i in range(model.nbody) if _has_ancestor(model, i, root_body)]
        self.body_ids = np.array(bodies)
        body_set = set(bodies)
        self.geom_ids = np.array(
            [g for g in range(model.ngeom) if model.geom_bodyid[g] in body_set]
        )
        self.shoe_geoms = np.array(
            [
                model.geom(f"{prefix}shoe_{part}_{side}").id
                for part in ("sole", "heel", "toe")
                for side in ("l", "r")
            ]
        )
        self.foot_sites = np.array(
            [
                [model.site(landmark_site(prefix, i)).id for i in pair]
                for pair in ((29, 31), (30, 32))
            ]
        )
        self.shapes = GeomShapes.of(model, self.geom_ids)
        self.shoe_shapes = GeomShapes.of(model, self.shoe_geoms, n=1)

    def place(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        x: float,
        y: float,
        yaw: float,
        pose: MannequinPose,
    ) -> None:
        """Pose the mannequin and stand it on the ground at (x, y) facing `yaw`.

        Runs forward kinematics twice: once to find the lowest point of the shoes, once
        after lifting or lowering the root so that point touches z = 0.
        """
        heading = yaw + pose.pelvis_yaw
        sway_x = -math.sin(yaw) * pose.sway
        sway_y = math.cos(yaw) * pose.sway
        q = data.qpos
        q[self.root_qpos : self.root_qpos + 3] = (x + sway_x, y + sway_y, self.proportions.hip_z)
        q[self.root_qpos + 3 : self.root_qpos + 7] = yaw_quat(heading)
        q[self.joint_qpos] = [getattr(pose, name) for name in JOINT_FIELDS]
        mujoco.mj_kinematics(model, data)
        lowest = float(np.min(self.shoe_shapes.z_extent(data)[0]))
        q[self.root_qpos + 2] -= lowest
        mujoco.mj_kinematics(model, data)

    def landmarks(self, data: mujoco.MjData) -> np.ndarray:
        """World positions (33, 3) of the BlazePose landmarks, in BlazePose order."""
        return data.site_xpos[self.landmark_sites].copy()

    def foot_point(self, data: mujoco.MjData) -> np.ndarray:
        """Midpoint between the two feet (each the middle of heel and toe), on the ground."""
        feet = data.site_xpos[self.foot_sites].mean(axis=1)
        point = feet.mean(axis=0)
        point[2] = 0.0
        return point

    def top_height(self, data: mujoco.MjData) -> float:
        """Highest point of the mannequin above the ground (m)."""
        return float(np.max(self.shapes.z_extent(data)[1]))

    def surface_points(self, data: mujoco.MjData) -> np.ndarray:
        """Points (N, 3) sampled on every geom's surface, for the apparent box."""
        return self.shapes.surface_points(data)


def _has_ancestor(model: mujoco.MjModel, body: int, ancestor: int) -> bool:
    while body > 0:
        if body == ancestor:
            return True
        body = int(model.body_parentid[body])
    return False
