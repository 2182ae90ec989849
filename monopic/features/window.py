"""Short least-squares fits over the last fraction of a second: rates of change for intent.

The constant-velocity Kalman track (ground_track) is what the baseline predictor reads;
it assumes constant velocity, so by construction it lags a pedestrian who slows, stops or
turns. Intent features want those changes, so they come from a separate estimate: a
polynomial fitted to the last `seconds` of samples. A window, not a filter, so nothing
older than the window can linger in it.

Where the fit is read matters more than the fit. Read at the newest sample, a quadratic's
slope is about four times noisier than read at the window's centre (on two rendered
human-walker runs 8 m away, median speed error 0.4-0.5 m/s against 0.1-0.3), because
an end point is where a polynomial is least pinned down. So the ground kinematics are
read at the window's (weighted) mean time: they describe the last second of motion,
centred about half a second ago (`Kinematics.age`). The acceleration, a quadratic's
constant second derivative, is the same wherever it is read.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

_NAN = float("nan")


@dataclass
class SlidingWindow:
    """The samples (t, value vector) of the last `seconds`, oldest first, with weights."""

    seconds: float
    _samples: deque[tuple[float, np.ndarray, float]] = field(default_factory=deque)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.seconds) and self.seconds > 0):
            raise ValueError(f"window must be positive seconds, got {self.seconds}")

    def add(self, t: float, value: np.ndarray | float, weight: float = 1.0) -> None:
        """Append a sample; samples older than `seconds` before it are dropped."""
        if self._samples and t <= self._samples[-1][0]:
            raise ValueError(f"timestamps must increase: {t} after {self._samples[-1][0]}")
        if not (math.isfinite(weight) and weight > 0):
            raise ValueError(f"sample weight must be positive, got {weight}")
        self._samples.append((float(t), np.atleast_1d(np.asarray(value, dtype=float)), weight))
        while t - self._samples[0][0] > self.seconds + 1e-9:
            self._samples.popleft()

    def __len__(self) -> int:
        return len(self._samples)

    @property
    def span(self) -> float:
        """Seconds from the oldest to the newest sample (0 with fewer than two)."""
        return self._samples[-1][0] - self._samples[0][0] if len(self._samples) > 1 else 0.0

    def first_values(self) -> list[tuple[float, float]]:
        """(t, first value component) of each sample, oldest first, as Python floats."""
        return [(t, float(v[0])) for t, v, _ in self._samples]

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(times (n,), values (n, d), weights (n,))."""
        t = np.array([s[0] for s in self._samples])
        v = np.array([s[1] for s in self._samples])
        w = np.array([s[2] for s in self._samples])
        return t, v, w

    def reset(self) -> None:
        self._samples.clear()


def median(values: Sequence[float]) -> float:
    """np.median of a few floats, the same float, in a tenth of its time.

    The middle value, or the two middle values' sum halved (np.median's mean of them).
    Between 0.0 and -0.0, equal to a sort, np.median may return either sign.
    """
    ordered = sorted(values)
    if not ordered:
        raise ValueError("the median of no values")
    mid = len(ordered) // 2
    if len(ordered) % 2:
        return float(ordered[mid])
    return float((ordered[mid - 1] + ordered[mid]) / 2)


def derivatives_at(
    t: np.ndarray,
    values: np.ndarray,
    degree: int,
    at: float,
    weights: np.ndarray | None = None,
) -> np.ndarray:
    """Weighted least-squares polynomial of `degree` in time, read at time `at`.

    Returns (degree + 1, d): row k is the k-th derivative of each value column at `at`.
    Time is taken relative to `at`, so the coefficients are the derivatives (times k!)
    directly and, with `at` inside the samples, the fit is well conditioned.
    """
    tau = np.asarray(t, dtype=float) - float(at)
    y = np.asarray(values, dtype=float).reshape(len(tau), -1)
    if len(tau) <= degree:
        raise ValueError(f"a degree-{degree} fit needs more than {degree} samples")
    A = np.vander(tau, degree + 1, increasing=True)
    if weights is None:  # unit weights: scaling by sqrt(1) = 1 changes no float
        coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    else:
        sw = np.sqrt(np.asarray(weights, dtype=float))[:, None]
        coef, *_ = np.linalg.lstsq(A * sw, y * sw, rcond=None)
    return coef * _factorials(degree)


@functools.lru_cache(maxsize=8)
def _factorials(degree: int) -> np.ndarray:
    """(degree + 1, 1): k! in row k, built once (a fit runs every frame)."""
    return np.array([math.factorial(k) for k in range(degree + 1)], dtype=float)[:, None]


