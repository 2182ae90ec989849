"""The walkers a scenario file can name, by its `[pedestrian.behaviour] model` key.

Each walker type is one module (its record, its reading of the table, its Track; the
interface is base.Walker) and one line of WALKERS. A table without `model` is the rail
target's, as a PedestrianSpec without a walker is.
"""

from __future__ import annotations

from sim.scenario.toml_table import TomlTable
from sim.scenario.walkers.base import Walker
from sim.scenario.walkers.human import HumanWalker
from sim.scenario.walkers.rail import RailWalker
from sim.scenario.walkers.replay import ReplayWalker

WALKERS: dict[str, type[Walker]] = {
    RailWalker.model: RailWalker,
    HumanWalker.model: HumanWalker,
    ReplayWalker.model: ReplayWalker,
}


def walker_from_table(t: TomlTable) -> Walker:
    """The walker of a [pedestrian.behaviour] table: its `model` (one of WALKERS) reads
    the rest (a one-line FieldError on an unknown model, a bad value or a key of another)."""
    model = t.text("model", RailWalker.model, tuple(WALKERS))
    return WALKERS[model].from_table(t)


__all__ = ["WALKERS", "HumanWalker", "RailWalker", "ReplayWalker", "Walker", "walker_from_table"]
