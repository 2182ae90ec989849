"""The authors' smoothing: a scalar Kalman filter on phi, moving averages on velocities."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field


@dataclass
class Kalman1D:
    """Random-walk scalar Kalman filter.

    q is the process variance added per update, r the measurement variance (deg^2 for
    phi). NaN measurements are skipped (the estimate is kept, its variance grows).
    """

    q: float = 4.0
    r: float = 100.0
    x: float = float("nan")
    p: float = 1e6

    def update(self, z: float) -> float:
        if not math.isfinite(z):
            self.p += self.q
            return self.x
        if not math.isfinite(self.x):
            self.x, self.p = z, self.r
            return self.x
        self.p += self.q
        k = self.p / (self.p + self.r)
        self.x += k * (z - self.x)
        self.p *= 1 - k
        return self.x

    def reset(self) -> None:
        self.x, self.p = float("nan"), 1e6


@dataclass
class MovingAverage:
    """Mean of the last `window` finite values."""

    window: int = 4
    _values: deque[float] = field(default_factory=deque)

    def __post_init__(self) -> None:
        if self.window < 1:
            raise ValueError(f"moving-average window must be >= 1, got {self.window}")
        self._values = deque(maxlen=self.window)

    def update(self, value: float) -> float:
        if math.isfinite(value):
            self._values.append(value)
        return sum(self._values) / len(self._values) if self._values else float("nan")

    def reset(self) -> None:
        self._values.clear()
