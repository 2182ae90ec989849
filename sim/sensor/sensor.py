"""One camera's sensor over a run: its auto-exposure, its readout and its noise's stream."""

from __future__ import annotations

import numpy as np

from sim.sensor.exposure import AutoExposure, ExposureState
from sim.sensor.photometry import electrons_per_second
from sim.sensor.readout import NoisePool, Readout
from sim.sensor.spec import SensorSpec

NOISE_STREAM = 0x53454E53  # the noise's random stream, apart from the run's others


class Sensor:
    """Exposes each frame's light: call `settings()` for the exposure the next frame gets,
    render the light over it, then `read(light, settings)` for the frame."""

    def __init__(self, spec: SensorSpec, illuminance_lux: float, dt: float, seed: int) -> None:
        spec.check_frame_rate(dt)
        self.spec = spec
        self.rate = electrons_per_second(spec, illuminance_lux)
        self.dt = dt
        self.readout = Readout(spec)
        self.reset(seed)

    def reset(self, seed: int) -> None:
        """A new run: the noise stream from the run's seed; exposure metered afresh."""
        self.rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, NOISE_STREAM])
        self._normals: NoisePool | None = None  # drawn on the first noisy frame
        self.exposure = AutoExposure(self.spec, self.dt, self.rate)

    @property
    def metered(self) -> bool:
        return self.exposure.value is not None

    def meter(self, light: np.ndarray) -> None:
        """Settle the auto-exposure on the first frame's light."""
        self.exposure.converge(light)

    def settings(self) -> ExposureState:
        t, gain = self.exposure.settings()
        return ExposureState(t, gain)

    def read(self, light: np.ndarray, state: ExposureState) -> tuple[np.ndarray, ExposureState]:
        """The frame for `light` under `state`, and the state with the signal read; the
        auto-exposure learns from it for the next frame."""
        if self._normals is None:
            self._normals = NoisePool(self.rng)
        image, signal = self.readout.read(
            light, self.rate, state.exposure_s, state.gain, self._normals
        )
        self.exposure.update(signal)
        return image, ExposureState(state.exposure_s, state.gain, state.subframes, signal)
