"""A camera's sensor as files write it: a preset by name and any of its figures overridden.

`[robot.camera]` of a scenario file and `[camera]` of the Euro NCAP car file share these
keys (scenarios/README.md, "The camera's sensor"): `preset` ("ideal" or a real camera of
sim.sensor.spec.PRESETS) and, for a real camera only, the figures of SensorSpec under
their own names. The ideal camera has no figures to override: naming one is refused
rather than ignored.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from sim.scenario.toml_table import TomlTable
from sim.sensor.spec import IDEAL, PRESETS, TONES, SensorSpec, SensorSpecError

# Each overridable figure: its reader (number with bounds and unit, integer, flag or text).
NUMBERS: dict[str, dict[str, Any]] = {
    "pixel_um": {"positive": True, "high": 20.0, "unit": "micrometres"},
    "quantum_efficiency": {"positive": True, "high": 1.0},
    "full_well_e": {"positive": True, "high": 1e6, "unit": "electrons"},
    "read_noise_e": {"low": 0.0, "high": 1000.0, "unit": "electrons rms"},
    "f_number": {"low": 0.7, "high": 32.0},
    "min_exposure_ms": {"positive": True, "high": 1000.0, "unit": "ms"},
    "max_exposure_ms": {"positive": True, "high": 1000.0, "unit": "ms"},
    "max_gain": {"low": 1.0, "high": 1e4, "unit": "times"},
    "max_fps": {"positive": True, "high": 10000.0, "unit": "frames/s"},
    "ae_target": {"positive": True, "high": 0.99},
    "ae_time_constant_s": {"low": 0.0, "high": 10.0, "unit": "s"},
    "exposure_ms": {"positive": True, "high": 1000.0, "unit": "ms"},
    "gain": {"low": 1.0, "high": 1e4, "unit": "times"},
    "blur_step_px": {"positive": True, "high": 100.0, "unit": "px"},
}
INTEGERS: dict[str, tuple[int, int]] = {
    "adc_bits": (8, 16),
    "jpeg_quality": (0, 100),
    "max_subframes": (1, 64),
}
FLAGS = ("noise", "motion_blur")


def read_sensor(t: TomlTable, default: SensorSpec | None) -> SensorSpec | None:
    """The sensor a camera table names (its `preset`, default `default`'s), with its
    overrides; marks the keys read. Every refusal names the table's field."""
    name = t.text("preset", IDEAL if default is None else default.name, tuple(PRESETS))
    base = PRESETS[name] if t.has("preset") else default
    given: dict[str, Any] = {}
    for key, bounds in NUMBERS.items():
        if t.has(key):
            given[key] = t.number(key, **bounds)
    for key, (low, high) in INTEGERS.items():
        if t.has(key):
            given[key] = t.integer(key, low=low, high=high)
    for key in FLAGS:
        if t.has(key):
            given[key] = t.flag(key)
    if t.has("tone"):
        given["tone"] = t.text("tone", choices=TONES)
    if base is None:
        if given:
            key = next(iter(given))
            real = ", ".join(n for n in PRESETS if n != IDEAL)
            raise t.error(key, given[key], f"the ideal camera has no sensor figures: set "
                          f"preset to a real camera ({real}) to give one")  # fmt: skip
        return None
    if not given:
        return base
    try:
        return replace(base, **given)
    except SensorSpecError as err:
        raise t.error(err.field, err.value, err.why) from None
