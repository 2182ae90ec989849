"""Light sources of the night: street lamps on their masts and the car's low beams.

Both are records in candela, so that the renderer's light values follow from photometry
(sim.world.lighting: a light of I cd at d metres puts I/d^2 lux on a surface facing it)
and a reader can check each figure against its source.

Street lamp. The published Euro NCAP night roads (the OpenDRIVE files beside the
protocol's OpenSCENARIO files) place "Streetlight Single" objects 5 m high and say
nothing of their light. We take a plain road luminaire: 1,600 cd straight down, the same
in every direction of a cone 75 degrees wide (half-angle) around the vertical, so that the
road right under a lamp gets 64 lux and the ground halfway between two lamps 25 m apart,
6 m to the side, about 5 lux: a lit residential street (EN 13201 classes P1-P2 ask 10-15
lux on average with a minimum of 2-3 lux). A renderer's spot light cannot make a real
luminaire's batwing (brightest at 60-70 degrees), so the street is darker between lamps
than a real one and brighter under them; tools/night_calibration.py measures both.

Low beam. A regulation low beam (UN R112 class B, its test points as the project read
them, in candela per lamp at 25 m: 50V at 0.86 deg down >= 3,750 cd; 50R at 0.86 deg down,
1.72 deg right >= 7,500 cd; 75R at 0.57 down, 1.15 right >= 7,500 cd; 25L and 25R at 1.72
down, 9 left and right >= 1,250 cd; 50L at 0.86 down, 3.43 left <= 9,375 cd; B50L at
0.57 up, 3.43 left <= 250 cd; zone III above
the cut-off <= 437 cd) has a flat cut-off 0.57 deg below the horizon: the road is lit, a
pedestrian's upper body beyond a few metres much less. MuJoCo's spot lights are round
cones, so the beam is built from cones whose tops touch the cut-off line: a wide cone aimed
steeply down (its top edge nearly flat over +-8 degrees) and a narrow hot spot just below
the cut-off, right of centre. The two lamps are lumped into one source at the car's
front centre (the lights it leaves for the street lamps: sim.world.lighting); intensities
are the pair's. How far the cones are from each test point: `regulation_table`, printed in
docs/night/calibration.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

CUT_OFF_DEG = 0.57  # the low beam's cut-off below the horizon (UN R112: 1 % down)
LAMP_HEIGHT = 5.0  # m, the published night roads' lamps
LAMP_INTENSITY_CD = 1600.0
LAMP_CUTOFF_DEG = 75.0
UP = np.array([0.0, 0.0, 1.0])  # the ground's normal


@dataclass(frozen=True)
class StreetLamp:
    """A lamp on a mast: where its foot stands (world frame, m), its height and its light."""

    x: float
    y: float
    height: float = LAMP_HEIGHT
    intensity_cd: float = LAMP_INTENSITY_CD  # straight down and within the cone
    cutoff_deg: float = LAMP_CUTOFF_DEG  # half-angle of the lit cone around the vertical
    on: bool = True  # a lamp that stands dark (the nearside night road's far-side pair)

    def illuminance(self, x: float, y: float) -> float:
        """Lux on the ground (horizontal) at (x, y)."""
        return float(self.illuminance_on(np.array([x, y, 0.0]), UP))

    def illuminance_on(self, points: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """Lux on surfaces at `points` (..., 3) facing `normal`: I / d^2 times the cosine of
        incidence, inside the lamp's cone."""
        if not self.on:
            return np.zeros(np.shape(points)[:-1])
        d = np.asarray(points, dtype=float) - np.array([self.x, self.y, self.height])
        r = np.linalg.norm(d, axis=-1)
        inside = -d[..., 2] / r >= math.cos(math.radians(self.cutoff_deg))
        return np.where(inside, self.intensity_cd * np.maximum(-(d @ normal), 0.0) / r**3, 0.0)


