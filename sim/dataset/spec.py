"""A dataset spec and the runs it expands into (format: scenarios/datasets/README.md).

A case grid ([grid]: every combination of place_case parameters is one run) or a sweep
spec ([[include]]: the runs the sweep expands it into, with the sweep's ids and seeds).
"""

from __future__ import annotations

import hashlib
import itertools
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from monopic.cases import GROUND_DEAD_ZONE_MPS, Case
from sim.runs.sweep import SPEC_KEYS as SWEEP_KEYS
from sim.runs.sweep import SweepSpec, expand_spec
from sim.runs.sweep import parse_spec as parse_sweep_spec
from sim.scenario.cases import OBLIQUE_RANGE_DEG, place_case
from sim.scenario.spec import CameraSpec, RobotSpec, Scenario
from sim.scenario.toml_table import MISSING, FieldError, TomlTable, read_toml

FORMAT_VERSION = 1
JPEG_QUALITY = 90


DEFAULT_LICENCE = "CC-BY-4.0"


CAMERA_KEYS = ("width", "height", "vertical_fov_deg", "mount_height", "pitch_deg")


DOC = "scenarios/datasets/README.md"


GRID_KEYS = ("name", "description", "licence", "seed", "duration", "fps", "horizon", "camera",
             "grid")  # fmt: skip


@dataclass(frozen=True)
class Grid:
    """place_case parameters; the dataset is every combination."""

    cases: tuple[int, ...]
    distances: tuple[float, ...]
    lateral_offsets: tuple[float, ...] = (0.0,)
    pedestrian_speeds: tuple[float, ...] = (1.4,)
    robot_speeds: tuple[float, ...] = (0.0,)
    angles: tuple[float, ...] = (45.0,)
    repeats: int = 1


@dataclass(frozen=True)
class CaseGrid:
    """The case-grid form's runs: the grid and the settings every one of its runs shares."""

    seed: int
    duration: float
    fps: float
    horizon: float
    camera: CameraSpec
    grid: Grid


@dataclass(frozen=True)
class DatasetSpec:
    """A dataset spec of either form: which runs (`source`) plus the card's metadata."""

    path: Path
    name: str
    description: str
    licence: str
    source: CaseGrid | SweepSpec  # a case grid, or a sweep spec's runs as `monopic sweep` has them
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
    """Read and validate a dataset spec of either form; every mistake names the field.

    The form follows from the keys: [grid] is a case grid, [[include]] a sweep spec.
    """
    path = Path(path)
    text, data = read_toml(path, "dataset spec")
    if _form(path, data) == "sweep":
        sweep = parse_sweep_spec(path, data, DOC)
        licence = sweep.licence or DEFAULT_LICENCE
        files = _scenario_files(sweep)
        return DatasetSpec(path, sweep.name, sweep.description, licence, sweep, text, files)
    top = TomlTable(path, "", data, DOC)
    name = top.slug("name")
    description = top.text("description", "")
    licence = top.text("licence", DEFAULT_LICENCE, nonempty=True)
    seed = top.integer("seed", 0, low=0, high=2**31 - 1)
    duration = top.number("duration", 3.0, low=0.2, high=60.0)
    fps = top.number("fps", 15.0, low=1.0, high=60.0)
    horizon = top.number("horizon", 1.0, low=0.1, high=10.0)
    cam_t = top.table("camera")
    base = CameraSpec()
    camera = CameraSpec(
        width=cam_t.integer("width", base.width, low=64, high=4096),
        height=cam_t.integer("height", base.height, low=64, high=4096),
        vertical_fov_deg=cam_t.number(
            "vertical_fov_deg", base.vertical_fov_deg, low=10.0, high=150.0
        ),
        mount_height=cam_t.number("mount_height", base.mount_height, low=0.1, high=5.0),
        pitch_deg=cam_t.number("pitch_deg", base.pitch_deg, low=-45.0, high=45.0),
    )
    cam_t.done()
    g = top.table("grid")
    cases = g.numbers("cases", low=1, high=9, nonempty=True, distinct=True)
    if any(c != int(c) for c in cases):
        raise g.error("cases", list(cases), "case numbers are integers 1-9")
    lo, hi = OBLIQUE_RANGE_DEG
    angles = g.numbers("angles", (45.0,), low=lo, high=hi, nonempty=True, distinct=True)
    for k, a in enumerate(angles):
        if not lo < a < hi:
            strictly = f"an oblique angle must lie strictly between {lo:.1f} and {hi:.1f}"
            raise FieldError(path, f"grid.angles[{k}]", a, strictly)

    def axis(key: str, default: Any, low: float, high: float) -> tuple[float, ...]:
        return g.numbers(key, default, low=low, high=high, nonempty=True, distinct=True)

    grid = Grid(
        cases=tuple(int(c) for c in cases),
        distances=axis("distances", MISSING, -50.0, 50.0),
        lateral_offsets=axis("lateral_offsets", (0.0,), -20.0, 20.0),
        pedestrian_speeds=axis("pedestrian_speeds", (1.4,), GROUND_DEAD_ZONE_MPS, 8.0),
        robot_speeds=axis("robot_speeds", (0.0,), 0.0, 20.0),
        angles=angles,
        repeats=g.integer("repeats", 1, low=1, high=1000),
    )
    g.done()
    top.done()
    source = CaseGrid(seed, duration, fps, horizon, camera, grid)
    return DatasetSpec(path, name, description, licence, source, text)


