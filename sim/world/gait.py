"""A kinematic walking gait: joint angles as smooth periodic functions of the gait phase.

No physics: the mannequin is posed directly. The curves follow the shape of normal
human gait in the sagittal plane (hip flexion peaking at heel strike, knee flexing about
15 degrees in loading and about 60 degrees in swing, ankle push-off, arms swinging
against the legs, pelvis and chest counter-rotating). Amplitudes, stride length and
cadence follow walking speed and body size with dynamic similarity (the same Froude
number gives the same gait shape), so an adult at 1.4 m/s takes about 1.8 steps per
second and a child of 1.15 m at the same speed takes shorter, quicker steps.

Phase convention: the phase runs over one stride (two steps) in [0, 1); phase 0 is the
heel strike of the person's left foot, phase 0.5 that of the right foot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.scenario.stride import ADULT_HEIGHT, IDLE_SPEED, REF_CADENCE, REF_SPEED, step_length

G = 9.81  # m/s^2


@dataclass(frozen=True)
class MannequinPose:
    """Joint angles (radians) and the pelvis' sideways sway (metres) of one frame.

    Signs: flexion is positive (hip and shoulder bring the limb forward, knee and elbow
    bend, ankle lifts the toes), abduction moves the limb away from the body on either
    side, yaw turns to the person's left, pitch leans or nods forward. `_l` and `_r`
    are the person's own left and right.
    """

    pelvis_yaw: float = 0.0
    sway: float = 0.0
    waist_yaw: float = 0.0
    waist_pitch: float = 0.0
    neck_yaw: float = 0.0
    neck_pitch: float = 0.0
    hip_flex_l: float = 0.0
    hip_abd_l: float = 0.0
    knee_l: float = 0.0
    ankle_l: float = 0.0
    shoulder_flex_l: float = 0.0
    shoulder_abd_l: float = 0.0
    elbow_l: float = 0.0
    hip_flex_r: float = 0.0
    hip_abd_r: float = 0.0
    knee_r: float = 0.0
    ankle_r: float = 0.0
    shoulder_flex_r: float = 0.0
    shoulder_abd_r: float = 0.0
    elbow_r: float = 0.0


# Joint fields of MannequinPose (everything but the root's yaw and sway).
JOINT_FIELDS: tuple[str, ...] = tuple(
    name for name in MannequinPose.__dataclass_fields__ if name not in ("pelvis_yaw", "sway")
)


def _bump(phase: float, centre: float, width: float) -> float:
    """Periodic Gaussian bump over the stride, 1 at `centre`."""
    d = (phase - centre + 0.5) % 1.0 - 0.5
    return math.exp(-((d / width) ** 2))


@dataclass(frozen=True)
class Gait:
    """Walking kinematics for a body of the given height (m)."""

    height: float = ADULT_HEIGHT
    ref_speed: float = REF_SPEED  # m/s, comfortable adult walking speed
    ref_cadence: float = REF_CADENCE  # steps/s at ref_speed for an adult of ADULT_HEIGHT

    @property
    def size_ratio(self) -> float:
        return self.height / ADULT_HEIGHT

    @property
    def ref_step(self) -> float:
        """Step length (m) at this body's comfortable speed."""
        return self.ref_speed / self.ref_cadence * self.size_ratio

    def step_length(self, speed: float) -> float:
        """Step length (m); grows with the square root of the size-normalised speed."""
        return step_length(speed, self.height, self.ref_speed, self.ref_cadence)

    def cadence(self, speed: float) -> float:
        """Steps per second at `speed` (0 when idle)."""
        step = self.step_length(speed)
        return speed / step if step > 0 else 0.0

    def advance(self, phase: float, speed: float, dt: float) -> float:
        """The gait phase `dt` seconds later when walking at `speed`."""
        return (phase + dt * self.cadence(speed) / 2.0) % 1.0

    def amplitude(self, speed: float) -> float:
        """Gait amplitude: 1 at the comfortable speed, smaller when slower."""
        if self.ref_step <= 0:
            return 0.0
        return min(self.step_length(speed) / self.ref_step, 1.3)

    def pose(self, phase: float, speed: float) -> MannequinPose:
        """Joint angles at `phase` of the stride when walking at `speed` m/s."""
        if speed <= IDLE_SPEED:
            return idle_pose()
        a = self.amplitude(speed)
        ph_l = phase % 1.0
        ph_r = (phase + 0.5) % 1.0
        leg_l = _leg(ph_l, a)
        leg_r = _leg(ph_r, a)
        arm_l = _arm(ph_l, a)
        arm_r = _arm(ph_r, a)
        swing = math.cos(2 * math.pi * ph_l)
        pelvis_yaw = -math.radians(5.0) * a * swing  # left hip forward at phase 0
        waist_yaw = -1.6 * pelvis_yaw  # chest turns against the pelvis
        waist_pitch = math.radians(3.0) * a
        return MannequinPose(
            pelvis_yaw=pelvis_yaw,
            sway=0.02 * self.size_ratio * a * math.sin(2 * math.pi * ph_l),
            waist_yaw=waist_yaw,
            waist_pitch=waist_pitch,
            neck_yaw=-(pelvis_yaw + waist_yaw),  # keep looking where the body goes
            neck_pitch=-waist_pitch,
            hip_flex_l=leg_l[0],
            hip_abd_l=math.radians(2.0),
            knee_l=leg_l[1],
            ankle_l=leg_l[2],
            shoulder_flex_l=arm_l[0],
            shoulder_abd_l=math.radians(8.0),
            elbow_l=arm_l[1],
            hip_flex_r=leg_r[0],
            hip_abd_r=math.radians(2.0),
            knee_r=leg_r[1],
            ankle_r=leg_r[2],
            shoulder_flex_r=arm_r[0],
            shoulder_abd_r=math.radians(8.0),
            elbow_r=arm_r[1],
        )


