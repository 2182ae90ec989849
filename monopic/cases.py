"""The one vocabulary of motion cases, and the functions that label motion with it.

Numbering and names follow the MonoPIC paper (section "ID3 Classification"). "Right" and
"left" are the camera's right and left; "away" is in the direction of the camera's motion
(along its optical axis), "toward" against it. Everyone in the project (pipeline, tree,
simulator ground truth, reports) labels motion with the functions here, so that a case
means the same thing everywhere.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import IntEnum

import numpy as np


class Case(IntEnum):
    """The paper's nine motion cases."""

    OBLIQUE_RIGHT_AWAY = 1
    OBLIQUE_LEFT_AWAY = 2
    OBLIQUE_RIGHT_TOWARD = 3
    OBLIQUE_LEFT_TOWARD = 4
    PERPENDICULAR_RIGHT = 5
    PERPENDICULAR_LEFT = 6
    TOWARD = 7
    AWAY = 8
    STILL = 9

    @property
    def label(self) -> str:
        """Short human-readable name, e.g. 'oblique right away'."""
        return self.name.lower().replace("_", " ")

    @property
    def lateral(self) -> int:
        """+1 moving to the camera's right, -1 to its left, 0 neither."""
        return _GRID[self][0]

    @property
    def depth(self) -> int:
        """+1 moving away from the camera (along its motion), -1 toward it, 0 neither."""
        return _GRID[self][1]

    @classmethod
    def from_signs(cls, lateral: int, depth: int) -> Case:
        """The case whose (lateral, depth) sign pattern is given."""
        return _FROM_GRID[(int(np.sign(lateral)), int(np.sign(depth)))]


# (lateral: +1 right / -1 left, depth: +1 away / -1 toward) for every case.
_GRID: dict[Case, tuple[int, int]] = {
    Case.OBLIQUE_RIGHT_AWAY: (1, 1),
    Case.OBLIQUE_LEFT_AWAY: (-1, 1),
    Case.OBLIQUE_RIGHT_TOWARD: (1, -1),
    Case.OBLIQUE_LEFT_TOWARD: (-1, -1),
    Case.PERPENDICULAR_RIGHT: (1, 0),
    Case.PERPENDICULAR_LEFT: (-1, 0),
    Case.TOWARD: (0, -1),
    Case.AWAY: (0, 1),
    Case.STILL: (0, 0),
}
_FROM_GRID = {signs: case for case, signs in _GRID.items()}

# The authors' code numbers directions on the image: 1 up-right, 2 down-left,
# 3 down-right, 4 up-left, 5 right, 6 left, 7 up, 8 down, 9 still. With a static camera
# "up" on the image is away from the camera and "down" is toward it.
AUTHORS_TO_CASE: dict[int, Case] = {
    1: Case.OBLIQUE_RIGHT_AWAY,
    2: Case.OBLIQUE_LEFT_TOWARD,
    3: Case.OBLIQUE_RIGHT_TOWARD,
    4: Case.OBLIQUE_LEFT_AWAY,
    5: Case.PERPENDICULAR_RIGHT,
    6: Case.PERPENDICULAR_LEFT,
    7: Case.AWAY,
    8: Case.TOWARD,
    9: Case.STILL,
}
CASE_TO_AUTHORS: dict[Case, int] = {case: code for code, case in AUTHORS_TO_CASE.items()}

# A component of motion counts only if it is at least tan(22.5 deg) of the other one:
# this turns the sign grid into eight 45-degree sectors centred on the eight directions.
SECTOR_RATIO = math.tan(math.radians(22.5))

# Below this ground speed (m/s) a pedestrian is "not moving significantly". Slow walking
# is about 0.8 m/s; standing sway and stepping on the spot stay well below 0.3 m/s.
GROUND_DEAD_ZONE_MPS = 0.3


