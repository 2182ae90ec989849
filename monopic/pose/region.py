"""Rotated square regions of interest, as MediaPipe builds them, and the crops they define.

A region is a square in pixels, centred on a body point and rotated so that the body's
axis (hip -> shoulder-ish keypoint) points up in the crop. Rotation follows MediaPipe:
r = target - atan2(-(y1 - y0), x1 - x0) with target 90 degrees, so an upright person has
r = 0; a crop point p (0..size) maps to the image as C + Rot(r) @ (p / size - 0.5) * side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from monopic.pose.warp import WarpBuffers, warp

# MediaPipe's pose graphs enlarge the keypoint-aligned square by 1.25 on each side.
DEFAULT_SCALE = 1.25


@dataclass(frozen=True)
class Region:
    """Square region: centre (px), side (px), rotation (rad, MediaPipe convention)."""

    cx: float
    cy: float
    side: float
    rotation: float = 0.0

    @classmethod
    def from_keypoints(
        cls,
        centre: tuple[float, float],
        scale_point: tuple[float, float],
        scale: float = DEFAULT_SCALE,
        target_angle: float = math.pi / 2,
    ) -> Region:
        """MediaPipe's alignment-points rect: radius = |scale_point - centre|, then scaled."""
        (x0, y0), (x1, y1) = centre, scale_point
        radius = math.hypot(x1 - x0, y1 - y0)
        rotation = _normalise(target_angle - math.atan2(-(y1 - y0), x1 - x0))
        return cls(x0, y0, 2 * radius * scale, rotation)

    @property
    def valid(self) -> bool:
        return all(math.isfinite(v) for v in (self.cx, self.cy, self.side, self.rotation)) and (
            self.side > 1.0
        )

    def bounds(self) -> tuple[float, float, float, float]:
        """x0, y0, x1, y1: the rotated square's axis-aligned bounds, continuous image pixels
        (what a crop of it reads, but for bilinear sampling's neighbours)."""
        half = self.side / 2 * (abs(math.cos(self.rotation)) + abs(math.sin(self.rotation)))
        return self.cx - half, self.cy - half, self.cx + half, self.cy + half

    def _affine(self, size: int) -> tuple[float, float, float, float, float, float]:
        """crop_to_image's rows (a00, a01, b0, a10, a11, b1) in Python floats, without numpy
        calls: they run right after a model run, when each is slow (bench/cold_paths.py).
        For a power-of-two size (the landmark model's 256) the products by size / 2 are
        exact, so these are the floats numpy's fused 2x2 product gave; for other sizes
        they may differ from it in the last bit."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        k = self.side / size
        a00, a01, a10, a11 = c * k, -s * k, s * k, c * k
        h = size / 2
        return a00, a01, self.cx - (a00 * h + a01 * h), a10, a11, self.cy - (a10 * h + a11 * h)

    def crop_to_image(self, size: int) -> np.ndarray:
        """2x3 affine map from continuous crop coordinates (0..size) to image coordinates."""
        a00, a01, b0, a10, a11, b1 = self._affine(size)
        return np.array([[a00, a01, b0], [a10, a11, b1]])

    def crop(self, image: np.ndarray, size: int, buffers: WarpBuffers | None = None) -> np.ndarray:
        """The region resampled to size x size x 3 (zero outside the image); the image is
        RGB or, cheaper to warp, its four-channel form (monopic.pose.warp). With `buffers`
        the crop is written there (`warp`)."""
        a00, a01, b0, a10, a11, b1 = self._affine(size)
        # warpAffine samples pixel centres: shift by half a pixel on both sides.
        b0 += (a00 * 0.5 + a01 * 0.5) - 0.5
        b1 += (a10 * 0.5 + a11 * 0.5) - 0.5
        m_idx = np.array([[a00, a01, b0], [a10, a11, b1]])
        return warp(image, m_idx, (size, size), cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, buffers)

    def to_image(self, points: np.ndarray, size: int) -> np.ndarray:
        """Crop coordinates (N, 2) in 0..size to image pixels (N, 2)."""
        m = self.crop_to_image(size)
        return np.asarray(points, dtype=float) @ m[:, :2].T + m[:, 2]

    def corners(self) -> np.ndarray:
        """The four corners in image pixels (for drawing)."""
        return self.to_image(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float), 1)


def _normalise(angle: float) -> float:
    return angle - 2 * math.pi * math.floor((angle + math.pi) / (2 * math.pi))