def _leg(phase: float, a: float) -> tuple[float, float, float]:
    """(hip flexion, knee flexion, ankle dorsiflexion) in radians for one leg."""
    hip = min(22.0 * a, 26.0) * math.cos(2 * math.pi * phase) + 2.0 * a
    knee = (
        3.0
        + 15.0 * a * _bump(phase, 0.15, 0.08)
        + (38.0 + 22.0 * min(a, 1.2)) * _bump(phase, 0.72, 0.11)
    )
    ankle = a * (
        -5.0 * _bump(phase, 0.04, 0.04)
        + 10.0 * _bump(phase, 0.42, 0.12)
        - 18.0 * _bump(phase, 0.62, 0.06)
        + 3.0 * _bump(phase, 0.85, 0.10)
    )
    return math.radians(hip), math.radians(knee), math.radians(ankle)


def _arm(phase: float, a: float) -> tuple[float, float]:
    """(shoulder flexion, elbow flexion) in radians; the arm swings against its leg."""
    c = math.cos(2 * math.pi * phase)
    shoulder = -18.0 * a * c
    elbow = 12.0 + 20.0 * a * (1.0 - c) / 2.0
    return math.radians(shoulder), math.radians(elbow)


def idle_pose() -> MannequinPose:
    """Standing relaxed: arms hanging slightly away from the body, knees soft."""
    return MannequinPose(
        hip_abd_l=math.radians(3.0),
        hip_abd_r=math.radians(3.0),
        knee_l=math.radians(3.0),
        knee_r=math.radians(3.0),
        ankle_l=math.radians(3.0),  # keeps the soles flat with the knees soft
        ankle_r=math.radians(3.0),
        shoulder_abd_l=math.radians(7.0),
        shoulder_abd_r=math.radians(7.0),
        elbow_l=math.radians(12.0),
        elbow_r=math.radians(12.0),
        shoulder_flex_l=math.radians(2.0),
        shoulder_flex_r=math.radians(2.0),
    )


def pose_vector(pose: MannequinPose) -> np.ndarray:
    """The joint angles of `pose` in JOINT_FIELDS order."""
    return np.array([getattr(pose, name) for name in JOINT_FIELDS])
