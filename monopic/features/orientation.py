"""The paper's facing angle phi from the two shoulder landmarks.

Camera look-at rotation matrix from the shoulders, quaternion by the paper's equations
3-6, theta = arccos(a / |Q|), phi = theta * 180/pi * 4 - 180.

What phi measures: with the look-at rows (s, u, -f), f the unit vector from the left to
the right shoulder and up the image's y axis, the rotation angle is 90 degrees plus the
yaw beta of the shoulder line out of the image plane, so phi = 2 * beta for
beta in [-90, 90]: 0 when the shoulders are square to the camera (facing it or facing
away), +-180 in profile. The authors fitted the linear correction on theta in [45, 90]
(phi in [0, 180]); theta below 45 degrees gives negative phi, which we keep (their
discretiser puts it in its own bin). theta never leaves [0, 90] because a >= 0, so phi
stays in [-180, 180]. Where a is (almost) zero, equations 4-6 divide by zero: the view is
a pure profile, theta is 90 degrees and phi is 180, which we return directly.
"""

from __future__ import annotations

import math

import numpy as np

UP = np.array([0.0, 1.0, 0.0])
_EPS = 1e-9


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """np.cross of two 3-vectors, term for term the same floats, in 2 us against its 21
    (its axis handling), and the stage after pose calls it twice a frame
    (`bench/post_pose.py`)."""
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    return np.array([x, y, a[0] * b[1] - a[1] * b[0]])


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray = UP) -> np.ndarray | None:
    """3x3 look-at rotation (rows s, u, -f); None when eye and target coincide or f || up."""
    f = np.asarray(target, dtype=float) - np.asarray(eye, dtype=float)
    n = np.linalg.norm(f)
    if n < _EPS:
        return None
    f /= n
    s = _cross(f, up)
    ns = np.linalg.norm(s)
    if ns < _EPS:
        return None
    s /= ns
    u = _cross(s, f)
    return np.stack([s, u, -f])


def quaternion(r: np.ndarray) -> tuple[float, float, float, float]:
    """(a, b, c, d) from a rotation matrix by the paper's equations 3-6.

    For a pure profile (a == 0) b, c, d are undefined by those equations: they are
    returned as 0 and a as 0, which keeps theta at 90 degrees.
    """
    a = 0.5 * math.sqrt(abs(1.0 + r[0, 0] + r[1, 1] + r[2, 2]))
    if a < _EPS:
        return 0.0, 0.0, 0.0, 0.0
    b = (r[2, 1] - r[1, 2]) / (4 * a)
    c = (r[0, 2] - r[2, 0]) / (4 * a)
    d = (r[1, 0] - r[0, 1]) / (4 * a)
    return a, b, c, d


def theta_from_quaternion(q: tuple[float, float, float, float]) -> float:
    """theta = arccos(a / |Q|) in radians; pi/2 for the degenerate profile quaternion."""
    a, b, c, d = q
    norm = math.sqrt(a * a + b * b + c * c + d * d)
    if norm < _EPS:
        return math.pi / 2
    return math.acos(min(1.0, max(-1.0, a / norm)))


def phi_from_theta(theta: float) -> float:
    """The paper's linear correction, equation 14, in degrees."""
    return theta * 180.0 / math.pi * 4.0 - 180.0


def facing_angle(left_shoulder: np.ndarray, right_shoulder: np.ndarray) -> float:
    """phi in degrees from two (x, y, z) shoulder points in one pixel-like unit; NaN if degenerate.

    MediaPipe's z is scaled like its normalised x, so pass (x_px, y_px, z * image_width).
    """
    r = look_at(left_shoulder, right_shoulder)
    if r is None:
        return float("nan")
    return phi_from_theta(theta_from_quaternion(quaternion(r)))
