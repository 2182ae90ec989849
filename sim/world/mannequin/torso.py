"""The mannequin's trunk: the pelvis (the root every other part hangs from) and the torso.

The torso is wider than it is deep and its shirt stops at the trousers, two of the
cues that make BlazePose take the mannequin for a person; the shoulder girdle and neck
join it to the arms and the head.
"""

from __future__ import annotations

import mujoco

from sim.world.mannequin.parts import Parts


def add_pelvis(parts: Parts) -> mujoco.MjsBody:
    """The root body at hip-joint height, with the free joint that places the whole person.

    A free joint puts the mannequin's position and heading in the same qpos as its joint
    angles, so one qpos holds the whole pose and a scene can be replayed from it.
    """
    p, b = parts.p, parts.p.body
    pelvis = parts.body(parts.spec.worldbody, "pelvis", pos=[0, 0, p.hip_z])
    pelvis.add_freejoint(name=parts.prefix + "root")
    parts.ellipsoid(
        pelvis,
        "pelvis",
        size=[0.062 * b, 0.098 * b, 0.065 * b],
        pos=[-0.006 * b, 0, 0.025 * b],
        material=parts.mat.trousers,
    )
    return pelvis


def add_torso(parts: Parts, pelvis: mujoco.MjsBody) -> mujoco.MjsBody:
    """The torso above the waist joint: abdomen, chest, shoulder girdle and neck.

    Its frame sits at the waist so that turning and leaning at the waist carries the
    arms and the head along; the neck geom belongs to it (not to the head) so the head
    can nod without the neck leaving the shoulders.
    """
    p, b, hh, shirt = parts.p, parts.p.body, parts.p.head, parts.mat.shirt
    torso = parts.body(pelvis, "torso", pos=[0, 0, p.waist_z - p.hip_z])
    parts.hinge(torso, "waist_yaw", axis=[0, 0, 1])
    parts.hinge(torso, "waist_pitch", axis=[0, 1, 0])
    parts.ellipsoid(
        torso,
        "abdomen",
        size=[0.058 * b, 0.088 * b, 0.08 * b],
        pos=[0.002 * b, 0, 0.02 * b],
        material=shirt,
    )
    parts.ellipsoid(
        torso,
        "chest",
        size=[0.066 * b, 0.098 * b, 0.11 * b],
        pos=[0.004 * b, 0, 0.12 * b],
        material=shirt,
    )
    shoulder_rel = p.shoulder_z - p.waist_z
    shoulder_line_z = shoulder_rel - 0.012 * b
    parts.capsule(
        torso,
        "shoulders",
        0.04 * b,
        fromto=[-0.008 * b, -0.085 * b, shoulder_line_z, -0.008 * b, 0.085 * b, shoulder_line_z],
        material=shirt,
    )
    parts.capsule(
        torso,
        "neck",
        0.03 * b,
        fromto=[0.0, 0, shoulder_rel - 0.02 * b, 0.005 * b, 0, p.chin_z - p.waist_z + 0.04 * hh],
        material=parts.mat.skin,
    )
    return torso
