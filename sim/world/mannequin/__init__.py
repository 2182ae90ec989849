"""The pedestrian mannequin: an articulated person built from MuJoCo primitives.

BlazePose has to accept it as a person, so it carries what the detector leans on: a
face (eyes with irises, eyebrows, nose, mouth, ears), hair, a neck, a torso that is
wider than it is deep, clothing that separates torso from legs, arms with hands, legs
with shoes. Proportions follow anthropometric tables (segment lengths as fractions of
stature, Drillis and Contini) with a head that is relatively larger for a child, so one
`height` parameter gives both the 1.8 m adult and the 1.15 m child.

Local frame of the mannequin: x forward (where the person faces), y to the person's
left, z up, origin on the ground between the feet. Joints are hinges posed directly
(kinematics only, no physics); the root is a free joint so one qpos holds the whole
pose and the scene can be replayed from it.

The package, in the order a reader meets it:
  proportions  stature -> segment lengths and girths (Proportions)
  clothing     the look's materials and the checked shirt (Materials)
  landmarks    BlazePose's 33 names and the sites that mark them
  parts        what every part is built with (Parts, Side): no closures
  torso        pelvis (the root) and torso with shoulders and neck
  head         skull, hair, the face and its landmarks (Face)
  limbs        arms with hands, legs with shoes
  build        build_mannequin: the parts in the model's order
  compiled     Mannequin: pose, stand and measure the compiled person
  shapes       GeomShapes, geom_z_extent: surface points and heights per frame
"""

from __future__ import annotations

from sim.world.mannequin.build import build_mannequin
from sim.world.mannequin.compiled import Mannequin
from sim.world.mannequin.landmarks import BLAZEPOSE_NAMES, N_LANDMARKS, SITE_GROUP
from sim.world.mannequin.proportions import Proportions
from sim.world.mannequin.shapes import GeomShapes, geom_z_extent

__all__ = [
    "BLAZEPOSE_NAMES",
    "N_LANDMARKS",
    "SITE_GROUP",
    "GeomShapes",
    "Mannequin",
    "Proportions",
    "build_mannequin",
    "geom_z_extent",
]
