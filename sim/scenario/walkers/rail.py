"""The `rail` walker: the Euro NCAP pedestrian target.

From standing it reaches its speed over `acceleration_distance` at constant acceleration,
then moves on straight lines at constant speed; the legs' stops and turns are instant
(sim.scenario.plan.rail_track: the plan as the placements time it). It shows no intent
cues.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

from sim.scenario.plan import Plan, rail_track
from sim.scenario.toml_table import TomlTable
from sim.scenario.track import Track
from sim.scenario.walkers.base import legacy_text

DEFAULT_ACCELERATION_DISTANCE = 1.0  # m, Euro NCAP's near-side target (far side 1.5 m)


@dataclass(frozen=True)
class RailWalker:
    """The Euro NCAP target (scenarios/README.md: units, ranges, sources)."""

    model: ClassVar[str] = "rail"
    # m from standing to speed; None: the placement's default (Euro NCAP AEB VRU
    # protocol: 1.0 m for near-side targets, 1.5 m for far-side ones; elsewhere 1.0 m).
    acceleration_distance: float | None = None

    @property
    def cues(self) -> bool:
        return False

    @property
    def start_distance(self) -> float:
        distance = self.acceleration_distance
        return DEFAULT_ACCELERATION_DISTANCE if distance is None else distance

    def placed(self, acceleration_distance: float) -> RailWalker:
        if self.acceleration_distance is not None:
            return self
        return replace(self, acceleration_distance=acceleration_distance)

    def track(self, plan: Plan, t_end: float, seed: int) -> Track:
        return rail_track(plan, self.start_distance)  # the same every run: no seed, no end

    def identity(self) -> str:
        return legacy_text(self.model, self.acceleration_distance)

    @classmethod
    def from_table(cls, t: TomlTable) -> RailWalker:
        distance = t.number("acceleration_distance", None, low=0.0, high=10.0, unit="m")
        t.done()
        return cls(acceleration_distance=distance)