def _form(path: Path, data: dict[str, Any]) -> str:
    """'grid' or 'sweep': which form a dataset spec is, by its keys; else a FieldError."""
    forms = "[grid] (a case grid) or [[include]] (a sweep spec)"
    if "grid" in data and "include" in data:
        both = f"a dataset spec has either {forms}, not both; see {DOC}"
        raise FieldError(path, "grid", data["grid"], both)
    if "grid" in data:
        return "grid"
    if "include" in data:
        return "sweep"
    neither = f"a dataset spec needs {forms}"
    for key, value in data.items():
        if key not in GRID_KEYS and key not in SWEEP_KEYS:
            raise FieldError(path, key, value, f"unknown key, and {neither}; see {DOC}")
    raise FieldError(path, "grid", MISSING, f"missing, and so is include: {neither}; see {DOC}")


def _scenario_files(sweep: SweepSpec) -> tuple[tuple[str, str], ...]:
    """The scenario files a sweep spec includes, named by their path from the spec's folder
    (leading ../ dropped), with their text: copied into the dataset, part of its digest."""
    out: dict[str, str] = {}
    for include in sweep.includes:
        for file in include.files:
            rel = Path(os.path.relpath(file, sweep.path.parent))
            name = "/".join(part for part in rel.parts if part not in ("..", "."))
            out[name] = file.read_text(encoding="utf-8")
    return tuple(out.items())


@dataclass(frozen=True)
class DatasetRun:
    """One run of the dataset: its id, the parameters it varies and its scenario."""

    index: int
    id: str
    params: dict[str, Any]
    scenario: Scenario


def run_seed(spec_seed: int, index: int) -> int:
    """The world seed of run `index`: independent streams per run, same for the same spec."""
    return int(np.random.SeedSequence([spec_seed, index]).generate_state(1)[0] >> 1)


def expand(spec: DatasetSpec) -> list[DatasetRun]:
    """Every run of the dataset, in a fixed order (the run ids follow it)."""
    if isinstance(spec.source, SweepSpec):
        return _sweep_runs(spec.source)
    return _grid_runs(spec, spec.source)


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


def _grid_runs(spec: DatasetSpec, source: CaseGrid) -> list[DatasetRun]:
    """Every combination of the grid.

    Axes a case ignores collapse: standing still has no walking speed or angle, only the
    oblique cases use the angle.
    """
    g = source.grid
    combos: list[dict[str, Any]] = []
    seen = set()
    for case_n, dist, lat, pspeed, rspeed, angle in itertools.product(
        g.cases, g.distances, g.lateral_offsets, g.pedestrian_speeds, g.robot_speeds, g.angles
    ):
        case = Case(case_n)
        if case is Case.STILL:
            pspeed = 0.0
        if case.lateral == 0 or case.depth == 0:
            angle = None
        key = (case_n, dist, lat, pspeed, rspeed, angle)
        if key in seen:
            continue
        seen.add(key)
        for rep in range(g.repeats):
            combos.append(
                {
                    "case": case_n,
                    "distance": dist,
                    "lateral_offset": lat,
                    "pedestrian_speed": pspeed,
                    "robot_speed": rspeed,
                    "angle_deg": angle,
                    "repeat": rep,
                }
            )
    runs = []
    robot = replace(RobotSpec(), camera=source.camera)
    for index, params in enumerate(combos):
        run_id = f"r{index:04d}"
        seed = run_seed(source.seed, index)
        try:
            scenario = place_case(
                Case(params["case"]),
                distance=params["distance"],
                lateral_offset=params["lateral_offset"],
                pedestrian_speed=params["pedestrian_speed"] or 1.4,
                robot_speed=params["robot_speed"],
                angle_deg=params["angle_deg"] or 45.0,
                duration=source.duration,
                dt=1.0 / source.fps,
                horizon=source.horizon,
                robot=robot,
                seed=seed,
                name=f"{spec.name}-{run_id}",
            )
        except ValueError as err:
            raise FieldError(spec.path, "grid", params, str(err)) from None
        runs.append(DatasetRun(index, run_id, {**params, "seed": seed}, scenario))
    return runs
