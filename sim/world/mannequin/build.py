"""`build_mannequin`: add the whole person to a spec, part by part.

The parts hang from one another (pelvis -> torso -> head and arms, pelvis -> legs), and
MuJoCo numbers bodies, geoms and sites in the order they are added; the ground truth
finds landmarks and geoms by those ids, so the order below is part of the model.
"""

from __future__ import annotations

import mujoco

from sim.scenario.spec import MannequinSpec
from sim.world.mannequin.clothing import add_materials
from sim.world.mannequin.head import add_head
from sim.world.mannequin.limbs import add_arm, add_leg
from sim.world.mannequin.parts import SIDES, Parts
from sim.world.mannequin.proportions import Proportions
from sim.world.mannequin.torso import add_pelvis, add_torso


def build_mannequin(spec: mujoco.MjSpec, look: MannequinSpec, prefix: str) -> None:
    """Add a mannequin to `spec` under the world body; all names start with `prefix`."""
    parts = Parts(
        spec=spec,
        prefix=prefix,
        p=Proportions.of(look.height),
        mat=add_materials(spec, look, prefix),
    )
    pelvis = add_pelvis(parts)
    torso = add_torso(parts, pelvis)
    add_head(parts, torso)
    for side in SIDES:
        add_arm(parts, torso, side)
    for side in SIDES:
        add_leg(parts, pelvis, side)
