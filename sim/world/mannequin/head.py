"""The mannequin's head: skull, jaw, hair and a face BlazePose can find.

The face is what the detector leans on most, so it carries eyes with irises, eyebrows,
ears, a nose and a mouth, each set on the face's surface (`Face.front_x`) so that none
floats in front of the skin or sinks into it. The face landmarks (0-10) sit on the same
surface, where a tracker would put them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from sim.world.mannequin.parts import ELLIPSOID, SIDES, SPHERE, Parts


@dataclass(frozen=True)
class Face:
    """Where the head's shapes and features sit, in the head frame (origin at the chin).

    x is forward, z up; every figure is a fraction of `hh`, the chin-to-crown height.
    """

    hh: float

    @property
    def skull(self) -> tuple[np.ndarray, np.ndarray]:
        """Centre and semi-axes of the skull ellipsoid."""
        hh = self.hh
        return np.array([0.03 * hh, 0.0, 0.5 * hh]), np.array([0.42 * hh, 0.33 * hh, 0.49 * hh])

    @property
    def jaw(self) -> tuple[np.ndarray, np.ndarray]:
        """Centre and semi-axes of the jaw: narrower than the skull, it shapes the face."""
        hh = self.hh
        return np.array([0.08 * hh, 0.0, 0.22 * hh]), np.array([0.28 * hh, 0.26 * hh, 0.2 * hh])

    def front_x(self, y: float, z: float) -> float:
        """x of the face's front surface (skull or jaw) at (y, z) in the head frame."""
        front = -math.inf
        for c, size in (self.skull, self.jaw):
            r = 1.0 - ((y - c[1]) / size[1]) ** 2 - ((z - c[2]) / size[2]) ** 2
            if r >= 0:
                front = max(front, float(c[0] + size[0] * math.sqrt(r)))
        return front

    @property
    def eye_z(self) -> float:
        return 0.5 * self.hh

    @property
    def eye_y(self) -> float:
        return 0.135 * self.hh

    @property
    def eye_r(self) -> float:
        """Half width of the visible eye."""
        return 0.075 * self.hh

    @property
    def nose_z(self) -> float:
        return 0.36 * self.hh

    @property
    def mouth_z(self) -> float:
        return 0.2 * self.hh

    @property
    def mouth_half(self) -> float:
        return 0.085 * self.hh

    @property
    def mouth_r(self) -> float:
        return 0.028 * self.hh


def add_head(parts: Parts, torso: mujoco.MjsBody) -> None:
    """The head on its neck joint at chin height, with its face and face landmarks.

    The parts go on in a fixed order (skull and hair, eyes, nose and mouth, landmarks):
    MuJoCo numbers geoms and sites in the order they are added.
    """
    p = parts.p
    head = parts.body(torso, "head", pos=[0, 0, p.chin_z - p.waist_z])
    parts.hinge(head, "neck_yaw", axis=[0, 0, 1])
    parts.hinge(head, "neck_pitch", axis=[0, 1, 0])
    face = Face(p.head)
    _skull_and_hair(parts, head, face)
    _eyes_brows_ears(parts, head, face)
    _nose_and_mouth(parts, head, face)
    _face_landmarks(parts, head, face)


def _skull_and_hair(parts: Parts, head: mujoco.MjsBody, face: Face) -> None:
    """Skull and jaw in skin, then hair as a cap over the crown and the back of the head.

    The hair leaves the forehead and face bare, so from the front the face reads as
    skin and from behind the head reads as hair (a cue for which way the person faces).
    """
    hh, skin, hair = face.hh, parts.mat.skin, parts.mat.hair
    (skull_c, skull_size), (jaw_c, jaw_size) = face.skull, face.jaw
    parts.ellipsoid(head, "head", size=skull_size.tolist(), pos=skull_c.tolist(), material=skin)
    parts.ellipsoid(head, "jaw", size=jaw_size.tolist(), pos=jaw_c.tolist(), material=skin)
    tilt = 0.35  # rad: the cap's front edge rides up, baring the forehead
    parts.geom(
        head,
        "hair_cap",
        type=ELLIPSOID,
        size=[0.43 * hh, 0.345 * hh, 0.36 * hh],
        pos=[-0.02 * hh, 0, 0.66 * hh],
        quat=_quat_from_axes(
            np.array([math.cos(tilt), 0, math.sin(tilt)]),
            np.array([-math.sin(tilt), 0, math.cos(tilt)]),
        ).tolist(),
        material=hair,
    )
    parts.ellipsoid(
        head,
        "hair_back",
        size=[0.34 * hh, 0.335 * hh, 0.4 * hh],
        pos=[-0.1 * hh, 0, 0.52 * hh],
        material=hair,
    )


