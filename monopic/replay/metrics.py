"""The two ways to score a position prediction on a log (see the authors' data README).

Paper metric: the fraction of frames j (j = 1..n-1, every row of the log, as the authors
computed it) with |centre(j) - predicted(j-1)| < R. It compares a 1-second prediction with
the position one frame later, so it mostly measures how little people move in one frame;
with R = 51 px it reproduces the authors' per-file figures exactly.

Horizon metric: |centre(t + horizon) - predicted(t)| on the scored rows, the future
centre interpolated from the log's timestamps. This is what a prediction must be judged by.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PAPER_RADIUS_PX = 51.0
SHARE_RADIUS_PX = 50.0


def paper_metric(
    center: np.ndarray, predicted: np.ndarray, radius: float = PAPER_RADIUS_PX
) -> float:
    """Share of frames j >= 1 whose centre lies within `radius` of prediction j - 1."""
    c = np.asarray(center, dtype=float)
    p = np.asarray(predicted, dtype=float)
    if c.shape != p.shape or c.ndim != 2 or c.shape[1] != 2:
        raise ValueError(f"centre and prediction must both be (n, 2), got {c.shape}, {p.shape}")
    if c.shape[0] < 2:
        raise ValueError("the paper metric needs at least two frames")
    d = np.hypot(c[1:, 0] - p[:-1, 0], c[1:, 1] - p[:-1, 1])
    return float(np.count_nonzero(d < radius) / d.size)


def horizon_errors(future_center: np.ndarray, predicted: np.ndarray) -> np.ndarray:
    """Euclidean error per row between the centre at t + horizon and the prediction."""
    f = np.asarray(future_center, dtype=float)
    p = np.asarray(predicted, dtype=float)
    return np.hypot(f[:, 0] - p[:, 0], f[:, 1] - p[:, 1])


@dataclass(frozen=True)
class ErrorSummary:
    """Median, mean and share within `radius` of a set of errors (px)."""

    n: int
    median: float
    mean: float
    share_within: float
    radius: float = SHARE_RADIUS_PX

    @classmethod
    def of(cls, errors: np.ndarray, radius: float = SHARE_RADIUS_PX) -> ErrorSummary:
        e = np.asarray(errors, dtype=float)
        if e.size == 0:
            nan = float("nan")
            return cls(0, nan, nan, nan, radius)
        if not np.all(np.isfinite(e)):
            raise ValueError("errors must be finite")
        return cls(
            n=int(e.size),
            median=float(np.median(e)),
            mean=float(np.mean(e)),
            share_within=float(np.count_nonzero(e < radius) / e.size),
            radius=radius,
        )
