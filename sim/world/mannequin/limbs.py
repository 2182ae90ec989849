"""The mannequin's limbs: arms with hands, legs with shoes, and their landmarks (11-32).

Each limb is a chain of bodies (upper arm, forearm, hand; thigh, shin, foot) whose
frames sit on the joints, so a landmark at a joint is simply the body's origin and
posing a hinge moves everything below it.
"""

from __future__ import annotations

import mujoco

from sim.world.mannequin.parts import BOX, Parts, Side


def add_arm(parts: Parts, torso: mujoco.MjsBody, side: Side) -> None:
    """Shoulder to fingertips: upper arm with its sleeve, forearm, hand with a thumb."""
    upper = _upper_arm(parts, torso, side)
    fore = parts.body(upper, f"forearm_{side.name}", pos=[0, 0, -parts.p.upper_arm])
    parts.hinge(fore, f"elbow_{side.name}", axis=[0, -1, 0])
    parts.capsule(
        fore,
        f"forearm_{side.name}",
        0.021 * parts.p.body,
        fromto=[0, 0, 0, 0, 0, -parts.p.forearm],
        material=parts.mat.arm,
    )
    parts.site(fore, 13 + side.lm, [0, 0, 0])  # elbow
    _hand(parts, fore, side)


def _upper_arm(parts: Parts, torso: mujoco.MjsBody, side: Side) -> mujoco.MjsBody:
    """The upper arm hanging from the shoulder, in a short sleeve over the arm.

    The sleeve is a slightly thicker capsule over the upper half, always in the shirt,
    so a short-sleeved arm shows skin below it and a long-sleeved one a continuous
    shirt. Its frame is the shoulder joint (the torso's frame sits at the waist).
    """
    p, b, name = parts.p, parts.p.body, side.name
    shoulder_rel = p.shoulder_z - p.waist_z
    upper = parts.body(
        torso, f"upper_arm_{name}", pos=[-0.008 * b, side.sign * p.shoulder_half, shoulder_rel]
    )
    parts.hinge(upper, f"shoulder_flex_{name}", axis=[0, -1, 0])
    parts.hinge(upper, f"shoulder_abd_{name}", axis=[side.sign, 0, 0])
    r_ua = 0.026 * b
    parts.capsule(
        upper,
        f"sleeve_{name}",
        r_ua * 1.12,
        fromto=[0, 0, 0, 0, 0, -0.5 * p.upper_arm],
        material=parts.mat.shirt,
    )
    parts.capsule(
        upper,
        f"upper_arm_{name}",
        r_ua,
        fromto=[0, 0, 0, 0, 0, -p.upper_arm],
        material=parts.mat.arm,
    )
    parts.site(upper, 11 + side.lm, [0, 0, 0])  # shoulder
    return upper


def _hand(parts: Parts, fore: mujoco.MjsBody, side: Side) -> None:
    """A flat hand at the wrist with a thumb, and the hand landmarks BlazePose reads.

    The thumb lies along the front of the hand when the arm hangs; the pinky, index
    and thumb landmarks sit where those fingers would be on a hand this size.
    """
    hand_len, skin = parts.p.hand, parts.mat.skin
    hand = parts.body(fore, f"hand_{side.name}", pos=[0, 0, -parts.p.forearm])
    hand_w, hand_t = 0.24 * hand_len, 0.12 * hand_len
    parts.ellipsoid(
        hand,
        f"hand_{side.name}",
        size=[hand_w, hand_t, 0.46 * hand_len],
        pos=[0, 0, -0.42 * hand_len],
        material=skin,
    )
    parts.capsule(
        hand,
        f"thumb_{side.name}",
        0.045 * hand_len,
        fromto=[0.75 * hand_w, 0, -0.12 * hand_len, 1.05 * hand_w, 0, -0.42 * hand_len],
        material=skin,
    )
    parts.site(hand, 15 + side.lm, [0, 0, 0])  # wrist
    parts.site(hand, 17 + side.lm, [-0.6 * hand_w, 0, -0.6 * hand_len])  # pinky knuckle
    parts.site(hand, 19 + side.lm, [0.6 * hand_w, 0, -0.65 * hand_len])  # index knuckle
    parts.site(hand, 21 + side.lm, [1.05 * hand_w, 0, -0.42 * hand_len])  # thumb tip