@dataclass(frozen=True)
class Spot:
    """One cone of a beam: where its axis points (degrees below the horizon and right of
    straight ahead), its half-angle, and its intensity inside (the same in every direction)."""

    down_deg: float
    right_deg: float
    cutoff_deg: float
    intensity_cd: float

    def direction(self) -> tuple[float, float, float]:
        """The axis in the car's frame (x forward, y left, z up)."""
        return _unit(self.down_deg, self.right_deg)


def _unit(down_deg: float, right_deg: float) -> tuple[float, float, float]:
    d, r = math.radians(down_deg), math.radians(right_deg)
    return (math.cos(d) * math.cos(r), -math.cos(d) * math.sin(r), -math.sin(d))


@dataclass(frozen=True)
class Headlamps:
    """The car's beam: its cones, lumped at the front centre at `height` above the road."""

    name: str
    spots: tuple[Spot, ...]
    height: float = 0.65  # m, a passenger car's headlamp centres (UN R48: 0.5-1.2 m)

    def intensity(self, down_deg: float, right_deg: float) -> float:
        """Candela towards a direction (degrees down and right): the sum of the cones that
        contain it."""
        return float(self.intensity_towards(np.array(_unit(down_deg, right_deg))))

    def intensity_towards(self, towards: np.ndarray) -> np.ndarray:
        """Candela towards unit vectors (..., 3) in the car's frame (x ahead, y left, z up)."""
        out = np.zeros(np.shape(towards)[:-1])
        for spot in self.spots:
            axis = np.array(spot.direction())
            inside = towards @ axis >= math.cos(math.radians(spot.cutoff_deg))
            out = out + np.where(inside, spot.intensity_cd, 0.0)
        return out


def _cone_below_cut_off(half_angle: float, right_deg: float, intensity: float) -> Spot:
    """A cone whose top edge touches the cut-off line."""
    return Spot(CUT_OFF_DEG + half_angle, right_deg, half_angle, intensity)


LOW_BEAM = Headlamps(
    name="low-beam",
    spots=(
        _cone_below_cut_off(60.0, 0.0, 4000.0),  # the wide cone: 2 x 2,000 cd
        # The hot spot, right of centre where the regulation's cut-off rises (its elbow).
        Spot(down_deg=2.6, right_deg=1.0, cutoff_deg=2.2, intensity_cd=20000.0),
    ),
)
HEADLAMPS: dict[str, Headlamps] = {LOW_BEAM.name: LOW_BEAM}

# UN R112 class B test points (per lamp, as read): name, degrees down (negative: up),
# degrees right (negative: left), the requirement's bound and whether it is a minimum.
R112_POINTS: tuple[tuple[str, float, float, float, bool], ...] = (
    ("B50L", -0.57, -3.43, 250.0, False),
    ("75R", 0.57, 1.15, 7500.0, True),
    ("50R", 0.86, 1.72, 7500.0, True),
    ("50V", 0.86, 0.0, 3750.0, True),
    ("50L", 0.86, -3.43, 9375.0, False),
    ("25L", 1.72, -9.0, 1250.0, True),
    ("25R", 1.72, 9.0, 1250.0, True),
    ("zone III (1 deg up)", -1.0, 0.0, 437.0, False),
)


def regulation_table(beam: Headlamps = LOW_BEAM) -> list[tuple[str, float, float, str, float]]:
    """Each R112 test point: name, down, right, the pair's requirement, the beam's cd."""
    rows = []
    for name, down, right, bound, minimum in R112_POINTS:
        need = f"{'>=' if minimum else '<='} {2 * bound:,.0f}"
        rows.append((name, down, right, need, beam.intensity(down, right)))
    return rows


def lamp_on_road(lamp: StreetLamp, road_edges: tuple[float, float]) -> bool:
    """Whether a lamp's mast stands on the carriageway (between the road's edges in y)."""
    south, north = road_edges
    return south < lamp.y < north