@dataclass(frozen=True)
class KinematicsConfig:
    """The ground window. Defaults physical, not tuned on sweep outcomes:

    - 1 s: a walker's stop or turn takes a couple of steps (about a second), so a much
      longer window averages the change away; a shorter one leaves too few frames to fit
      a curvature through the foot point's noise (a few tenths of a metre at 8 m) and
      the stride's own surge (about 2 m/s^2 twice a stride): at 0.8 s the acceleration
      of a steady walker read 0.9-1.3 m/s^2 (median magnitude), at 1 s 0.5-1.2;
    - at least 5 samples spanning 0.4 s before anything is said (a fresh track is NaN);
    - below 0.2 m/s the walking direction is undefined (standing sway, stepping on the
      spot), so acceleration along it and the heading rate are NaN.
    """

    seconds: float = 1.0
    min_samples: int = 5
    min_span: float = 0.4  # s
    min_heading_speed: float = 0.2  # m/s

    def __post_init__(self) -> None:
        if not self.min_samples >= 3:
            raise ValueError(f"a quadratic fit needs min_samples >= 3, got {self.min_samples}")
        if not 0 < self.min_span <= self.seconds:
            raise ValueError(f"min_span must be in (0, seconds], got {self.min_span}")


@dataclass(frozen=True)
class Kinematics:
    """The foot point's motion over the ground from the window fit (NaN: not known)."""

    speed: float = _NAN  # m/s
    acceleration: float = _NAN  # m/s^2 along the walking direction (< 0: slowing)
    heading_rate: float = _NAN  # deg/s, > 0 turning left (counter-clockwise from above)
    age: float = _NAN  # s from the time the fit is read at to the newest sample


@dataclass
class GroundKinematics:
    """Speed, along-track acceleration and heading rate of a point in a fixed ground frame.

    Fed the same measurements the Kalman track believed (fixed odometry frame, so the
    robot's own motion is already out), each weighted by the inverse of its mean position
    variance: a far, noisy foot point counts for less. Speed, along-track acceleration
    and turn rate do not depend on how the fixed frame is oriented, so they need no
    rotation back into the robot's frame.
    """

    config: KinematicsConfig = field(default_factory=KinematicsConfig)
    _window: SlidingWindow = field(init=False)

    def __post_init__(self) -> None:
        self._window = SlidingWindow(self.config.seconds)

    def add(self, t: float, z: np.ndarray, R: np.ndarray) -> None:
        """A position measurement (m, fixed frame) and its covariance (m^2)."""
        variance = float(np.trace(np.asarray(R, dtype=float))) / 2
        self._window.add(t, np.asarray(z, dtype=float)[:2], 1.0 / max(variance, 1e-12))

    def estimate(self) -> Kinematics:
        c = self.config
        if len(self._window) < c.min_samples or self._window.span < c.min_span - 1e-9:
            return Kinematics()
        t, z, w = self._window.arrays()
        at = float(np.sum(w * t) / np.sum(w))
        d = derivatives_at(t, z, 2, at, w)
        v, a = d[1], d[2]
        speed = float(math.hypot(v[0], v[1]))
        age = float(t[-1]) - at
        if speed < c.min_heading_speed:
            return Kinematics(speed=speed, age=age)
        along = float(v @ a) / speed
        turn = float(v[0] * a[1] - v[1] * a[0]) / speed**2  # rad/s
        return Kinematics(speed, along, math.degrees(turn), age)

    def reset(self) -> None:
        self._window.reset()


def angle_rate(window: SlidingWindow, period: float = 360.0, min_samples: int = 3,
               min_span: float = 0.2) -> float:  # fmt: skip
    """Least-squares slope (unit/s) of an angle over the window, unwrapped by `period`.

    NaN until the window holds `min_samples` finite samples spanning `min_span` seconds.
    """
    if len(window) < min_samples or window.span < min_span - 1e-9:
        return _NAN
    # The finite samples as Python floats: a frame's window holds a handful, and numpy's
    # masking and fitting of them cost more than the rest of the frame's features.
    finite = [(t, v) for t, v in window.first_values() if math.isfinite(v)]
    if len(finite) < min_samples or finite[-1][0] - finite[0][0] < min_span - 1e-9:
        return _NAN
    values = [v for _, v in finite]
    if any(abs(b - a) >= period / 2 for a, b in itertools.pairwise(values)):
        values = np.unwrap(values, period=period).tolist()
    return line_slope([t for t, _ in finite], values)


def line_slope(t: Sequence[float], y: Sequence[float]) -> float:
    """Slope of the least-squares line through (t, y), from the centred sums.

    Time is taken relative to the last sample first, as `derivatives_at` does. Within
    about 2e-12 (relative) of that fit's `np.linalg.lstsq` slope, which it replaces for
    `angle_rate`: right after the landmark model, `angle_rate` with the solver took
    0.14-0.17 ms of a frame's 0.36-0.45 ms of features (the stage after pose:
    `bench/post_pose.py`). At least two distinct times.
    """
    n = len(t)
    last = t[-1]
    tau = [ti - last for ti in t]
    mt, my = sum(tau) / n, sum(y) / n
    sxx = sum((ti - mt) ** 2 for ti in tau)
    if not sxx > 0:
        raise ValueError("a line needs at least two distinct times")
    return sum((ti - mt) * (yi - my) for ti, yi in zip(tau, y, strict=True)) / sxx