def add_leg(parts: Parts, pelvis: mujoco.MjsBody, side: Side) -> None:
    """Hip to toes: thigh and shin in trousers, then the foot in its shoe."""
    p, b, name, trousers = parts.p, parts.p.body, side.name, parts.mat.trousers
    thigh = parts.body(pelvis, f"thigh_{name}", pos=[0, side.sign * p.hip_half, 0])
    parts.hinge(thigh, f"hip_flex_{name}", axis=[0, -1, 0])
    parts.hinge(thigh, f"hip_abd_{name}", axis=[side.sign, 0, 0])
    parts.capsule(
        thigh, f"thigh_{name}", 0.037 * b, fromto=[0, 0, 0, 0, 0, -p.thigh], material=trousers
    )
    # A thicker upper thigh: the leg tapers from hip to knee.
    parts.capsule(
        thigh,
        f"thigh_top_{name}",
        0.045 * b,
        fromto=[0, side.sign * 0.004 * b, -0.02 * b, 0, 0, -0.45 * p.thigh],
        material=trousers,
    )
    parts.site(thigh, 23 + side.lm, [0, 0, 0])  # hip
    shin = parts.body(thigh, f"shin_{name}", pos=[0, 0, -p.thigh])
    parts.hinge(shin, f"knee_{name}", axis=[0, 1, 0])
    parts.capsule(
        shin, f"shin_{name}", 0.029 * b, fromto=[0, 0, 0, 0, 0, -p.shin], material=trousers
    )
    # The calf bulges behind the upper shin.
    parts.capsule(
        shin,
        f"calf_{name}",
        0.033 * b,
        fromto=[-0.006 * b, 0, -0.1 * p.shin, -0.006 * b, 0, -0.45 * p.shin],
        material=trousers,
    )
    parts.site(shin, 25 + side.lm, [0, 0, 0])  # knee
    _foot(parts, shin, side)


def _foot(parts: Parts, shin: mujoco.MjsBody, side: Side) -> None:
    """The foot at the ankle in a shoe: a flat sole, a high heel counter, a lower toe box.

    The shoe's shape shows which way the foot points (a cue for telling a back view
    from a front view). The sole's bottom is at the ground when the mannequin stands
    straight; `Mannequin.place` finds the lowest shoe point to stand any pose on it.
    """
    p, b, name, shoes = parts.p, parts.p.body, side.name, parts.mat.shoes
    foot = parts.body(shin, f"foot_{name}", pos=[0, 0, -p.shin])
    parts.hinge(foot, f"ankle_{name}", axis=[0, -1, 0])
    shoe_w = 0.03 * b
    sole_h = 0.012 * b
    toe_end = p.foot - p.heel_back
    parts.geom(
        foot,
        f"shoe_sole_{name}",
        type=BOX,
        size=[p.foot / 2, shoe_w, sole_h / 2],
        pos=[toe_end - p.foot / 2, 0, -p.ankle_z + sole_h / 2],
        material=shoes,
    )
    parts.ellipsoid(
        foot,
        f"shoe_heel_{name}",
        size=[0.24 * p.foot, shoe_w, 0.75 * p.ankle_z],
        pos=[-p.heel_back + 0.24 * p.foot, 0, -0.25 * p.ankle_z],
        material=shoes,
    )
    parts.ellipsoid(
        foot,
        f"shoe_toe_{name}",
        size=[0.42 * p.foot, 0.95 * shoe_w, 0.42 * p.ankle_z],
        pos=[toe_end - 0.42 * p.foot, 0, -0.58 * p.ankle_z],
        material=shoes,
    )
    parts.site(foot, 27 + side.lm, [0, 0, 0])  # ankle
    sole_top = -p.ankle_z + 0.3 * p.ankle_z
    parts.site(foot, 29 + side.lm, [-p.heel_back + 0.01 * b, 0, sole_top])  # heel
    parts.site(foot, 31 + side.lm, [toe_end - 0.01 * b, 0, sole_top])  # foot index (toes)
