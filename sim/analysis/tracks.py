"""The true world-plane tracks of a sweep's (or a dataset's) pedestrians, at 0.4 s steps.

Every person of every run (the scripted one first, then the others) walks its Track
(sim.scenario.motion.people_tracks, each with their own seed from the run's: exactly the
motion the run renders); sampled every STEP seconds over the run it gives a track in the
ETH/UCY text format (`frame person x y`, frames 10 apart), one file per family, so the
simulated walkers can be set beside real tracks or fed to other trajectory predictors;
run_rows gives a run's people as such rows together (frame and id kept), for the crowd
statistics (sim.analysis.crowd_stats). No rendering: seconds for a whole sweep.
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
from sim.analysis.realism import FRAME_STEP, STEP, tracks_text
from sim.runs.run_spec import RunSpec
from sim.scenario.motion import people_tracks
from sim.scenario.spec import SCRIPTED


@dataclass(frozen=True)
class RunTrack:
    """One person of a run, sampled every STEP seconds over the run (or as run_track is
    told)."""

    run: str
    family: str
    behaviour: str
    positions: np.ndarray  # (n, 2) world x, y in metres
    person: str = SCRIPTED  # the person's name in the run ("ped": the scripted one)


def run_tracks(spec: RunSpec, step: float = STEP, after: float = 0.0) -> list[RunTrack]:
    """Every person of the run (the scripted one first) every `step` s from t = 0 to
    `after` s past the run's end, where the truth has them."""
    s = spec.scenario
    paths = people_tracks(s, s.seed, s.duration + after)
    times = np.arange(0.0, s.duration + after + 1e-9, step)
    return [
        RunTrack(
            spec.id,
            spec.family or s.family,
            person.behaviour.model,
            paths[name].positions_at(times),
            name,
        )  # fmt: skip
        for name, person in zip(paths, s.people, strict=True)
    ]


def run_track(spec: RunSpec, step: float = STEP, after: float = 0.0, person: int = 0) -> RunTrack:
    """A person of the run (0: the scripted one) every `step` s from t = 0 to `after` s
    past the run's end."""
    return run_tracks(spec, step, after)[person]


def run_rows(spec: RunSpec) -> np.ndarray:
    """Every person of the run every STEP s over the run as ETH/UCY rows (frame, person,
    x, y; frames FRAME_STEP apart from 0, people numbered from 1 in the run's order)."""
    rows = [
        np.column_stack(
            [
                np.arange(len(t.positions)) * FRAME_STEP,
                np.full(len(t.positions), i + 1),
                t.positions,
            ]
        )  # fmt: skip
        for i, t in enumerate(run_tracks(spec))
    ]
    return np.concatenate(rows) if rows else np.empty((0, 4))


def sweep_tracks(runs: Sequence[RunSpec], on_run: Callable[[int], None] | None = None
                 ) -> list[RunTrack]:  # fmt: skip
    """Every person of every run, run by run."""
    out = []
    for k, spec in enumerate(runs):
        out.extend(run_tracks(spec))
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
