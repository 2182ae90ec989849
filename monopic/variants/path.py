"""Variant 2: path projection. The whole extrapolated path against the robot's path.

The predicted displacement over one horizon is repeated along the path (no change of
state, as the paper assumes), out to `length` seconds; the conflict point is the first
point of that path inside the robot's zone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monopic.features.record import Features
from monopic.predict.base import Prediction
from monopic.variants.zone import points_in_polygon


@dataclass(frozen=True)
class PathProjection:
    times: np.ndarray  # (N,) seconds ahead
    image_path: np.ndarray  # (N, 2) predicted foot points, pixels
    ground_path: np.ndarray | None  # (N, 2) robot frame, metres, in ground mode
    conflict_index: int | None  # first index inside the robot's zone

    @property
    def conflict(self) -> tuple[float, float] | None:
        if self.conflict_index is None:
            return None
        u, v = self.image_path[self.conflict_index]
        return float(u), float(v)

    @property
    def conflict_time(self) -> float | None:
        return None if self.conflict_index is None else float(self.times[self.conflict_index])


def project_path(
    features: Features,
    prediction: Prediction,
    zone: np.ndarray,
    length: float = 3.0,
    steps: int = 15,
) -> PathProjection:
    times = np.linspace(0.0, length, steps + 1)
    frac = times / prediction.horizon
    foot = np.asarray(features.foot, dtype=float)
    image_path = foot + frac[:, None] * (np.asarray(prediction.foot) - foot)
    ground_path = None
    if prediction.ground is not None and features.ground is not None:
        g0 = np.asarray(features.ground.position, dtype=float)
        ground_path = g0 + frac[:, None] * (np.asarray(prediction.ground) - g0)
        pts = features.ground.camera.project(
            np.column_stack([ground_path, np.zeros(len(ground_path))])
        )
        ok = np.all(np.isfinite(pts), axis=1)
        image_path = np.where(ok[:, None], pts, image_path)
    hits = np.flatnonzero(points_in_polygon(image_path, zone))
    conflict = int(hits[0]) if hits.size else None
    return PathProjection(times, image_path, ground_path, conflict)
