"""How many electrons the rendered light is worth: the camera equation, to first order.

The renderer's linear value 1 stands for a white (reflectance 1) Lambertian surface under
the scene's illuminance (sim.scenario.lighting.Lighting.illuminance_lux). Such a surface
has luminance E/pi; a lens of aperture N puts E/(4 N^2) on the sensor on its axis (no
vignetting, lens transmission 1). One lux is 1/683 W/m^2 at 555 nm, 4.1e15 photons a
second per square metre; broadband daylight carries more photons per lux but a colour
sensor's filters pass about a third of them to each channel, which this figure leaves
inside the quantum efficiency's uncertainty.
"""

from __future__ import annotations

from sim.sensor.spec import SensorSpec

PHOTONS_PER_LUX_S_M2 = 4.1e15  # photons per second per m^2 per lux at 555 nm


def electrons_per_second(spec: SensorSpec, illuminance_lux: float) -> float:
    """Electrons a second a pixel collects from rendered linear light 1 under `illuminance_lux`."""
    if not illuminance_lux > 0:
        raise ValueError(f"illuminance must be positive lux, got {illuminance_lux}")
    area_m2 = (spec.pixel_um * 1e-6) ** 2
    on_sensor_lux = illuminance_lux / (4.0 * spec.f_number**2)
    return spec.quantum_efficiency * PHOTONS_PER_LUX_S_M2 * on_sensor_lux * area_m2