def case_from_components(
    lateral: float, depth: float, dead_zone: float, ratio: float = SECTOR_RATIO
) -> Case:
    """Label a motion from its right-ward and away-ward components.

    Below `dead_zone` in magnitude the motion is STILL; otherwise each component counts
    when it is at least `ratio` times the other, which gives eight equal 45-degree sectors
    when both components are in the same unit.
    """
    if not (math.isfinite(lateral) and math.isfinite(depth)):
        raise ValueError(f"motion components must be finite, got ({lateral}, {depth})")
    if math.hypot(lateral, depth) < dead_zone:
        return Case.STILL
    lat = np.sign(lateral) if abs(lateral) >= ratio * abs(depth) else 0
    dep = np.sign(depth) if abs(depth) >= ratio * abs(lateral) else 0
    return Case.from_signs(int(lat), int(dep))


def case_from_ground_velocity(
    forward: float, left: float, dead_zone: float = GROUND_DEAD_ZONE_MPS
) -> Case:
    """Label a ground-plane velocity given in the camera's frame (x forward, y left), m/s.

    The velocity must be the pedestrian's own motion over the ground expressed in the
    camera's axes, not the motion relative to a moving camera: a person standing still in
    front of a moving robot is STILL, not TOWARD.
    """
    return case_from_components(lateral=-left, depth=forward, dead_zone=dead_zone)


@dataclass(frozen=True)
class ImageTrackThresholds:
    """Dead zones for labelling an image track, in body heights per second.

    The lateral rate is the foot point's horizontal image speed divided by the apparent
    height (for a person at any distance it equals the lateral ground speed over the
    person's height). The depth rate adds the foot point's downward image speed to the
    growth of the apparent height, both over the apparent height: positive when the
    person comes toward a static camera.
    """

    lateral: float = 0.15
    depth: float = 0.05


def case_from_image_track(
    times: Sequence[float],
    foot_u: Sequence[float],
    foot_v: Sequence[float],
    height: Sequence[float],
    thresholds: ImageTrackThresholds | None = None,
) -> Case:
    """Label the motion of an image track seen by a static camera.

    Right/left comes from the foot point moving right/left on the image; toward/away from
    the foot point moving down/up together with the apparent height growing/shrinking.
    Rates are least-squares slopes over the whole track, so the track should span the
    interval being labelled (e.g. the next second of motion).
    """
    th = thresholds or ImageTrackThresholds()
    t = np.asarray(times, dtype=float)
    if t.size < 2 or not np.all(np.isfinite(t)) or t[-1] - t[0] <= 0:
        raise ValueError("an image track needs at least two finite, increasing times")
    u, v, h = (np.asarray(a, dtype=float) for a in (foot_u, foot_v, height))
    if not (u.shape == v.shape == h.shape == t.shape):
        raise ValueError("times, foot_u, foot_v and height must have the same length")
    mean_h = float(np.mean(h))
    if not mean_h > 0:
        raise ValueError(f"apparent height must be positive, got mean {mean_h}")
    lateral = _slope(t, u) / mean_h
    approach = (_slope(t, v) + _slope(t, h)) / mean_h
    lat = _signed_component(lateral, approach, th.lateral, th.depth)
    dep = _signed_component(approach, lateral, th.depth, th.lateral)
    return Case.from_signs(lat, -dep)


def _signed_component(value: float, other: float, dead: float, other_dead: float) -> int:
    """Sign of a component that clears its dead zone and is not dwarfed by the other.

    The two rates are in different units, so "dwarfed" compares each to its own dead
    zone: a component counts if its multiple of its own dead zone is at least
    SECTOR_RATIO times the other's.
    """
    if abs(value) < dead:
        return 0
    if abs(value) / dead < SECTOR_RATIO * abs(other) / other_dead:
        return 0
    return int(np.sign(value))


def _slope(t: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope dy/dt."""
    tc = t - t.mean()
    return float(np.dot(tc, y - y.mean()) / np.dot(tc, tc))
