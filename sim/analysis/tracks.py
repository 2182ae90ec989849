"""The true world-plane tracks of a sweep's (or a dataset's) pedestrians, at 0.4 s steps.

Every person of every run (the scripted one first, then the others) walks its Track
(sim.scenario.path, as its behaviour walks it, with the run's seed: exactly the motion
the run renders); sampled every STEP seconds over the
run it gives a track in the ETH/UCY text format (`frame person x y`, frames 10 apart),
one file per family, so the simulated walkers can be set beside real tracks or fed to
other trajectory predictors. No rendering: seconds for a whole sweep.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from monopic.errors import UserError
from monopic.output import write_text_atomically
from sim.analysis.realism import STEP, tracks_text
from sim.runs.run_spec import RunSpec
from sim.scenario.path import pedestrian_path
from sim.scenario.spec import SCRIPTED, person_name


@dataclass(frozen=True)
class RunTrack:
    """One person of a run, sampled every STEP seconds over the run (or as run_track is
    told)."""

    run: str
    family: str
    behaviour: str
    positions: np.ndarray  # (n, 2) world x, y in metres
    person: str = SCRIPTED  # the person's name in the run ("ped": the scripted one)


def run_track(spec: RunSpec, step: float = STEP, after: float = 0.0, person: int = 0) -> RunTrack:
    """A person of the run (0: the scripted one) every `step` s from t = 0 to `after` s
    past the run's end."""
    s = spec.scenario
    walker = s.people[person]
    path = pedestrian_path(walker, s.duration + after, s.seed)
    times = np.arange(0.0, s.duration + after + 1e-9, step)
    return RunTrack(spec.id, spec.family or s.family, walker.behaviour.model,
                    path.positions_at(times), person_name(walker, person))  # fmt: skip


def sweep_tracks(runs: Sequence[RunSpec], on_run: Callable[[int], None] | None = None
                 ) -> list[RunTrack]:  # fmt: skip
    """Every person of every run, run by run."""
    out = []
    for k, spec in enumerate(runs):
        out.extend(run_track(spec, person=i) for i in range(len(spec.scenario.people)))
        if on_run is not None:
            on_run(k)
    return out


def write_tracks(tracks: Sequence[RunTrack], out: Path) -> list[Path]:
    """`<family>.txt` per family and `index.csv` (file, id, run, family, behaviour, steps,
    person); whole files."""
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    families = sorted({t.family for t in tracks})
    index = io.StringIO()
    rows = csv.writer(index, lineterminator="\n")
    rows.writerow(("file", "id", "run", "family", "behaviour", "steps", "person"))
    for family in families:
        mine = [t for t in tracks if t.family == family]
        name = f"{family}.txt"
        write_text_atomically(out / name, tracks_text([t.positions for t in mine]))
        written.append(out / name)
        for i, t in enumerate(mine, start=1):
            rows.writerow((name, i, t.run, family, t.behaviour, len(t.positions), t.person))
    write_text_atomically(out / "index.csv", index.getvalue())
    return [*written, out / "index.csv"]
