"""A person's box in motion: a constant-velocity Kalman filter on its centre and height.

Between the frames where a person's landmarks are run (the budget spreads them) and
through short occlusions, the box has to move on its own: association compares each
detection with where the person should be now, not where they were last seen. Centre and
height carry velocities (height: people walking toward the camera grow); the width follows
the measured ones smoothed, as people's aspect barely changes. Noise scales with the
person's height, so one filter fits people 30 and 300 px tall:
- acceleration: a walker changes velocity by about 1.5 m/s within a second, about 0.9 of
  their height per second squared;
- measurement: a detection's box is good to about 8 % of the height (the detector's
  keypoints), a pose's to about 3 %.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from monopic.people.box import Box

ACCELERATION = 0.9  # heights / s^2
DETECTION_NOISE = 0.08  # heights
POSE_NOISE = 0.03
WIDTH_SMOOTHING = 0.3  # weight of a new width measurement


@dataclass
class BoxMotion:
    """State x = (cx, cy, h, vx, vy, vh) in pixels and pixels per second."""

    box: Box
    time: float
    x: np.ndarray = field(init=False)
    p: np.ndarray = field(init=False)
    width: float = field(init=False)

    def __post_init__(self) -> None:
        x0, y0, x1, y1 = self.box
        h = y1 - y0
        self.x = np.array([(x0 + x1) / 2, (y0 + y1) / 2, h, 0.0, 0.0, 0.0])
        # A new person's velocity is unknown up to a brisk walk: about a height a second.
        self.p = np.diag([(0.1 * h) ** 2] * 3 + [h**2] * 3)
        self.width = x1 - x0

    def predict(self, time: float) -> Box:
        """Move the state to `time` (s) and return the box expected there."""
        dt = max(time - self.time, 0.0)
        if dt > 0:
            f = np.eye(6)
            f[:3, 3:] = np.eye(3) * dt
            q_std = ACCELERATION * max(self.x[2], 1.0)
            g = np.vstack([np.eye(3) * dt**2 / 2, np.eye(3) * dt])
            self.x = f @ self.x
            self.p = f @ self.p @ f.T + g @ g.T * q_std**2
            self.time = time
        return self.current()

    def update(self, box: Box, noise: float) -> None:
        """Fold in a measured box, with `noise` in heights (DETECTION_NOISE, POSE_NOISE)."""
        x0, y0, x1, y1 = box
        z = np.array([(x0 + x1) / 2, (y0 + y1) / 2, y1 - y0])
        r = np.eye(3) * (noise * max(z[2], 1.0)) ** 2
        h = np.hstack([np.eye(3), np.zeros((3, 3))])
        s = h @ self.p @ h.T + r
        k = self.p @ h.T @ np.linalg.inv(s)
        self.x = self.x + k @ (z - h @ self.x)
        self.p = (np.eye(6) - k @ h) @ self.p
        self.width += WIDTH_SMOOTHING * ((x1 - x0) - self.width)

    def current(self) -> Box:
        cx, cy, h = self.x[:3]
        h = max(h, 1.0)
        return cx - self.width / 2, cy - h / 2, cx + self.width / 2, cy + h / 2

    @property
    def velocity(self) -> tuple[float, float]:
        """The centre's image velocity, px/s."""
        return float(self.x[3]), float(self.x[4])

    def position_spread(self) -> float:
        """Two standard deviations of the centre's position (px, the larger axis)."""
        return float(2.0 * np.sqrt(max(self.p[0, 0], self.p[1, 1])))
