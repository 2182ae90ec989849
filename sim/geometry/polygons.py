"""Convex polygons on the ground: rectangles from a pose and size, and the gap between two."""

from __future__ import annotations

import math

import numpy as np


def rectangle(centre: np.ndarray, yaw: float, length: float, width: float) -> np.ndarray:
    """Corners (4, 2) of a rectangle on the ground, counter-clockwise."""
    c, s = math.cos(yaw), math.sin(yaw)
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * [length / 2, width / 2]
    return np.asarray(centre, dtype=float)[:2] + half @ np.array([[c, s], [-s, c]])


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = float(np.clip((p - a) @ ab / max(float(ab @ ab), 1e-18), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def _inside(p: np.ndarray, poly: np.ndarray) -> bool:
    """Point in a convex counter-clockwise polygon (boundary included)."""
    for a, b in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) < -1e-12:
            return False
    return True


def polygon_gap(a: np.ndarray, b: np.ndarray) -> float:
    """Distance between two convex polygons (counter-clockwise corners), 0 when they overlap."""
    if any(_inside(p, b) for p in a) or any(_inside(p, a) for p in b):
        return 0.0
    gap = math.inf
    for poly, other in ((a, b), (b, a)):
        edges = list(zip(other, np.roll(other, -1, axis=0), strict=True))
        for p in poly:
            gap = min(gap, min(_segment_distance(p, e0, e1) for e0, e1 in edges))
    if gap > 0:  # edges crossing without a corner inside: a '+' shaped overlap
        for p0, p1 in zip(a, np.roll(a, -1, axis=0), strict=True):
            for q0, q1 in zip(b, np.roll(b, -1, axis=0), strict=True):
                if _segments_cross(p0, p1, q0, q1):
                    return 0.0
    return gap


def _segments_cross(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> bool:
    def side(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    return side(p0, p1, q0) * side(p0, p1, q1) < 0 and side(q0, q1, p0) * side(q0, q1, p1) < 0