def _eyes_brows_ears(parts: Parts, head: mujoco.MjsBody, face: Face) -> None:
    """Per side: the eye white, the iris in front of it, the eyebrow above it, the ear.

    The eye white bulges a little out of the face surface and the iris a little further,
    so from the front both show: a dark disc in a pale almond, as a real eye does.
    """
    hh, mat = face.hh, parts.mat
    eye_z = face.eye_z
    for side in SIDES:
        y = side.sign * face.eye_y
        x = face.front_x(y, eye_z)
        parts.ellipsoid(
            head,
            f"eye_{side.name}",
            size=[0.03 * hh, face.eye_r, 0.042 * hh],
            pos=[x - 0.012 * hh, y, eye_z],
            material=mat.eye_white,
        )
        parts.geom(
            head,
            f"iris_{side.name}",
            type=SPHERE,
            size=[0.036 * hh, 0, 0],
            pos=[x - 0.008 * hh, y, eye_z],
            material=mat.iris,
        )
        brow_z = eye_z + 0.13 * hh
        inner_y, outer_y = side.sign * 0.07 * hh, side.sign * 0.22 * hh
        parts.capsule(
            head,
            f"brow_{side.name}",
            0.02 * hh,
            fromto=[
                face.front_x(inner_y, brow_z),
                inner_y,
                brow_z,
                face.front_x(outer_y, brow_z),
                outer_y,
                brow_z - 0.02 * hh,
            ],
            material=mat.hair,
        )
        parts.ellipsoid(
            head,
            f"ear_{side.name}",
            size=[0.08 * hh, 0.035 * hh, 0.13 * hh],
            pos=[0.0, side.sign * 0.32 * hh, 0.45 * hh],
            material=mat.skin_dark,
        )


def _nose_and_mouth(parts: Parts, head: mujoco.MjsBody, face: Face) -> None:
    """The nose on the face's centre line, and the lips as two capsules meeting there.

    Two capsules, each from a mouth corner to the centre, follow the face's curve: the
    corners sit further back than the middle of the mouth.
    """
    hh, mat = face.hh, parts.mat
    nose_z = face.nose_z
    parts.ellipsoid(
        head,
        "nose",
        size=[0.07 * hh, 0.045 * hh, 0.1 * hh],
        pos=[face.front_x(0.0, nose_z), 0, nose_z],
        material=mat.skin_dark,
    )
    z, half, r = face.mouth_z, face.mouth_half, face.mouth_r
    mid = [face.front_x(0.0, z) - 0.3 * r, 0.0, z]
    right = [face.front_x(-half, z) - 0.3 * r, -half, z]
    left = [face.front_x(half, z) - 0.3 * r, half, z]
    parts.capsule(head, "mouth", r, fromto=right + mid, material=mat.lips)
    parts.capsule(head, "mouth_2", r, fromto=mid + left, material=mat.lips)


def _face_landmarks(parts: Parts, head: mujoco.MjsBody, face: Face) -> None:
    """BlazePose's face landmarks on the face's surface.

    0 nose, 1-3 left eye inner/centre/outer, 4-6 right eye, 7/8 ears, 9/10 mouth
    left/right; the eye corners sit on the surface at 0.8 of the eye's half width.
    """
    hh, eye_z = face.hh, face.eye_z
    nose_z = face.nose_z
    parts.site(head, 0, [face.front_x(0.0, nose_z) + 0.07 * hh, 0, nose_z - 0.02 * hh])
    for side, first in zip(SIDES, (1, 4), strict=True):
        y = side.sign * face.eye_y
        inner_y = y - side.sign * 0.8 * face.eye_r
        outer_y = y + side.sign * 0.8 * face.eye_r
        parts.site(head, first, [face.front_x(inner_y, eye_z), inner_y, eye_z])
        parts.site(head, first + 1, [face.front_x(y, eye_z) + 0.01 * hh, y, eye_z])
        parts.site(head, first + 2, [face.front_x(outer_y, eye_z), outer_y, eye_z])
    parts.site(head, 7, [0.0, 0.34 * hh, 0.45 * hh])
    parts.site(head, 8, [0.0, -0.34 * hh, 0.45 * hh])
    z, half = face.mouth_z, face.mouth_half
    parts.site(head, 9, [face.front_x(half, z), half, z])
    parts.site(head, 10, [face.front_x(-half, z), -half, z])


def _quat_from_axes(x_axis: np.ndarray, z_axis: np.ndarray) -> np.ndarray:
    """Quaternion of the frame whose x and z axes are given (y completes it)."""
    x = x_axis / np.linalg.norm(x_axis)
    z = z_axis / np.linalg.norm(z_axis)
    y = np.cross(z, x)
    mat = np.column_stack([x, y, z]).reshape(-1)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat)
    return quat
