"""How a scene is lit: a Lighting record and the named presets a scenario file chooses.

A Lighting is the sky's light from everywhere (MuJoCo's headlight: ambient and diffuse
from the camera) and the sun, a directional light with its direction, colours and whether
it casts shadows. Overcast is the same sun behind clouds: weak, shadowless, with more
light from the sky. Night is one more preset: 1 lux from everywhere (the Euro NCAP night
tests' ambient), a black sky, the moon left out (the protocol catalogue's night moon gives
0.1 lux, a tenth of the ambient), and the light that matters from lamps and headlamps
(sim.scenario.lamps), which a night scene must have: the car's low beams at least.

`name` is the preset the lighting came from; results record it (sim.runs.result) and a
report can group by it. A file that moves the sun (`sun_azimuth_deg`, `sun_elevation_deg`)
keeps its preset's name and records the angles it used in the scenario.

Illuminance (for a real camera's sensor, sim.sensor): a clear sky's 32,000 lux is the low
end of direct sunlight and an overcast sky's 1,000 lux the usual figure for an overcast day
(the illuminance tables of the lux's definition, e.g. Wikipedia's "Lux"). At night the
render is photometric: its white stands for NIGHT_FULL_SCALE_LUX and every light's value
is its illuminance over that (sim.world.lighting).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

RGB = tuple[float, float, float]


@dataclass(frozen=True)
class Sun:
    """A directional light: where it comes from (degrees: azimuth counter-clockwise from
    east, elevation above the horizon) and how it shines."""

    azimuth_deg: float
    elevation_deg: float
    shadows: bool = True
    diffuse: RGB = (0.78, 0.76, 0.72)
    ambient: RGB = (0.12, 0.12, 0.13)
    specular: RGB = (0.15, 0.15, 0.15)

    @property
    def shines(self) -> bool:
        """Whether it gives any light (a light that gives none takes no renderer slot)."""
        return any(v > 0 for v in (*self.diffuse, *self.ambient, *self.specular))


@dataclass(frozen=True)
class Lighting:
    """The scene's light: the sky's (from everywhere) and the sun's."""

    name: str
    sun: Sun
    sky_ambient: RGB = (0.32, 0.32, 0.33)
    sky_diffuse: RGB = (0.25, 0.25, 0.25)
    # What the render's white stands for: the illuminance on a white surface drawn at full
    # brightness (sim.sensor.photometry). Only a real camera's sensor reads it.
    illuminance_lux: float = 32000.0
    sky_box: tuple[RGB, RGB] = ((0.5, 0.68, 0.9), (0.9, 0.93, 0.97))  # zenith, horizon
    # Night: the robot must carry headlamps (sim.scenario.lamps), and the render is
    # photometric (each light's value is its lux over illuminance_lux).
    night: bool = False

    @property
    def shadows(self) -> bool:
        """Whether anything casts a shadow (the render then makes a shadow pass)."""
        return self.sun.shadows

    def with_sun(self, azimuth_deg: float, elevation_deg: float) -> Lighting:
        """The same light with the sun moved (a file's sun_azimuth_deg, sun_elevation_deg)."""
        return replace(self, sun=replace(self.sun, azimuth_deg=azimuth_deg,
                                         elevation_deg=elevation_deg))  # fmt: skip


def sunny(name: str, azimuth_deg: float, elevation_deg: float) -> Lighting:
    """A clear sky: the sun casts shadows."""
    return Lighting(name, Sun(azimuth_deg, elevation_deg))


def overcast(name: str, azimuth_deg: float, elevation_deg: float) -> Lighting:
    """The sun behind clouds: more sky light from everywhere, a weak sun that casts nothing.
    It also halves the render time on software GL: the shadow pass is half of it
    (bench/simulator.py)."""
    sun = Sun(azimuth_deg, elevation_deg, shadows=False, diffuse=(0.35, 0.35, 0.36))
    return Lighting(
        name, sun, sky_ambient=(0.5, 0.5, 0.52), sky_diffuse=(0.3, 0.3, 0.3),
        illuminance_lux=1000.0,
    )  # fmt: skip


# What the render's white stands for at night: the illuminance that fills the imx273's
# wells at its longest exposure (30 ms) and 12 dB gain (sim.sensor: 10,470 e- / 4 at about
# 60 e- per lux on white in 30 ms). The render reads 8 bits, so white must not stand for
# much more: 1 lux ambient on white is 5 of its 255 steps.
NIGHT_FULL_SCALE_LUX = 50.0
NIGHT_AMBIENT_LUX = 1.0  # the Euro NCAP night tests' ambient light


def night(name: str) -> Lighting:
    """Night: 1 lux from everywhere, a black sky, no sun; lamps and headlamps light it."""
    dark: RGB = (0.0, 0.0, 0.0)
    moon = Sun(178.0, 66.0, shadows=False, diffuse=dark, ambient=dark, specular=dark)
    ambient = NIGHT_AMBIENT_LUX / NIGHT_FULL_SCALE_LUX
    return Lighting(
        name, moon, sky_ambient=(ambient, ambient, ambient), sky_diffuse=dark,
        illuminance_lux=NIGHT_FULL_SCALE_LUX, sky_box=(dark, dark),
        night=True,
    )  # fmt: skip


# The robot drives east, so azimuth 0 is a low sun straight ahead (backlit pedestrians).
PRESETS: dict[str, Lighting] = {
    light.name: light
    for light in (
        sunny("noon", 210.0, 60.0),
        sunny("morning", 120.0, 25.0),
        sunny("low-sun-behind", 180.0, 10.0),
        sunny("low-sun-ahead", 15.0, 10.0),
        overcast("overcast", 210.0, 60.0),
        # Scenarios built in code (the eight-case placement, the Euro NCAP grid, a case
        # placed on the command line) have always had this sun, 50 degrees high.
        sunny("day", 210.0, 50.0),
        night("night"),
    )
}
FILE_DEFAULT = "noon"  # what a scenario file without `[scene] lighting` gets
DAY = PRESETS["day"]
NIGHT = PRESETS["night"]
# The presets whose run identities write only their sun (sim.scenario.spec.scene_identity).
SUN_ONLY_IDENTITY = ("noon", "morning", "low-sun-behind", "low-sun-ahead", "overcast", "day")
