"""What one run is, as a worker receives it: the scenario and what to do with the run.

Plain, picklable data, light to import: sweeps expand specs into these without loading
the simulator, and executors send them to workers in other processes or on Ray.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from sim.scenario.spec import Scenario

# Whom the pipeline follows: "one", the one-pedestrian tracker (the most confident person,
# followed until lost; every result before the people tracker), or "everyone" in view
# (monopic.people.tracker with `monopic video`'s defaults: every person's landmarks every
# frame), whose robot warning is the worst person's (sim.runs.pipelines).
ONE, EVERYONE = "one", "everyone"
TRACKERS = (ONE, EVERYONE)


@dataclass(frozen=True)
class RunSpec:
    """Everything a worker needs for one run (plain, picklable data)."""

    id: str
    scenario: Scenario
    family: str = ""
    file: str = ""
    kind: str = "case"
    scale: str = "small"
    params: dict[str, Any] = field(default_factory=dict)
    sweep: str = ""
    ablation: bool = True
    stop_at_contact: bool = True
    # .rrd recordings: "failed" keeps runs where the primary predictor missed a collision
    # or raised a false alarm, "all" keeps every run, "none" records nothing.
    record: str = "none"
    record_dir: str = ""
    # The .rrd file itself, instead of record_dir/<id>.rrd (`monopic rerun --out`).
    record_file: str = ""
    intent_tree: str = ""  # a ground intent tree file: also run predictor intent-tree/ground
    tracker: str = ONE  # whom the pipeline follows (TRACKERS)
    code: str = ""  # sim.runs.code_version of the code that runs it, written into the result
