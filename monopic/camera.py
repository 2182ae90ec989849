"""The camera model a real robot knows about itself: intrinsics and mounting.

Frames used throughout the project:
- robot frame: origin on the ground below the robot's reference point, x forward,
  y left, z up (metres);
- camera optical frame: x right, y down, z along the optical axis;
- image: u right, v down, pixels, origin at the top-left pixel's corner.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CameraModel:
    """Pinhole camera mounted on the robot, pitched down by `pitch` radians."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    mount_height: float  # metres above the ground
    pitch: float = 0.0  # radians, positive looks down
    mount_forward: float = 0.0  # metres ahead of the robot's reference point

    def __post_init__(self) -> None:
        if self.width <= 0 or self.height <= 0:
            raise ValueError(f"image size must be positive, got {self.width}x{self.height}")
        if not (self.fx > 0 and self.fy > 0):
            raise ValueError(f"focal lengths must be positive, got fx={self.fx}, fy={self.fy}")
        if not self.mount_height > 0:
            raise ValueError(f"mount_height must be positive, got {self.mount_height}")

    @classmethod
    def from_fov(
        cls,
        width: int,
        height: int,
        vertical_fov_deg: float,
        mount_height: float,
        pitch_deg: float = 0.0,
        mount_forward: float = 0.0,
    ) -> CameraModel:
        """Square pixels, principal point at the image centre, given vertical field of view."""
        if not 0 < vertical_fov_deg < 180:
            raise ValueError(f"vertical_fov_deg must be in (0, 180), got {vertical_fov_deg}")
        f = (height / 2) / math.tan(math.radians(vertical_fov_deg) / 2)
        return cls(
            width=width,
            height=height,
            fx=f,
            fy=f,
            cx=width / 2,
            cy=height / 2,
            mount_height=mount_height,
            pitch=math.radians(pitch_deg),
            mount_forward=mount_forward,
        )

    @property
    def vertical_fov_deg(self) -> float:
        return math.degrees(2 * math.atan((self.height / 2) / self.fy))

    @property
    def position(self) -> np.ndarray:
        """Optical centre in the robot frame."""
        return np.array([self.mount_forward, 0.0, self.mount_height])

    @property
    def axes(self) -> np.ndarray:
        """Rows: the optical x (right), y (down) and z (forward) axes in the robot frame."""
        s, c = math.sin(self.pitch), math.cos(self.pitch)
        return np.array([[0.0, -1.0, 0.0], [-s, 0.0, -c], [c, 0.0, -s]])

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """Robot-frame points (..., 3) to the optical frame (..., 3)."""
        return (np.asarray(points, dtype=float) - self.position) @ self.axes.T

    def project(self, points: np.ndarray) -> np.ndarray:
        """Robot-frame points (..., 3) to pixels (..., 2); NaN for points behind the camera."""
        pc = self.to_camera(points)
        z = pc[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.where(z > 1e-9, self.fx * pc[..., 0] / z + self.cx, np.nan)
            v = np.where(z > 1e-9, self.fy * pc[..., 1] / z + self.cy, np.nan)
        return np.stack([u, v], axis=-1)

    def ground_point(self, pixels: np.ndarray) -> np.ndarray:
        """Pixels (..., 2) to the ground point (x forward, y left) they see, (..., 2).

        NaN where the ray does not meet the ground in front of the camera (at or above
        the horizon).
        """
        px = np.asarray(pixels, dtype=float)
        xn = (px[..., 0] - self.cx) / self.fx
        yn = (px[..., 1] - self.cy) / self.fy
        ax = self.axes
        rays = xn[..., None] * ax[0] + yn[..., None] * ax[1] + ax[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(rays[..., 2] < -1e-9, -self.mount_height / rays[..., 2], np.nan)
        ground = self.position[:2] + t[..., None] * rays[..., :2]
        return ground

    def horizon_v(self) -> float:
        """Image row of the horizon (may lie outside the image)."""
        return self.cy - self.fy * math.tan(self.pitch)
