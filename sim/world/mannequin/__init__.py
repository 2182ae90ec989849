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
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sim.scenario.spec import RGBA, MannequinSpec
from sim.world.mannequin.compiled import Mannequin
from sim.world.mannequin.landmarks import BLAZEPOSE_NAMES, N_LANDMARKS, SITE_GROUP, landmark_site
from sim.world.mannequin.proportions import Proportions
from sim.world.mannequin.shapes import GeomShapes, geom_z_extent


def _quat_from_axes(x_axis: np.ndarray, z_axis: np.ndarray) -> np.ndarray:
    """Quaternion of the frame whose x and z axes are given (y completes it)."""
    x = x_axis / np.linalg.norm(x_axis)
    z = z_axis / np.linalg.norm(z_axis)
    y = np.cross(z, x)
    mat = np.column_stack([x, y, z]).reshape(-1)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat)
    return quat


def build_mannequin(spec: mujoco.MjSpec, look: MannequinSpec, prefix: str) -> None:
    """Add a mannequin to `spec` under the world body; all names start with `prefix`."""
    p = Proportions.of(look.height)
    b, hh = p.body, p.head

    def material(name: str, rgba: RGBA, specular: float, shininess: float) -> str:
        mat = spec.add_material(name=prefix + name)
        mat.rgba = list(rgba)
        mat.specular = specular
        mat.shininess = shininess
        return prefix + name

    skin = material("skin", look.skin, 0.15, 0.2)
    skin_dark = material("skin_dark", tuple(0.82 * c for c in look.skin[:3]) + (1.0,), 0.15, 0.2)
    hair = material("hair", look.hair, 0.1, 0.3)
    shoes = material("shoes", look.shoes, 0.3, 0.4)
    trousers = material("trousers", look.trousers, 0.05, 0.1)
    shirt = material("shirt", look.shirt, 0.05, 0.1)
    if look.shirt_pattern == "checker":
        tex = spec.add_texture(
            name=prefix + "shirt_check",
            type=mujoco.mjtTexture.mjTEXTURE_2D,
            builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
            width=64,
            height=64,
            rgb1=list(look.shirt[:3]),
            rgb2=[0.55 * c + 0.45 for c in look.shirt[:3]],
        )
        mat = spec.material(shirt)
        mat.rgba = [1.0, 1.0, 1.0, 1.0]
        mat.texuniform = True
        mat.texrepeat = [8.0, 8.0]
        textures = [""] * int(mujoco.mjtTextureRole.mjNTEXROLE)
        textures[int(mujoco.mjtTextureRole.mjTEXROLE_RGB)] = tex.name
        mat.textures = textures
    eye_white = material("eye_white", (0.95, 0.95, 0.93, 1.0), 0.4, 0.6)
    iris = material("iris", (0.12, 0.08, 0.05, 1.0), 0.5, 0.8)
    lips = material("lips", (0.62, 0.28, 0.28, 1.0), 0.2, 0.3)
    forearm_mat = shirt if look.long_sleeves else skin

    ellipsoid = mujoco.mjtGeom.mjGEOM_ELLIPSOID
    capsule = mujoco.mjtGeom.mjGEOM_CAPSULE
    sphere = mujoco.mjtGeom.mjGEOM_SPHERE
    box = mujoco.mjtGeom.mjGEOM_BOX

    def geom(body: mujoco.MjsBody, name: str, **kw: object) -> None:
        g = body.add_geom(name=prefix + name, contype=0, conaffinity=0, group=1, **kw)
        g.mass = 1.0  # kinematic only; any positive mass keeps the compiler happy

    def site(body: mujoco.MjsBody, index: int, pos: list[float]) -> None:
        body.add_site(
            name=landmark_site(prefix, index), pos=pos, size=[0.005, 0, 0], group=SITE_GROUP
        )

    # Pelvis: the root, at hip-joint height, with a free joint.
    pelvis = spec.worldbody.add_body(name=prefix + "pelvis", pos=[0, 0, p.hip_z])
    pelvis.add_freejoint(name=prefix + "root")
    geom(
        pelvis,
        "pelvis",
        type=ellipsoid,
        size=[0.062 * b, 0.098 * b, 0.065 * b],
        pos=[-0.006 * b, 0, 0.025 * b],
        material=trousers,
    )

    # Torso: waist joint, abdomen, chest, shoulder girdle, neck.
    torso = pelvis.add_body(name=prefix + "torso", pos=[0, 0, p.waist_z - p.hip_z])
    torso.add_joint(name=prefix + "waist_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    torso.add_joint(name=prefix + "waist_pitch", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
    geom(
        torso,
        "abdomen",
        type=ellipsoid,
        size=[0.058 * b, 0.088 * b, 0.08 * b],
        pos=[0.002 * b, 0, 0.02 * b],
        material=shirt,
    )
    geom(
        torso,
        "chest",
        type=ellipsoid,
        size=[0.066 * b, 0.098 * b, 0.11 * b],
        pos=[0.004 * b, 0, 0.12 * b],
        material=shirt,
    )
    shoulder_rel = p.shoulder_z - p.waist_z
    geom(
        torso,
        "shoulders",
        type=capsule,
        size=[0.04 * b, 0, 0],
        fromto=[
            -0.008 * b,
            -0.085 * b,
            shoulder_rel - 0.012 * b,
            -0.008 * b,
            0.085 * b,
            shoulder_rel - 0.012 * b,
        ],
        material=shirt,
    )
    geom(
        torso,
        "neck",
        type=capsule,
        size=[0.03 * b, 0, 0],
        fromto=[0.0, 0, shoulder_rel - 0.02 * b, 0.005 * b, 0, p.chin_z - p.waist_z + 0.04 * hh],
        material=skin,
    )

    # Head: neck joint at chin height, face features on the front (+x).
    head = torso.add_body(name=prefix + "head", pos=[0, 0, p.chin_z - p.waist_z])
    head.add_joint(name=prefix + "neck_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    head.add_joint(name=prefix + "neck_pitch", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
    head_c = np.array([0.03 * hh, 0.0, 0.5 * hh])
    head_size = np.array([0.42 * hh, 0.33 * hh, 0.49 * hh])
    geom(head, "head", type=ellipsoid, size=head_size.tolist(), pos=head_c.tolist(), material=skin)
    # A jaw narrower than the skull gives the face its shape from the side and front.
    jaw_c = np.array([0.08 * hh, 0.0, 0.22 * hh])
    jaw_size = np.array([0.28 * hh, 0.26 * hh, 0.2 * hh])
    geom(head, "jaw", type=ellipsoid, size=jaw_size.tolist(), pos=jaw_c.tolist(), material=skin)
    # Hair: a cap over crown and back of the head, leaving forehead and face bare.
    geom(
        head,
        "hair_cap",
        type=ellipsoid,
        size=[0.43 * hh, 0.345 * hh, 0.36 * hh],
        pos=[-0.02 * hh, 0, 0.66 * hh],
        quat=_quat_from_axes(
            np.array([math.cos(0.35), 0, math.sin(0.35)]),
            np.array([-math.sin(0.35), 0, math.cos(0.35)]),
        ).tolist(),
        material=hair,
    )
    geom(
        head,
        "hair_back",
        type=ellipsoid,
        size=[0.34 * hh, 0.335 * hh, 0.4 * hh],
        pos=[-0.1 * hh, 0, 0.52 * hh],
        material=hair,
    )

    def face_x(y: float, z: float) -> float:
        """x of the face's front surface (skull or jaw) at (y, z) in the head frame."""
        front = -math.inf
        for c, size in ((head_c, head_size), (jaw_c, jaw_size)):
            r = 1.0 - ((y - c[1]) / size[1]) ** 2 - ((z - c[2]) / size[2]) ** 2
            if r >= 0:
                front = max(front, float(c[0] + size[0] * math.sqrt(r)))
        return front

    eye_z = 0.5 * hh
    eye_y = 0.135 * hh
    eye_r = 0.075 * hh  # half width of the visible eye
    for side, sign in (("l", 1.0), ("r", -1.0)):
        y = sign * eye_y
        x = face_x(y, eye_z)
        geom(
            head,
            f"eye_{side}",
            type=ellipsoid,
            size=[0.03 * hh, eye_r, 0.042 * hh],
            pos=[x - 0.012 * hh, y, eye_z],
            material=eye_white,
        )
        geom(
            head,
            f"iris_{side}",
            type=sphere,
            size=[0.036 * hh, 0, 0],
            pos=[x - 0.008 * hh, y, eye_z],
            material=iris,
        )
        brow_z = eye_z + 0.13 * hh
        geom(
            head,
            f"brow_{side}",
            type=capsule,
            size=[0.02 * hh, 0, 0],
            fromto=[
                face_x(sign * 0.07 * hh, brow_z),
                sign * 0.07 * hh,
                brow_z,
                face_x(sign * 0.22 * hh, brow_z),
                sign * 0.22 * hh,
                brow_z - 0.02 * hh,
            ],
            material=hair,
        )
        geom(
            head,
            f"ear_{side}",
            type=ellipsoid,
            size=[0.08 * hh, 0.035 * hh, 0.13 * hh],
            pos=[0.0, sign * 0.32 * hh, 0.45 * hh],
            material=skin_dark,
        )
    nose_z = 0.36 * hh
    nose_x = face_x(0.0, nose_z)
    geom(
        head,
        "nose",
        type=ellipsoid,
        size=[0.07 * hh, 0.045 * hh, 0.1 * hh],
        pos=[nose_x, 0, nose_z],
        material=skin_dark,
    )
    mouth_z = 0.2 * hh
    mouth_half = 0.085 * hh
    mouth_r = 0.028 * hh
    mouth_x = face_x(0.0, mouth_z) - 0.3 * mouth_r
    geom(
        head,
        "mouth",
        type=capsule,
        size=[mouth_r, 0, 0],
        fromto=[
            face_x(-mouth_half, mouth_z) - 0.3 * mouth_r,
            -mouth_half,
            mouth_z,
            mouth_x,
            0.0,
            mouth_z,
        ],
        material=lips,
    )
    geom(
        head,
        "mouth_2",
        type=capsule,
        size=[mouth_r, 0, 0],
        fromto=[
            mouth_x,
            0.0,
            mouth_z,
            face_x(mouth_half, mouth_z) - 0.3 * mouth_r,
            mouth_half,
            mouth_z,
        ],
        material=lips,
    )

    # Face landmarks (BlazePose: 0 nose, 1-3 left eye inner/centre/outer, 4-6 right eye,
    # 7/8 ears, 9/10 mouth left/right).
    site(head, 0, [nose_x + 0.07 * hh, 0, nose_z - 0.02 * hh])
    for sign, (inner, centre, outer) in ((1.0, (1, 2, 3)), (-1.0, (4, 5, 6))):
        y = sign * eye_y
        site(head, inner, [face_x(y - sign * 0.8 * eye_r, eye_z), y - sign * 0.8 * eye_r, eye_z])
        site(head, centre, [face_x(y, eye_z) + 0.01 * hh, y, eye_z])
        site(head, outer, [face_x(y + sign * 0.8 * eye_r, eye_z), y + sign * 0.8 * eye_r, eye_z])
    site(head, 7, [0.0, 0.34 * hh, 0.45 * hh])
    site(head, 8, [0.0, -0.34 * hh, 0.45 * hh])
    site(head, 9, [face_x(mouth_half, mouth_z), mouth_half, mouth_z])
    site(head, 10, [face_x(-mouth_half, mouth_z), -mouth_half, mouth_z])

    # Arms.
    hinge = mujoco.mjtJoint.mjJNT_HINGE
    for side, sign, lm in (("l", 1.0, 0), ("r", -1.0, 1)):
        upper = torso.add_body(
            name=f"{prefix}upper_arm_{side}", pos=[-0.008 * b, sign * p.shoulder_half, shoulder_rel]
        )
        upper.add_joint(name=f"{prefix}shoulder_flex_{side}", type=hinge, axis=[0, -1, 0])
        upper.add_joint(name=f"{prefix}shoulder_abd_{side}", type=hinge, axis=[sign, 0, 0])
        r_ua = 0.026 * b
        geom(
            upper,
            f"sleeve_{side}",
            type=capsule,
            size=[r_ua * 1.12, 0, 0],
            fromto=[0, 0, 0, 0, 0, -0.5 * p.upper_arm],
            material=shirt,
        )
        geom(
            upper,
            f"upper_arm_{side}",
            type=capsule,
            size=[r_ua, 0, 0],
            fromto=[0, 0, 0, 0, 0, -p.upper_arm],
            material=shirt if look.long_sleeves else skin,
        )
        site(upper, 11 + lm, [0, 0, 0])
        fore = upper.add_body(name=f"{prefix}forearm_{side}", pos=[0, 0, -p.upper_arm])
        fore.add_joint(name=f"{prefix}elbow_{side}", type=hinge, axis=[0, -1, 0])
        geom(
            fore,
            f"forearm_{side}",
            type=capsule,
            size=[0.021 * b, 0, 0],
            fromto=[0, 0, 0, 0, 0, -p.forearm],
            material=forearm_mat,
        )
        site(fore, 13 + lm, [0, 0, 0])
        hand = fore.add_body(name=f"{prefix}hand_{side}", pos=[0, 0, -p.forearm])
        hand_w, hand_t = 0.24 * p.hand, 0.12 * p.hand
        geom(
            hand,
            f"hand_{side}",
            type=ellipsoid,
            size=[hand_w, hand_t, 0.46 * p.hand],
            pos=[0, 0, -0.42 * p.hand],
            material=skin,
        )
        # The thumb lies along the front of the hand when the arm hangs.
        geom(
            hand,
            f"thumb_{side}",
            type=capsule,
            size=[0.045 * p.hand, 0, 0],
            fromto=[0.75 * hand_w, 0, -0.12 * p.hand, 1.05 * hand_w, 0, -0.42 * p.hand],
            material=skin,
        )
        site(hand, 15 + lm, [0, 0, 0])
        site(hand, 17 + lm, [-0.6 * hand_w, 0, -0.6 * p.hand])  # pinky knuckle
        site(hand, 19 + lm, [0.6 * hand_w, 0, -0.65 * p.hand])  # index knuckle
        site(hand, 21 + lm, [1.05 * hand_w, 0, -0.42 * p.hand])  # thumb tip

    # Legs.
    for side, sign, lm in (("l", 1.0, 0), ("r", -1.0, 1)):
        thigh = pelvis.add_body(name=f"{prefix}thigh_{side}", pos=[0, sign * p.hip_half, 0])
        thigh.add_joint(name=f"{prefix}hip_flex_{side}", type=hinge, axis=[0, -1, 0])
        thigh.add_joint(name=f"{prefix}hip_abd_{side}", type=hinge, axis=[sign, 0, 0])
        geom(
            thigh,
            f"thigh_{side}",
            type=capsule,
            size=[0.037 * b, 0, 0],
            fromto=[0, 0, 0, 0, 0, -p.thigh],
            material=trousers,
        )
        geom(
            thigh,
            f"thigh_top_{side}",
            type=capsule,
            size=[0.045 * b, 0, 0],
            fromto=[0, sign * 0.004 * b, -0.02 * b, 0, 0, -0.45 * p.thigh],
            material=trousers,
        )
        site(thigh, 23 + lm, [0, 0, 0])
        shin = thigh.add_body(name=f"{prefix}shin_{side}", pos=[0, 0, -p.thigh])
        shin.add_joint(name=f"{prefix}knee_{side}", type=hinge, axis=[0, 1, 0])
        geom(
            shin,
            f"shin_{side}",
            type=capsule,
            size=[0.029 * b, 0, 0],
            fromto=[0, 0, 0, 0, 0, -p.shin],
            material=trousers,
        )
        geom(
            shin,
            f"calf_{side}",
            type=capsule,
            size=[0.033 * b, 0, 0],
            fromto=[-0.006 * b, 0, -0.1 * p.shin, -0.006 * b, 0, -0.45 * p.shin],
            material=trousers,
        )
        site(shin, 25 + lm, [0, 0, 0])
        foot = shin.add_body(name=f"{prefix}foot_{side}", pos=[0, 0, -p.shin])
        foot.add_joint(name=f"{prefix}ankle_{side}", type=hinge, axis=[0, -1, 0])
        # Shoe: a flat sole, a high heel counter and a lower toe box, so the foot shows
        # which way it points (a cue for telling a back view from a front view).
        shoe_w = 0.03 * b
        sole_h = 0.012 * b
        toe_end = p.foot - p.heel_back
        geom(
            foot,
            f"shoe_sole_{side}",
            type=box,
            size=[p.foot / 2, shoe_w, sole_h / 2],
            pos=[toe_end - p.foot / 2, 0, -p.ankle_z + sole_h / 2],
            material=shoes,
        )
        geom(
            foot,
            f"shoe_heel_{side}",
            type=ellipsoid,
            size=[0.24 * p.foot, shoe_w, 0.75 * p.ankle_z],
            pos=[-p.heel_back + 0.24 * p.foot, 0, -0.25 * p.ankle_z],
            material=shoes,
        )
        geom(
            foot,
            f"shoe_toe_{side}",
            type=ellipsoid,
            size=[0.42 * p.foot, 0.95 * shoe_w, 0.42 * p.ankle_z],
            pos=[toe_end - 0.42 * p.foot, 0, -0.58 * p.ankle_z],
            material=shoes,
        )
        site(foot, 27 + lm, [0, 0, 0])
        site(foot, 29 + lm, [-p.heel_back + 0.01 * b, 0, -p.ankle_z + 0.3 * p.ankle_z])
        site(foot, 31 + lm, [toe_end - 0.01 * b, 0, -p.ankle_z + 0.3 * p.ankle_z])


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
