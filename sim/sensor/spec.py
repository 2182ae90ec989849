"""A camera sensor's figures (SensorSpec) and the named presets a scenario chooses.

`ideal` is no sensor at all: the renderer's frames bit for bit, as every scenario had
before the sensor existed, and what a scenario file that names none keeps. A real
preset's figures come from its datasheet; scenarios/README.md ("The camera's sensor")
gives each one's source. A scenario file's `[robot.camera]` table names a preset and may
override any of its figures (sim.scenario.files).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

IDEAL = "ideal"
TONES = ("srgb", "linear")  # the tone curve from the linear signal to the 8-bit output


class SensorSpecError(ValueError):
    """A sensor figure outside what a camera can have; the message names the field."""

    def __init__(self, field: str, value: object, why: str) -> None:
        super().__init__(f"{field} = {value!r}: {why}")
        self.field, self.value, self.why = field, value, why


@dataclass(frozen=True)
class SensorSpec:
    """One camera: its sensor, its lens' aperture, its auto-exposure and its output.

    Exposure and gain are automatic unless `exposure_ms` (and then `gain`) is given. The
    exposure window ends at the frame's time (a global shutter: every row sees the same
    window). Figures are per pixel of the rendered image: the render stands for the
    sensor read out at the scenario's resolution.
    """

    name: str
    pixel_um: float  # pixel pitch, micrometres
    quantum_efficiency: float  # electrons per photon, 0-1
    full_well_e: float  # saturation capacity, electrons
    read_noise_e: float  # temporal dark noise, electrons rms
    adc_bits: int  # the digitiser's depth
    f_number: float  # the lens' aperture
    min_exposure_ms: float
    max_exposure_ms: float  # the sensor's longest; the frame interval caps it too
    max_gain: float  # analog gain, times (1: none)
    max_fps: float  # the sensor's fastest frame rate at full resolution
    # Auto-exposure: the mean linear signal it aims at (0-1 of full scale) and how fast it
    # follows (the time constant of its first-order lag, seconds; 0: at once).
    ae_target: float = 0.18
    ae_time_constant_s: float = 0.25
    exposure_ms: float | None = None  # fixed exposure (None: automatic)
    gain: float | None = None  # fixed gain with a fixed exposure (None: automatic)
    tone: str = "srgb"
    jpeg_quality: int = 0  # 0: no compression; 1-100: JPEG at that quality
    noise: bool = True  # shot and read noise (off: a noiseless sensor, e.g. to see blur alone)
    motion_blur: bool = True  # integrate the scene's motion over the exposure
    # Sub-frame renders are spaced at most this many pixels of image motion apart, and at
    # most `max_subframes` of them (sim.world.shutter).
    blur_step_px: float = 1.0
    max_subframes: int = 12

    def __post_init__(self) -> None:
        positive = {
            "pixel_um": self.pixel_um,
            "full_well_e": self.full_well_e,
            "f_number": self.f_number,
            "min_exposure_ms": self.min_exposure_ms,
            "max_exposure_ms": self.max_exposure_ms,
            "max_fps": self.max_fps,
            "blur_step_px": self.blur_step_px,
        }
        for name, value in positive.items():
            if not (math.isfinite(value) and value > 0):
                raise SensorSpecError(name, value, "must be a positive number")
        if not 0 < self.quantum_efficiency <= 1:
            raise SensorSpecError(
                "quantum_efficiency", self.quantum_efficiency, "must be in (0, 1]"
            )
        if not (math.isfinite(self.read_noise_e) and self.read_noise_e >= 0):
            raise SensorSpecError("read_noise_e", self.read_noise_e, "must be >= 0 electrons")
        if not 8 <= self.adc_bits <= 16:
            raise SensorSpecError("adc_bits", self.adc_bits, "must be in [8, 16]")
        if not (math.isfinite(self.max_gain) and self.max_gain >= 1):
            raise SensorSpecError("max_gain", self.max_gain, "must be >= 1")
        if self.min_exposure_ms > self.max_exposure_ms:
            raise SensorSpecError(
                "min_exposure_ms", self.min_exposure_ms,
                f"must be <= max_exposure_ms ({self.max_exposure_ms:g})",
            )  # fmt: skip
        if not 0 < self.ae_target < 1:
            raise SensorSpecError("ae_target", self.ae_target, "must be in (0, 1)")
        if not (math.isfinite(self.ae_time_constant_s) and self.ae_time_constant_s >= 0):
            raise SensorSpecError(
                "ae_time_constant_s", self.ae_time_constant_s, "must be >= 0 seconds"
            )
        if self.exposure_ms is not None and not (
            self.min_exposure_ms <= self.exposure_ms <= self.max_exposure_ms
        ):
            raise SensorSpecError(
                "exposure_ms", self.exposure_ms,
                f"must be in [{self.min_exposure_ms:g}, {self.max_exposure_ms:g}] ms "
                "(the sensor's exposure range)",
            )  # fmt: skip
        if self.gain is not None:
            if self.exposure_ms is None:
                raise SensorSpecError("gain", self.gain, "a fixed gain needs a fixed exposure_ms")
            if not 1 <= self.gain <= self.max_gain:
                raise SensorSpecError("gain", self.gain, f"must be in [1, {self.max_gain:g}]")
        if self.tone not in TONES:
            raise SensorSpecError("tone", self.tone, f"must be one of {', '.join(TONES)}")
        if not 0 <= self.jpeg_quality <= 100:
            raise SensorSpecError("jpeg_quality", self.jpeg_quality, "must be in [0, 100]")
        if not 1 <= self.max_subframes <= 64:
            raise SensorSpecError("max_subframes", self.max_subframes, "must be in [1, 64]")

    @property
    def automatic(self) -> bool:
        return self.exposure_ms is None

    @property
    def levels(self) -> int:
        """The digitiser's largest code."""
        return (1 << self.adc_bits) - 1

    def check_frame_rate(self, dt: float) -> None:
        """Refuse a frame interval this camera cannot keep or an exposure that overruns it."""
        fps = 1.0 / dt
        if fps > self.max_fps * (1 + 1e-9):
            raise SensorSpecError(
                "fps", round(fps, 3), f"the {self.name} camera runs at most {self.max_fps:g} fps"
            )
        if self.exposure_ms is not None and self.exposure_ms > 1000.0 * dt * (1 + 1e-9):
            raise SensorSpecError(
                "exposure_ms", self.exposure_ms,
                f"longer than the frame interval ({1000.0 * dt:.4g} ms at {fps:.4g} fps)",
            )  # fmt: skip


# Sony IMX273 (Pregius, global shutter, 1/2.9", 1456 x 1088), the sensor of robot and
# machine-vision cameras such as FLIR's Blackfly S BFS-U3-16S2 and Balluff's mvBlueFOX3-2016.
# Figures and their sources: scenarios/README.md, "The camera's sensor".
IMX273 = SensorSpec(
    name="imx273",
    pixel_um=3.45,
    quantum_efficiency=0.65,
    full_well_e=10470.0,
    read_noise_e=2.8,
    adc_bits=12,
    f_number=2.0,
    min_exposure_ms=0.01,
    max_exposure_ms=30.0,
    max_gain=251.0,  # 48 dB
    max_fps=226.0,
)

PRESETS: dict[str, SensorSpec | None] = {IDEAL: None, IMX273.name: IMX273}
REAL_CAMERA = IMX273.name  # the real camera the Euro NCAP grid uses


def preset(name: str) -> SensorSpec | None:
    """The named preset (None for `ideal`); an unknown name is refused naming the choices."""
    if name not in PRESETS:
        raise SensorSpecError("preset", name, f"unknown camera; choose one of {', '.join(PRESETS)}")
    return PRESETS[name]
