"""Head yaw relative to the shoulders from BlazePose's ear and eye landmarks.

The same geometry as phi (orientation.py), which reads the shoulder line's depth: here
each left-to-right pair (shoulders, ears, eyes) gives a line across the body in the
camera's horizontal plane (image x, BlazePose z, both in pixels), and the head's yaw
is the angle from the shoulder line to the head's line. Lines are directed (the
person's left point minus the right one), so the angle has the full circle: it reads
the same seen from the front, the back or obliquely.

Sign: positive when the head is turned to the person's own left, as the simulator's
`head_yaw_shoulders` (sim/world/ground_truth.py). Why: with x right, y down and z away
from the camera, up is x cross z, so a turn to the left (counter-clockwise from above)
raises atan2(z, x) of every line across the body.

The nose is not used for the angle: its depth ahead of the ears enters with BlazePose's
z scale differently than a line across the head does, so mixing the two would bias the
angle wherever that scale is off; lines across shoulders and head share the same bias
and it cancels at zero yaw. Both ears are required (one BlazePose marks hidden gives
no head line; in practice it marks ears visible even in profile); the eyes add a second
head line when both are visible, which averages down their noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from monopic.features.window import SlidingWindow, median
from monopic.pose.skeleton import INDEX, LEFT_SHOULDER, RIGHT_SHOULDER

LEFT_EYE, RIGHT_EYE = INDEX["left_eye"], INDEX["right_eye"]
LEFT_EAR, RIGHT_EAR = INDEX["left_ear"], INDEX["right_ear"]
NOSE = INDEX["nose"]
# The head's proportions the image facing divides by (the ratio is what counts):
NOSE_AHEAD_M = 0.10  # ear axis to the nose tip, adult head (assumed)
EYE_SEPARATION_M = 0.063  # the adult mean interpupillary distance (Dodgson 2004)
# Below this BlazePose visibility a landmark is not trusted for the head yaw.
MIN_HEAD_VISIBILITY = 0.5


@dataclass(frozen=True)
class HeadYaw:
    """The head's yaw from the shoulders and how visible its landmarks were."""

    yaw: float  # deg in (-180, 180], + turned to the person's left; NaN when not visible
    visibility: float  # min BlazePose visibility of the ears and shoulders, 0-1


def _line_angle(left: np.ndarray, right: np.ndarray) -> float | None:
    """Angle (rad) of the directed line right -> left in the (x, z) plane; None if a point."""
    dx, dz = float(left[0] - right[0]), float(left[2] - right[2])
    if math.hypot(dx, dz) < 1e-9:
        return None
    return math.atan2(dz, dx)


def head_yaw(
    landmarks: np.ndarray, visibility: np.ndarray, min_visibility: float = MIN_HEAD_VISIBILITY
) -> HeadYaw:
    """Head yaw from (33, 3) landmarks (x, y, z in pixels, z as BlazePose scales it)."""
    vis = float(min(visibility[i] for i in (LEFT_EAR, RIGHT_EAR, LEFT_SHOULDER, RIGHT_SHOULDER)))
    nan = HeadYaw(float("nan"), vis)
    if not vis >= min_visibility:
        return nan
    shoulders = _line_angle(landmarks[LEFT_SHOULDER], landmarks[RIGHT_SHOULDER])
    ears = _line_angle(landmarks[LEFT_EAR], landmarks[RIGHT_EAR])
    if shoulders is None or ears is None:
        return nan
    heads = [ears]
    if min(visibility[LEFT_EYE], visibility[RIGHT_EYE]) >= min_visibility:
        eyes = _line_angle(landmarks[LEFT_EYE], landmarks[RIGHT_EYE])
        if eyes is not None:
            heads.append(eyes)
    # Circular mean of the head lines, then the signed angle from the shoulder line.
    head = math.atan2(sum(math.sin(a) for a in heads), sum(math.cos(a) for a in heads))
    d = math.degrees(head - shoulders)
    return HeadYaw(-((-d + 180.0) % 360.0 - 180.0), vis)


def head_facing(
    landmarks: np.ndarray, visibility: np.ndarray, min_visibility: float = MIN_HEAD_VISIBILITY
) -> float:
    """The head's facing from the camera (deg, 0 at it, + to the person's left), image x only.

    Why not depth: BlazePose's depths of points across the head follow a head turn by about
    a fifth at every distance (studies/intent/head_reading.py), while the image keeps it. Seen from
    the camera, the nose sits ahead of the ears' midpoint by NOSE_AHEAD_M sin(facing) and
    the eyes lie EYE_SEPARATION_M cos(facing) apart, left minus right (the person's left
    eye is on the image right when the face is toward the camera). NaN when the nose, an
    eye or an ear is below `min_visibility` (a head seen from behind).
    """
    idx = (NOSE, LEFT_EYE, RIGHT_EYE, LEFT_EAR, RIGHT_EAR)
    if not min(float(visibility[i]) for i in idx) >= min_visibility:
        return float("nan")
    ears_mid = (float(landmarks[LEFT_EAR, 0]) + float(landmarks[RIGHT_EAR, 0])) / 2
    ahead = (float(landmarks[NOSE, 0]) - ears_mid) / NOSE_AHEAD_M
    across = (float(landmarks[LEFT_EYE, 0]) - float(landmarks[RIGHT_EYE, 0])) / EYE_SEPARATION_M
    if math.hypot(ahead, across) < 1e-9:
        return float("nan")
    return math.degrees(math.atan2(ahead, across))


@dataclass
class HeadTurnWindow:
    """How far the head has turned toward the camera lately (deg, + toward it).

    A head check is a change while the walk keeps its line, so it is read as one: the
    median |facing| between `past_s` seconds ago less the median |facing| over the last
    `now_s` seconds. Medians, because one frame's facing scatters by 20-30 degrees on a
    walker. NaN until both windows hold enough samples; restart it with the track.
    """

    now_s: float = 0.15  # about 3 frames at 15 fps
    past_s: tuple[float, float] = (0.5, 1.5)  # a check lasts about a second (scenarios/README)
    min_now: int = 2
    min_past: int = 4
    _facings: SlidingWindow = field(init=False)

    def __post_init__(self) -> None:
        self._facings = SlidingWindow(self.past_s[1])

    def update(self, timestamp: float, facing: float) -> float:
        """Add this frame's facing (NaN: not seen) and return the turn toward the camera."""
        if math.isfinite(facing):
            self._facings.add(timestamp, abs(facing))
        samples = self._facings.first_values()  # Python floats: a few samples, no numpy
        start = timestamp - self.now_s - 1e-9
        far, near = timestamp - self.past_s[1] - 1e-9, timestamp - self.past_s[0] + 1e-9
        now = [v for t, v in samples if t >= start]
        past = [v for t, v in samples if far <= t <= near]
        if len(now) < max(self.min_now, 1) or len(past) < max(self.min_past, 1):
            return float("nan")  # (an empty median was NaN)
        return median(past) - median(now)

    def reset(self) -> None:
        self._facings.reset()
