"""Landmark smoothing across frames, as MediaPipe's pose graph does it.

The reference pipeline (MediaPipe 0.10.14 Pose, tracking mode, smooth_landmarks=True)
runs the PoseLandmarkFiltering subgraph after the landmark model. Its node options, read
from the subgraph config embedded in mediapipe/python/_framework_bindings*.so and parsed
with mediapipe.framework.calculator_pb2 (the installed pose_landmark_cpu.binarypb only
names the subgraph):

- landmarks: VisibilitySmoothingCalculator low_pass_filter {alpha 0.1}, then
  LandmarksSmoothingCalculator one_euro_filter {min_cutoff 0.05, beta 80,
  derivate_cutoff 1} (frequency 30 and min_allowed_object_scale 1e-6 by default), both
  behind SwitchContainer ENABLE:smooth_landmarks;
- auxiliary landmarks (which give the next frame's region): the same low-pass on
  visibility and one_euro_filter {min_cutoff 0.01, beta 10, derivate_cutoff 1}, always,
  whatever smooth_landmarks says;
- both one-euro filters get OBJECT_SCALE_ROI: AlignmentPointsRectsCalculator's square
  over the *unfiltered* auxiliary points 0 (centre) and 1 (scale point), before the 1.25
  enlargement, so the object scale is its side, 2 |aux1 - aux0| pixels.

LandmarksSmoothingCalculator filters every coordinate on its own in pixels (x * width,
y * height, z * width: our landmarks are already pixels) with value_scale =
1 / object_scale, so the speed that opens the filter is measured in object sizes per
second and the filter behaves alike near and far. When a frame has no landmarks (person
lost) both calculators reset their filters.

One deliberate difference: MediaPipe's OneEuroFilter keeps its last timestamp as int64
nanoseconds with 0 meaning "none yet", so a sample stamped exactly 0 is passed through
and not remembered. Its Python solution never stamps 0 (it feeds 33333 us, 66666 us, ...);
our frames often start at 0 s, so "none yet" is None here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from monopic.pose.landmarks import Pose


@dataclass
class LowPassFilter:
    """Exponential smoothing of an array, mediapipe/util/filtering/low_pass_filter.cc.

    The first sample is returned as is and stored; each later one returns
    alpha * value + (1 - alpha) * stored. The last raw input is kept too (the one-euro
    filter's derivative uses it). `alpha` is the default weight of the newest sample
    (VisibilitySmoothingCalculator's low_pass_filter); `apply` may override it per call
    and per element, as OneEuroFilter does.
    """

    alpha: float = 0.1
    _stored: np.ndarray | None = field(default=None, init=False, repr=False)
    _raw: np.ndarray | None = field(default=None, init=False, repr=False)

    @property
    def last_raw(self) -> np.ndarray | None:
        return self._raw

    def apply(self, value: np.ndarray, alpha: float | np.ndarray | None = None) -> np.ndarray:
        value = np.array(value, dtype=np.float64)
        if self._stored is None:
            result = value
        else:
            if self._stored.shape != value.shape:
                raise ValueError(f"shape changed from {self._stored.shape} to {value.shape}")
            a = self.alpha if alpha is None else alpha
            result = a * value + (1.0 - a) * self._stored
        self._raw = value
        self._stored = result
        return result.copy()

    def reset(self) -> None:
        self._stored = None
        self._raw = None


@dataclass
class OneEuroFilter:
    """The 1-euro filter of an array, element by element, as MediaPipe's
    mediapipe/util/filtering/one_euro_filter.cc.

    A low-pass filter whose cutoff rises with the (smoothed) speed of the signal: still
    points are held steady (cutoff min_cutoff), moving ones follow with little lag
    (cutoff min_cutoff + beta * |speed|). Speed is (value - last raw value) * value_scale
    * frequency, so with value_scale = 1 / object size it is in object sizes per second.
    The sampling frequency starts at `frequency` and is 1 / (time since the last sample)
    from the second sample on; a sample not later than the last returns the value as is
    and leaves the state alone (MediaPipe logs a warning and does the same).
    """

    min_cutoff: float = 1.0
    beta: float = 0.0
    derivate_cutoff: float = 1.0
    frequency: float = 30.0  # Hz before two timestamps are known (MediaPipe's default)
    _x: LowPassFilter = field(default_factory=LowPassFilter, init=False, repr=False)
    _dx: LowPassFilter = field(default_factory=LowPassFilter, init=False, repr=False)
    _last_time: float | None = field(default=None, init=False, repr=False)
    _rate: float = field(default=0.0, init=False, repr=False)

    def __post_init__(self) -> None:
        self._rate = self.frequency

    def alpha(self, cutoff: float | np.ndarray) -> float | np.ndarray:
        """Weight of the newest sample for a cutoff frequency (Hz) at the current rate."""
        te = 1.0 / self._rate
        if isinstance(cutoff, float):  # Python floats, the same IEEE steps, no numpy calls
            return 1.0 / (1.0 + 1.0 / (2.0 * math.pi * cutoff) / te)
        tau = 1.0 / (2.0 * math.pi * np.asarray(cutoff, dtype=np.float64))
        return 1.0 / (1.0 + tau / te)

    def apply(self, value: np.ndarray, timestamp: float, value_scale: float = 1.0) -> np.ndarray:
        """Filtered `value` at `timestamp` (seconds)."""
        value = np.array(value, dtype=np.float64)
        if self._last_time is not None:
            if timestamp <= self._last_time:
                return value
            self._rate = 1.0 / (timestamp - self._last_time)
        self._last_time = timestamp
        raw = self._x.last_raw  # speed 0 on the first sample
        dvalue = np.zeros_like(value) if raw is None else (value - raw) * value_scale * self._rate
        edvalue = self._dx.apply(dvalue, self.alpha(self.derivate_cutoff))
        cutoff = self.min_cutoff + self.beta * np.abs(edvalue)
        return self._x.apply(value, self.alpha(cutoff))

    def reset(self) -> None:
        self._x.reset()
        self._dx.reset()
        self._last_time = None
        self._rate = self.frequency


# PoseLandmarkFiltering's options (MediaPipe 0.10.14), see the module docstring.
VISIBILITY_ALPHA = 0.1
LANDMARK_FILTER = {"min_cutoff": 0.05, "beta": 80.0, "derivate_cutoff": 1.0}
AUX_FILTER = {"min_cutoff": 0.01, "beta": 10.0, "derivate_cutoff": 1.0}
MIN_OBJECT_SCALE = 1e-6  # LandmarksSmoothingCalculator's min_allowed_object_scale


def object_scale(aux: np.ndarray) -> float:
    """Side of the alignment square over the raw auxiliary points: 2 |aux1 - aux0| px."""
    return 2.0 * math.hypot(float(aux[1, 0] - aux[0, 0]), float(aux[1, 1] - aux[0, 1]))


@dataclass
class LandmarkFilter:
    """MediaPipe's PoseLandmarkFiltering for one tracked person.

    `apply` returns the pose with filtered auxiliary points (so `next_region` builds the
    next crop from them, as PoseLandmarksToRoi does from FILTERED_AUX_NORM_LANDMARKS)
    and, when `smooth_landmarks`, filtered landmarks and visibility. `smooth_region`
    False leaves the auxiliary points raw (MediaPipe has no such switch: ablations only).
    Call `reset` when the person is lost, as the calculators do on an empty packet.
    """

    smooth_landmarks: bool = True
    smooth_region: bool = True
    landmarks: OneEuroFilter = field(default_factory=lambda: OneEuroFilter(**LANDMARK_FILTER))
    visibility: LowPassFilter = field(default_factory=lambda: LowPassFilter(VISIBILITY_ALPHA))
    aux: OneEuroFilter = field(default_factory=lambda: OneEuroFilter(**AUX_FILTER))

    def apply(self, pose: Pose, timestamp: float) -> Pose:
        scale = object_scale(pose.aux)
        # Below the minimum scale the smoothing calculators pass landmarks through
        # untouched (visibility is still smoothed: it is another calculator).
        track = scale >= MIN_OBJECT_SCALE
        changes: dict[str, np.ndarray] = {}
        if self.smooth_landmarks:
            changes["visibility"] = self.visibility.apply(pose.visibility)
            if track:
                changes["landmarks"] = self.landmarks.apply(pose.landmarks, timestamp, 1 / scale)
        if self.smooth_region and track:
            changes["aux"] = self.aux.apply(pose.aux, timestamp, 1 / scale)
        return replace(pose, **changes) if changes else pose

    def reset(self) -> None:
        self.landmarks.reset()
        self.visibility.reset()
        self.aux.reset()
