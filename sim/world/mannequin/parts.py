"""What every part of the mannequin is built with: one small context instead of closures.

The builder is split into parts (torso, head, limbs); each needs the same few things:
the spec, the prefix every name starts with, the proportions and the materials. `Parts`
holds them and adds bodies, hinges, geoms and landmark sites the one way the mannequin
needs them (kinematic geoms that never collide, sites in the hidden group).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco

from sim.world.mannequin.clothing import Materials
from sim.world.mannequin.landmarks import SITE_GROUP, landmark_site
from sim.world.mannequin.proportions import Proportions

# The only shapes the mannequin is made of (GeomShapes measures exactly these).
ELLIPSOID = mujoco.mjtGeom.mjGEOM_ELLIPSOID
CAPSULE = mujoco.mjtGeom.mjGEOM_CAPSULE
SPHERE = mujoco.mjtGeom.mjGEOM_SPHERE
BOX = mujoco.mjtGeom.mjGEOM_BOX


@dataclass(frozen=True)
class Side:
    """One side of the body, the person's own: names, mirror sign and landmark offset."""

    name: str  # "l" or "r", the suffix of the part's names
    sign: float  # +1 on the left (+y), -1 on the right: mirrors y and abduction axes
    lm: int  # BlazePose numbers paired landmarks left then right: 0 on the left, 1 on the right


LEFT = Side("l", 1.0, 0)
RIGHT = Side("r", -1.0, 1)
SIDES = (LEFT, RIGHT)


@dataclass(frozen=True)
class Parts:
    """The spec a mannequin is added to, with its name prefix, proportions and materials."""

    spec: mujoco.MjSpec
    prefix: str
    p: Proportions
    mat: Materials

    def body(self, parent: mujoco.MjsBody, name: str, pos: Sequence[float]) -> mujoco.MjsBody:
        """A child body of `parent`, placed at `pos` in the parent's frame."""
        return parent.add_body(name=self.prefix + name, pos=pos)

    def hinge(self, body: mujoco.MjsBody, name: str, axis: Sequence[float]) -> None:
        """A hinge joint posed directly from `MannequinPose` (the field of the same name)."""
        body.add_joint(name=self.prefix + name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis)

    def geom(self, body: mujoco.MjsBody, name: str, **kw: object) -> None:
        """A visible geom (group 1) that never collides: the mannequin is posed, not simulated."""
        g = body.add_geom(name=self.prefix + name, contype=0, conaffinity=0, group=1, **kw)
        g.mass = 1.0  # kinematic only; any positive mass keeps the compiler happy

    def ellipsoid(
        self,
        body: mujoco.MjsBody,
        name: str,
        size: Sequence[float],
        pos: Sequence[float],
        material: str,
    ) -> None:
        """An ellipsoid with semi-axes `size` centred at `pos`: most of the soft body."""
        self.geom(body, name, type=ELLIPSOID, size=size, pos=pos, material=material)

    def capsule(
        self, body: mujoco.MjsBody, name: str, radius: float, fromto: Sequence[float], material: str
    ) -> None:
        """A capsule of `radius` between two points (`fromto`): limbs, neck, brows, lips."""
        self.geom(body, name, type=CAPSULE, size=[radius, 0, 0], fromto=fromto, material=material)

    def site(self, body: mujoco.MjsBody, index: int, pos: Sequence[float]) -> None:
        """The site marking BlazePose landmark `index`, hidden from the camera."""
        body.add_site(
            name=landmark_site(self.prefix, index), pos=pos, size=[0.005, 0, 0], group=SITE_GROUP
        )
