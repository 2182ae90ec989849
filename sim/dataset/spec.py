"""A dataset spec and the runs it expands into (format: scenarios/datasets/README.md).

A dataset spec is a sweep spec (scenarios/README.md) plus the card's licence: a dataset
holds exactly the runs `monopic sweep` runs of it, with the sweep's ids, scenarios and
seeds. A grid over the nine cases is a sweep over `path.case` and the other placement
parameters of a case scenario file (scenarios/datasets/case_grid.toml).
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sim.runs.run_spec import ONE
from sim.runs.sweep import SweepSpec, expand_spec
from sim.runs.sweep import parse_spec as parse_sweep_spec
from sim.scenario.files import PEOPLE_KEY, people_files
from sim.scenario.spec import Scenario
from sim.scenario.toml_table import FieldError, read_toml

FORMAT_VERSION = 1
JPEG_QUALITY = 90


DEFAULT_LICENCE = "CC-BY-4.0"


DOC = "scenarios/datasets/README.md"


@dataclass(frozen=True)
class DatasetSpec:
    """A dataset spec of either form: which runs (`source`) plus the card's metadata."""

    path: Path
    name: str
    description: str
    licence: str
    source: SweepSpec  # the runs, as `monopic sweep` has them
    text: str = field(repr=False)  # the file as written, kept in the dataset
    # Included scenario files (sweep form): their path in the dataset and their text.
    scenario_files: tuple[tuple[str, str], ...] = ()

    @property
    def digest(self) -> str:
        """Names what the runs are made from: the spec and (sweep form) its scenario files."""
        h = hashlib.sha256(self.text.encode())
        for name, text in self.scenario_files:
            h.update(f"\0{name}\0{text}".encode())
        return h.hexdigest()[:16]


def load_spec(path: Path) -> DatasetSpec:
    """Read and validate a dataset spec (a sweep spec); every mistake names the field."""
    path = Path(path)
    text, data = read_toml(path, "dataset spec")
    if "grid" in data:
        raise FieldError(
            path, "grid", data["grid"],
            "the [grid] form is gone: a dataset spec is a sweep spec; sweep `path.case` and the "
            f"other placement keys of scenarios/datasets/case_grid.toml instead (see {DOC})",
        )  # fmt: skip
    sweep = parse_sweep_spec(path, data, DOC, "dataset spec")
    if sweep.tracker != ONE:  # the features CSV is the one-pedestrian pipeline's
        raise FieldError(
            path, "tracker", sweep.tracker,
            "a dataset's features/<run>.csv is the one-pedestrian pipeline's log; run the "
            "people tracker on a dataset's frames with `monopic video mot/<run> --tracks`",
        )  # fmt: skip
    licence = sweep.licence or DEFAULT_LICENCE
    files = _scenario_files(sweep)
    return DatasetSpec(path, sweep.name, sweep.description, licence, sweep, text, files)


def _scenario_files(sweep: SweepSpec) -> tuple[tuple[str, str], ...]:
    """The scenario files a sweep spec includes and the people files they and the includes
    name, by their path from the spec's folder (leading ../ dropped), with their text:
    copied into the dataset, part of its digest."""
    out: dict[str, str] = {}

    def add(file: Path) -> None:
        rel = Path(os.path.relpath(file, sweep.path.parent))
        name = "/".join(part for part in rel.parts if part not in ("..", "."))
        out[name] = file.read_text(encoding="utf-8")

    for include in sweep.includes:
        for file in include.files:
            add(file)
            _, data = read_toml(file, "scenario file")
            for people in people_files(file, data.get(PEOPLE_KEY, "")):
                add(people)  # the file's own bystanders
        for people in include.people:  # those the include adds
            add(people)
    return tuple(out.items())


@dataclass(frozen=True)
class DatasetRun:
    """One run of the dataset: its id, the parameters it varies and its scenario."""

    index: int
    id: str
    params: dict[str, Any]
    scenario: Scenario


def expand(spec: DatasetSpec) -> list[DatasetRun]:
    """Every run of the dataset, in the sweep's order (the run ids follow it)."""
    return _sweep_runs(spec.source)


def _sweep_runs(sweep: SweepSpec) -> list[DatasetRun]:
    """The runs `monopic sweep` makes of the spec: its ids, scenarios and seeds."""
    return [
        DatasetRun(
            index,
            run.id,
            {
                "family": run.family,
                "kind": run.kind,
                "scale": run.scale,
                "parameters": run.params,
                "seed": run.scenario.seed,
            },
            run.scenario,
        )
        for index, run in enumerate(expand_spec(sweep))
    ]
