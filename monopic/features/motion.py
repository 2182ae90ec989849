"""Velocity of a tracked point from its positions and their timestamps.

Like the authors' code, the velocity is the displacement over `window` frames divided by
the time those frames actually span (never an assumed frame rate), then averaged over the
last few estimates.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from monopic.features.smoothing import MovingAverage


@dataclass
class VelocityEstimator:
    """Finite-difference velocity over `window` frames, smoothed by a moving average."""

    window: int = 4
    average: int = 4
    _history: deque[tuple[float, float, float]] = field(default_factory=deque)
    _avg_x: MovingAverage = field(init=False)
    _avg_y: MovingAverage = field(init=False)

    def __post_init__(self) -> None:
        if self.window < 1:
            raise ValueError(f"velocity window must be >= 1 frame, got {self.window}")
        self._history = deque(maxlen=self.window + 1)
        self._avg_x = MovingAverage(self.average)
        self._avg_y = MovingAverage(self.average)

    def update(self, t: float, x: float, y: float) -> tuple[float, float]:
        """Add a position; return the smoothed velocity (NaN until two samples exist)."""
        if self._history and t <= self._history[-1][0]:
            raise ValueError(f"timestamps must increase: {t} after {self._history[-1][0]}")
        self._history.append((t, x, y))
        if len(self._history) < 2:
            return float("nan"), float("nan")
        t0, x0, y0 = self._history[0]
        dt = t - t0
        vx, vy = (x - x0) / dt, (y - y0) / dt
        return self._avg_x.update(vx), self._avg_y.update(vy)

    def reset(self) -> None:
        self._history.clear()
        self._avg_x.reset()
        self._avg_y.reset()
