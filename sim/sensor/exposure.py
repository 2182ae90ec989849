"""Auto-exposure: the exposure time and gain of each frame, following the light with a lag.

The camera's exposure value (exposure time times gain) aims at `ae_target`, the mean
linear signal as a share of full scale. Each frame it measures the mean signal of the frame
it just read and moves its exposure value a step toward the one that would have met the
target, in the logarithm (a first-order lag with time constant `ae_time_constant_s`,
the way camera ISPs damp exposure changes so the image does not pump). The exposure value
is spent on time first, up to the sensor's longest exposure or the frame interval,
whichever is shorter, then on gain: a longer exposure costs blur, more gain costs noise,
and a camera prefers the cost it cannot see in a still image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.sensor.spec import SensorSpec

METER_STRIDE = 4  # the meter reads every 4th pixel each way (camera ISPs meter on a grid)


@dataclass(frozen=True)
class ExposureState:
    """One frame's exposure: time (s), analog gain, the sub-frames rendered over it and the
    mean linear signal read (share of full scale)."""

    exposure_s: float
    gain: float
    subframes: int = 1
    signal: float = float("nan")

    def to_dict(self) -> dict[str, float | int | None]:
        return {
            "exposure_ms": 1000.0 * self.exposure_s,
            "gain": self.gain,
            "subframes": self.subframes,
            "signal": None if math.isnan(self.signal) else self.signal,
        }


class AutoExposure:
    """The exposure of the next frame from the ones read so far (or fixed, if the spec says)."""

    def __init__(self, spec: SensorSpec, dt: float, electrons_per_s: float) -> None:
        self.spec = spec
        self.longest = min(spec.max_exposure_ms / 1000.0, dt)
        self.shortest = spec.min_exposure_ms / 1000.0
        self.step = (
            1.0 if spec.ae_time_constant_s == 0 else 1.0 - math.exp(-dt / spec.ae_time_constant_s)
        )
        self.rate = electrons_per_s
        self.value: float | None = None  # exposure value, s x gain; None: not metered yet
        if not spec.automatic:
            assert spec.exposure_ms is not None
            self.value = spec.exposure_ms / 1000.0 * (spec.gain or 1.0)

    def settings(self) -> tuple[float, float]:
        """(exposure time in s, gain) for the current exposure value."""
        if self.value is None:
            raise RuntimeError("meter the first frame before asking for an exposure")
        spec = self.spec
        if not spec.automatic:
            assert spec.exposure_ms is not None
            return spec.exposure_ms / 1000.0, spec.gain or 1.0
        t = min(max(self.value, self.shortest), self.longest)
        gain = min(max(self.value / t, 1.0), spec.max_gain)
        return t, gain

    def _clamp(self, value: float) -> float:
        return min(max(value, self.shortest), self.longest * self.spec.max_gain)

    def converge(self, light: np.ndarray) -> None:
        """Start settled on this light (a camera that was running before the scenario began):
        the exposure value whose clipped mean signal meets the target."""
        if not self.spec.automatic:
            return
        sample = light[::METER_STRIDE, ::METER_STRIDE].astype(np.float64)
        full = self.spec.full_well_e
        mean = float(sample.mean())
        value = self._clamp(self.spec.ae_target * full / (self.rate * max(mean, 1e-6)))
        for _ in range(8):  # clipping makes the mean sub-linear: a few fixed-point steps
            signal = float(np.minimum(sample * (self.rate * value / full), 1.0).mean())
            value = self._clamp(value * self.spec.ae_target / max(signal, 1e-6))
        self.value = value

    def update(self, signal: float) -> None:
        """The frame just read had mean linear signal `signal` (share of full scale)."""
        if not self.spec.automatic or self.value is None:
            return
        wanted = self._clamp(self.value * self.spec.ae_target / max(signal, 1e-4))
        self.value = self._clamp(self.value * (wanted / self.value) ** self.step)
