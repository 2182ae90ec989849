"""The walker interface: how the pedestrian walks its plan (sim.scenario.plan).

A walker is a frozen record of its own parameters behind one small interface (Walker).
A scenario file picks one by `[pedestrian.behaviour] model` (the registry,
sim.scenario.walkers.WALKERS), and the walker reads the rest of that table itself
(from_table). pedestrian_path (sim.scenario.path) asks it for the Track, then shifts the
Track to meet the placement's anchor, so every walker meets a placement exactly.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar, Protocol, runtime_checkable

from sim.scenario.plan import Plan
from sim.scenario.toml_table import TomlTable
from sim.scenario.track import Track


@runtime_checkable
class Walker(Protocol):
    """How a pedestrian walks its plan: a frozen record of the walker's parameters."""

    # Its name in the registry and in a scenario file's `[pedestrian.behaviour] model`.
    model: ClassVar[str]

    @property
    def cues(self) -> bool:
        """Whether it shows intent cues (head checks, slowing before a stop, ...)."""
        ...

    @property
    def start_distance(self) -> float:
        """Metres over which a placement times this walker's starts from standing (the
        rail target's acceleration distance; 0 for a walker that meets the anchor its
        own way)."""
        ...

    def placed(self, acceleration_distance: float) -> Walker:
        """This walker as a placement puts it, given the protocol's acceleration distance
        for the placement's side (the rail target takes it unless it has its own)."""
        ...

    def track(self, plan: Plan, t_end: float, seed: int) -> Track:
        """The plan walked, from t = 0 to at least t_end (straight on after); `seed` draws
        whatever varies between runs (the scenario's seed: the same run, the same walk)."""
        ...

    def identity(self) -> str:
        """Its text in the scenario's identity (spec.scenario_text: run ids and seeds);
        a new walker: its repr."""
        ...

    @classmethod
    def from_table(cls, t: TomlTable) -> Walker:
        """The walker of a scenario file's [pedestrian.behaviour] table, whose `model` the
        registry has read: its own keys checked (one FieldError line naming the file, the
        dotted field and the value), any other key refused (t.done())."""
        ...


# The one record every walker's parameters were before the walkers were types, its fields
# after model and acceleration_distance in order with their defaults then. Its repr is
# what run ids digest, so the rail and the human walker write themselves as it did
# (legacy_text) and keep every earlier run's id and seed. Never change these values.
LEGACY_FIELDS: tuple[tuple[str, float], ...] = (
    ("start_time", 1.8),
    ("stop_time", 1.2),
    ("max_yaw_rate", 90.0),
    ("speed_wander", 0.1),
    ("lateral_wander", 0.15),
    ("sway", 0.02),
    ("surge", 0.12),
    ("head_check_probability", 0.8),
    ("head_check_lead", 1.0),
    ("head_check_duration", 0.8),
    ("head_check_amplitude", 60.0),
    ("head_check_interval", 1.5),
    ("torso_share", 0.3),
    ("turn_lead", 0.4),
    ("stop_lead", 0.6),
)


def legacy_text(
    model: str, acceleration_distance: float | None, values: Mapping[str, object] | None = None
) -> str:
    """A walker as the one record's repr wrote it: `values` for its fields (the defaults
    above for those not given); a value it did not have is appended after them."""
    values = values or {}
    items: dict[str, object] = {"model": model, "acceleration_distance": acceleration_distance}
    items.update({name: values.get(name, default) for name, default in LEGACY_FIELDS})
    items.update({k: v for k, v in values.items() if k not in items})
    return "Behaviour(" + ", ".join(f"{k}={v!r}" for k, v in items.items()) + ")"
