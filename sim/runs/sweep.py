"""Sweeps: a SPEC file lists scenario files and how to sample them; runs go to a results file.

A sweep spec (scenarios/sweeps/*.toml, documented in scenarios/README.md):

    name = "demo"
    ablation = true                 # also run the ground-truth-crop pipeline
    licence = "CC-BY-4.0"           # only for `monopic dataset` (a sweep ignores it)
    intent_tree = "../trees/ground.json"  # optional: also run predictor intent-tree/ground
    camera = "imx273"               # optional: every run's camera sensor (default: the file's)
    [[include]]
    files = ["../families/car/*.toml"]   # globs, relative to the spec
    sampling = "random"             # "file" (as each file says), "base", "grid", "random"
    runs = 3                        # random draws per file (random sampling only)
    seed = 7
    people = "../people/pavement_pair.toml"  # optional: bystanders every run of these adds
    [include.parameters]            # add or replace sweep parameters of those files
    "robot.speed" = [0.0, 8.33]     # (with "base": a grid over these alone)

Expansion is deterministic: a run's id is the file's name, its draw number and a digest
of the complete scenario, and its seed derives from the same, so re-expanding the spec
finds the same runs (resume) and any executor produces the same results.

A spec's `camera` (a sensor preset, sim.sensor.spec.PRESETS) is put into each run's
scenario after its id and seed are made from the file's own scenario: the same sweep under
two cameras has the same runs, paired by id. Its results are kept apart by the code
version (CAMERA_TAG), and `monopic rerun` reads the camera back from there.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import sys
import time
import zlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Protocol

from tqdm import tqdm

from monopic.cli.args import output_folder
from monopic.errors import UserError
from monopic.output import stale_temporaries_cleared
from sim.runs.code_version import code_version
from sim.runs.result import SCHEMA
from sim.runs.results_file import ResultsState, ResultsWriter, check_unlocked, read_rows, scan
from sim.runs.run_spec import EVERYONE, ONE, TRACKERS, RunSpec
from sim.scenario.files import (
    PEOPLE_KEY,
    ScenarioFile,
    ScenarioFileError,
    Sweep,
    Values,
    expand,
    is_scenario_file,
    load,
    parse_parameters,
    people_files,
    read_people,
    unsweepable,
)
from sim.scenario.spec import Scenario, scenario_text
from sim.scenario.toml_table import FieldError, TomlTable, read_toml
from sim.sensor.spec import PRESETS as CAMERAS
from sim.sensor.spec import SensorSpecError, preset

INCLUDE_SAMPLING = ("file", "base", "grid", "random")
SPEC_KEYS = (
    "name", "description", "ablation", "licence", "intent_tree", "tracker", "camera", "include",
)  # fmt: skip


@dataclass(frozen=True)
class Include:
    """One [[include]] entry of a sweep spec."""

    files: tuple[Path, ...]
    sampling: str = "file"
    runs: int | None = None
    seed: int | None = None
    parameters: dict[str, Any] = field(default_factory=dict)
    # People files (of [[pedestrians]] entries) every run of these files adds after the
    # file's own people: bystanders for a family without copying it.
    people: tuple[Path, ...] = ()


@dataclass(frozen=True)
class SweepSpec:
    path: Path
    name: str
    description: str
    ablation: bool
    includes: tuple[Include, ...]
    # The licence a dataset of these runs states (`monopic dataset`); a sweep ignores it.
    licence: str | None = None
    # A ground intent tree file (`monopic tree train --mode ground`): every run also runs
    # predictor intent-tree/ground with it, after the fixed ones (a dataset ignores it).
    intent_tree: Path | None = None
    # Whom the pipeline follows (sim.runs.run_spec.TRACKERS): "one" pedestrian, as every
    # sweep before the people tracker, or "everyone" in view, judged person by person.
    tracker: str = ONE
    # The camera's sensor preset every run has (sim.sensor.spec.PRESETS); None: each
    # scenario file's own camera, as every sweep before the camera model.
    camera: str | None = None


def load_spec(path: Path | str) -> SweepSpec:
    """Read and check a sweep spec; globs must match scenario files."""
    path = Path(path)
    _, data = read_toml(path, "sweep spec")
    return parse_spec(path, data)


def parse_spec(
    path: Path, data: Mapping[str, Any], doc: str = "scenarios/README.md", what: str = "sweep spec"
) -> SweepSpec:
    """Check a sweep spec's data (keys SPEC_KEYS); `doc` is where the keys are documented."""
    if is_scenario_file(data):
        raise UserError(
            f"{path}: this is a scenario file, not a {what} (a {what} lists scenario files "
            f"under [[include]], see {doc}): record it alone with `monopic record {path}`"
        )
    top = TomlTable(path, "", data, doc)
    name = top.slug("name")
    description = top.text("description", "")
    ablation = top.flag("ablation", True)
    licence = top.text("licence", None, nonempty=True)
    intent_tree = _intent_tree(top, path)
    tracker = top.text("tracker", ONE, TRACKERS)
    camera = top.text("camera", None, tuple(CAMERAS))
    includes = []
    for entry in top.tables("include"):
        patterns = entry.raw("files")
        if (
            not isinstance(patterns, list)
            or not patterns
            or not all(isinstance(p, str) for p in patterns)
        ):
            raise entry.error("files", patterns, "must be a non-empty list of glob patterns")
        files: list[Path] = []
        for pattern in patterns:
            matched = sorted(_glob(path.parent, pattern))
            if not matched:
                raise entry.error("files", pattern, "matches no scenario file")
            files.extend(m for m in matched if m not in files)
        sampling = entry.text("sampling", "file", INCLUDE_SAMPLING)
        runs = entry.integer("runs", None, low=1)
        seed = entry.integer("seed", None)
        for key, value in (("runs", runs), ("seed", seed)):
            if value is not None and sampling in ("base", "grid"):
                raise entry.error(
                    key, value, f'draws at random only: sampling = "{sampling}" would ignore it'
                )
        parameters = parse_parameters(entry, need_steps=sampling in ("grid", "base"))
        for key in parameters:
            reason = unsweepable(key)  # a file's own [sweep.parameters] obey the same rule
            if reason is not None:
                field = f"{entry.field('parameters')}.{key}"
                raise ScenarioFileError(path, field, entry.data["parameters"][key], reason)
        _check_people_parameter(entry, path, parameters.get(PEOPLE_KEY))
        people = _people(entry, path, entry.raw(PEOPLE_KEY, None), entry.field(PEOPLE_KEY))
        entry.done()
        includes.append(Include(tuple(files), sampling, runs, seed, parameters, people))
    top.done()
    if not includes:
        raise ScenarioFileError(path, "include", [], "a sweep needs at least one [[include]]")
    return SweepSpec(
        path, name, description, ablation, tuple(includes), licence, intent_tree, tracker, camera
    )


def _people(entry: TomlTable, spec: Path, value: Any, field: str) -> tuple[Path, ...]:
    """The people files an include names (relative to the spec), each read now: a file
    that is not one is refused before any run."""
    if value is None:
        return ()
    files = people_files(spec, value, field)
    for file in files:
        read_people(file)
    return files


def _check_people_parameter(entry: TomlTable, spec: Path, dist: Any) -> None:
    """A swept `people` in [include.parameters]: a set of people files (relative to the
    spec, "" for none), each there and a people file."""
    if dist is None:
        return
    field = f"{entry.field('parameters')}.{PEOPLE_KEY}"
    if not isinstance(dist, Values) or not all(isinstance(v, str) for v in dist.values):
        raise ScenarioFileError(
            spec, field, entry.data["parameters"][PEOPLE_KEY],
            'must be a list of people files (relative to the spec; "" for none)',
        )  # fmt: skip
    for value in dist.values:
        _people(entry, spec, value, field)


def _with_people(
    params: dict[str, Any], include: Include, file: ScenarioFile, spec: Path
) -> dict[str, Any]:
    """A run's values with the include's people: `people` names the file's own people
    files, then the include's swept ones, then its `people`, each relative to the scenario
    file (as the file's own key is; a rerun rebuilds the run from the file and these
    values). Values of an include without people are as they were (their run ids too)."""
    swept = PEOPLE_KEY in include.parameters
    if not include.people and not swept:
        return params
    out = dict(params)
    written = file.data.get(PEOPLE_KEY, "")  # the file's own key (its sweep may vary it)
    own = written if swept else out.get(PEOPLE_KEY, written)
    names = [n for n in (own if isinstance(own, list) else [own]) if n]
    added = (*(people_files(spec, out[PEOPLE_KEY]) if swept else ()), *include.people)
    names += [_relative(p, file.path) for p in added]
    out[PEOPLE_KEY] = names if len(names) != 1 else names[0]
    if not names:
        out[PEOPLE_KEY] = ""  # a swept "": none
    return out


def _relative(path: Path, file: Path) -> str:
    """`path` as written from the folder of `file` (forward slashes)."""
    return Path(os.path.relpath(path, file.parent)).as_posix()


def _intent_tree(top: TomlTable, path: Path) -> Path | None:
    """The spec's `intent_tree`, relative to the spec, checked by loading it."""
    value = top.text("intent_tree", None, nonempty=True)
    if value is None:
        return None
    tree = Path(value) if Path(value).is_absolute() else path.parent / value
    if not tree.is_file():
        raise top.error("intent_tree", value, f"no such file ({tree})")
    from monopic.tree.serialise import load_intent_model

    try:
        load_intent_model(tree)
    except UserError as err:
        raise top.error("intent_tree", value, str(err)) from None
    return tree.resolve()


def _glob(base: Path, pattern: str) -> list[Path]:
    if Path(pattern).is_absolute():
        return [Path(p) for p in sorted(Path("/").glob(pattern.lstrip("/")))]
    return [p for p in base.glob(pattern) if p.is_file()]


def _effective_sweep(include: Include, file: ScenarioFile) -> Sweep | None:
    """The file's sweep as the include entry modifies it (None: just the base scenario).

    "base" drops the file's own sweep: one run at the file's values, or with
    [include.parameters] a grid over those parameters only (never silently dropped)."""
    if include.sampling == "base":
        return Sweep("grid", dict(include.parameters)) if include.parameters else None
    own = file.sweep
    params = dict(own.parameters) if own else {}
    params.update(include.parameters)
    sampling = include.sampling if include.sampling != "file" else (own.sampling if own else "grid")
    runs = include.runs or (own.runs if own else 1)
    seed = include.seed if include.seed is not None else (own.seed if own else 0)
    if sampling == "grid":
        for key, dist in params.items():
            if getattr(dist, "steps", 0) is None:
                raise ScenarioFileError(
                    file.path, f"sweep.parameters.{key}", key, "a range needs steps in a grid"
                )
    return Sweep(sampling, params, runs, seed)


def run_id(file: ScenarioFile, index: int, digest: str) -> str:
    return f"{file.name}/{index:04d}-{digest}"


def run_scenario(file: ScenarioFile, params: Mapping[str, Any]) -> tuple[Scenario, Scenario, str]:
    """A run's scenario as built from the file and its params, the same at seed 0, and the
    digest of that (the last part of its run id): what `monopic rerun` rebuilds a run with."""
    built = file.scenario(params, name=file.name)
    probe = replace(built, seed=0)
    return built, probe, hashlib.sha1(scenario_text(probe).encode()).hexdigest()[:8]


def run_seed(file: ScenarioFile, digest: str, seed: int) -> int:
    """The run's world seed: the file's (or a swept) seed mixed with the scenario's digest."""
    return (seed + zlib.crc32(f"{file.name}:{digest}".encode())) % 2**31


def expand_spec(spec: SweepSpec) -> list[RunSpec]:
    """Every run of the sweep, validated, in a stable order (duplicates dropped)."""
    runs: list[RunSpec] = []
    seen: set[str] = set()
    for include in spec.includes:
        for path in include.files:
            file = load(path)
            sweep = _effective_sweep(include, file)
            try:
                combos = list(expand(sweep, file.name))
            except ValueError as err:
                raise ScenarioFileError(path, "sweep", include.sampling, str(err)) from None
            drawn: set[tuple[str, int]] = set()
            for index, combo in enumerate(combos):
                params = _with_people(combo, include, file, spec.path)
                built, probe, digest = run_scenario(file, params)
                rid = run_id(file, index, digest)
                # The same scenario twice (e.g. a walking speed swept for a person who
                # stands) is one run: its results would be identical. A swept `seed` makes
                # repeats: the run's seed derives from it.
                if rid in seen or (digest, built.seed) in drawn:
                    continue
                seen.add(rid)
                drawn.add((digest, built.seed))
                seed = run_seed(file, digest, built.seed)
                scenario = replace(probe, name=rid, seed=seed)
                if spec.camera is not None:  # after the id and seed: the file's own runs
                    scenario = with_camera(scenario, spec.camera, spec.path)
                runs.append(
                    RunSpec(
                        id=rid,
                        scenario=scenario,
                        family=file.family,
                        file=str(path),
                        kind=file.kind,
                        scale=str(params.get("scale", file.scale.value)),  # swept: applied
                        params={k: _plain(v) for k, v in params.items()},
                        sweep=spec.name,
                        ablation=spec.ablation,
                        intent_tree=str(spec.intent_tree) if spec.intent_tree else "",
                        tracker=spec.tracker,
                    )
                )
    return runs


def with_camera(scenario: Scenario, name: str, spec: Path) -> Scenario:
    """The scenario with the camera sensor preset `name` (the spec's `camera`); a camera
    that cannot keep the scenario's frame rate is refused naming the spec's field."""
    try:
        camera = replace(scenario.robot.camera, sensor=preset(name))
        return replace(scenario, robot=replace(scenario.robot, camera=camera))
    except SensorSpecError as err:
        raise FieldError(spec, "camera", name, f"run {scenario.name}: {err}") from None


def _plain(value: Any) -> Any:
    return json.loads(json.dumps(value))


@dataclass(frozen=True)
class SweepOutcome:
    total: int
    skipped: int  # already in the results file
    finished: int  # run now and appended
    failed: tuple[tuple[str, str], ...]  # (run id, error)
    seconds: float


Executor = Callable[[Sequence[RunSpec], Callable[[dict[str, Any]], None]], None]


def recordings_folder(out: Path, record_dir: Path | None = None) -> Path:
    """Where a sweep's .rrd recordings go: the given folder or <results>_rrd/ beside it."""
    return record_dir if record_dir is not None else out.parent / f"{out.stem}_rrd"


def aside_moves(out: Path, folder: Path, tag: str) -> list[tuple[Path, Path]]:
    """Where set_aside moves a stale results file and its recordings folder
    (<name>.<tag>...); an earlier one already there is refused, never overwritten."""
    moves = [(out, out.with_name(f"{out.stem}.{tag}{out.suffix}"))]
    if folder.exists():
        moves.append((folder, folder.with_name(f"{folder.name}.{tag}")))
    for _, target in moves:
        if target.exists():
            raise UserError(f"{target}: already there; move it away to restart {out}")
    return moves


def set_aside(moves: list[tuple[Path, Path]]) -> None:
    """Rename a stale results file and its recordings folder (aside_moves)."""
    for source, target in moves:
        try:
            source.rename(target)
        except OSError as err:
            raise UserError(f"{source}: cannot set it aside ({err.strerror or err})") from None
        print(f"set aside: {source} -> {target}", file=sys.stderr)


@dataclass(frozen=True)
class OutputCheck:
    """What a sweep found at its output before its first run (check_output)."""

    state: ResultsState | None  # the results file as it stands (None: not there yet)
    code: str  # the code version the sweep's lines carry (sweep_code)
    folder: Path  # where the recordings go
    moves: tuple[tuple[Path, Path], ...] = ()  # --restart: what is set aside first

    @property
    def done(self) -> frozenset[str]:
        """The ids the sweep will find there (none when the file is set aside)."""
        return self.state.ids if self.state is not None and not self.moves else frozenset()


def check_output(
    spec: SweepSpec,
    out: Path,
    record: str = "failed",
    record_dir: Path | None = None,
    restart: bool = False,
) -> OutputCheck:
    """Every check a sweep makes on its output before its first run; the dry run calls it
    too, so it refuses what the run refuses, with the same line, and changes nothing.

    The results path (a file, in a folder that can be made, writable), what the file holds
    (whole lines; another sweep's runs, other code's, a newer schema: refused unless
    `restart` sets the file aside), another sweep appending to it (its lock) and the
    recordings folder (it can be made, unless `record` is "none")."""
    if out.is_dir():
        raise UserError(f"--out {out}: is a folder; give a file name")
    _check_makeable(out.parent, f"--out {out.parent}: a file is in the way of this folder")
    _check_writable(out, "{path}: cannot write there ({reason}); use another --out")
    code = sweep_code(spec)
    folder = recordings_folder(out, record_dir)
    state = scan(out) if out.exists() else None
    other = state.other_code(code) if state else None
    newer = state.newer_schema(SCHEMA) if state else None
    if newer and not restart:
        line, schema = newer
        raise UserError(
            f"{out}:{line}: a result of schema {schema}, newer than this code's {SCHEMA} "
            "(written by newer code, which alone reads it); to redo its runs with this code, "
            "use another --out, or --restart to set the file aside and start over"
        )
    mixed = state.other_sweeps(spec.name) if state else None
    if mixed and not restart:
        names = ", ".join(f"{n!r} ({k} run{'' if k == 1 else 's'})" for n, k in mixed.most_common())
        raise UserError(
            f"{out}: holds runs of another sweep ({names}), not of {spec.name!r}; a results "
            "file holds one sweep, so give this one another --out (or --restart to set that "
            "file aside and start over)"
        )
    if other and not restart:
        versions = ", ".join(f"{n} by {c}" for c, n in other.most_common())
        raise UserError(
            f"{out}: holds runs of other code ({versions}; this code is {code}), and a "
            "sweep resumes only its own code's runs; use another --out, or --restart to "
            "set the old results aside and start over"
        )
    check_unlocked(out)
    moves: list[tuple[Path, Path]] = []
    if mixed:
        moves = aside_moves(out, folder, mixed.most_common(1)[0][0])
    elif other or newer:
        tag = other.most_common(1)[0][0] if other and len(other) == 1 else "mixed"
        moves = aside_moves(out, folder, tag if other else f"schema{newer[1]}")
    if record != "none":
        message = (
            "{path}: cannot make the recordings folder ({reason}); use --recordings DIR or "
            "--record none"
        )
        _check_makeable(folder, message.format(path=folder, reason="a file is in the way"))
        _check_writable(folder, message)
    return OutputCheck(state, code, folder, tuple(moves))


def _check_makeable(folder: Path, message: str) -> None:
    """`mkdir -p folder` would not meet a file on its way (`message` if it would)."""
    for part in (folder, *folder.parents):
        if part.exists():
            if not part.is_dir():
                raise UserError(message)
            return


def _check_writable(path: Path, message: str) -> None:
    """`path` (or, while it is not there, the nearest folder it would be made in) can be
    written; `message` takes {path} and {reason} (as the error the write would raise)."""
    target = next(p for p in (path, *path.parents) if p.exists())
    if os.access(target, os.W_OK):
        return
    readonly = os.statvfs(target).f_flag & os.ST_RDONLY
    reason = os.strerror(errno.EROFS if readonly else errno.EACCES)
    raise UserError(message.format(path=path, reason=reason))


def sweep_code(spec: SweepSpec) -> str:
    """The code version its results carry: with an intent tree, the tree file's digest too.

    So a results file made with one tree is not resumed with another (it is "other code"),
    nor one made with the one-pedestrian tracker with the people tracker (PEOPLE_TAG), nor
    one of each file's own camera with a camera the spec names, or one camera with another
    (CAMERA_TAG: any `camera` key, "ideal" too, since a file may name a real camera).
    """
    code = code_version()
    if spec.tracker == EVERYONE:
        code += PEOPLE_TAG
    if spec.camera is not None:
        code += f"{CAMERA_TAG}{spec.camera}"
    if spec.intent_tree is None:
        return code
    return f"{code}{TREE_TAG}{tree_digest(spec.intent_tree)}"


TREE_TAG = "+tree-"  # joins the code version and the intent tree's digest (sweep_code)
PEOPLE_TAG = "+everyone"  # follows the code version of a sweep with the people tracker
CAMERA_TAG = "+camera-"  # then the camera preset of a sweep whose spec names one


def camera_of_code(code: str | None) -> str | None:
    """The camera preset a sweep's spec named, from its lines' code (None: none named)."""
    camera = (code or "").partition(TREE_TAG)[0].partition(CAMERA_TAG)[2]
    return camera or None


def tree_digest(path: Path) -> str:
    """8 hex digits over an intent tree file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:8]


def run_sweep(
    spec: SweepSpec,
    out: Path,
    executor: Executor,
    ablation: bool | None = None,
    progress: bool = True,
    limit: int | None = None,
    record: str = "failed",
    record_dir: Path | None = None,
    restart: bool = False,
) -> SweepOutcome:
    """Run every run of `spec` missing from `out`, appending each result as it finishes.

    `ablation` overrides the spec's flag; `limit` stops after that many new runs (to
    measure a rate, or to test resuming). `record` ("failed", "all" or "none") says which
    runs keep a .rrd recording in `record_dir` (default: beside the results file).
    A results file holding runs of other code (sim.runs.code_version) is not resumed: that
    is an error, or with `restart` the file and its recordings are set aside first.
    The recordings folder is cleared of stale temporaries (monopic.output) before the runs
    start and after the workers are gone, however the sweep ends: a worker stopped
    mid-run dies without deleting the recording it was writing.
    """
    runs = expand_spec(spec)
    if ablation is not None:
        runs = [replace(r, ablation=ablation) for r in runs]
    check = check_output(spec, out, record, record_dir, restart)
    folder = check.folder
    runs = [replace(r, record=record, record_dir=str(folder), code=check.code) for r in runs]
    output_folder(out.parent, "--out")
    set_aside(list(check.moves))
    # The lock held, no other sweep of this results file writes recordings: the
    # temporaries found in its folder are a killed sweep's, or being written by a sweep
    # of another results file sharing the folder (its processes run: kept).
    with ResultsWriter(out) as writer, stale_temporaries_cleared(folder):
        if record != "none":
            try:
                folder.mkdir(parents=True, exist_ok=True)
            except OSError as err:
                raise UserError(
                    f"{folder}: cannot make the recordings folder ({err.strerror or err}); "
                    "use --recordings DIR or --record none"
                ) from None
        state = writer.state
        todo = [r for r in runs if r.id not in state.ids]
        skipped = len(runs) - len(todo)
        if limit is not None:
            todo = todo[:limit]
        start = time.perf_counter()
        if skipped and progress:
            say_skipped(out, skipped, len(runs), len(todo))
        finished, failed = run_missing(todo, executor, writer, spec.name, progress)
    return SweepOutcome(len(runs), skipped, finished, tuple(failed), time.perf_counter() - start)


class Resumable(Protocol):
    """A run as the Euro NCAP grid and the closed loop hand them to their workers: a
    frozen dataclass with its id and the code version its line will carry."""

    id: str
    code: str


def run_resumable(
    runs: Sequence[Resumable], out: Path, executor: Executor, desc: str, progress: bool = True
) -> SweepOutcome:
    """Run every run missing from the results file `out` (by id), appending each result
    line as it finishes, each stamped with this code's version (resumed as a sweep is)."""
    code = code_version()
    stamped = [replace(r, code=code) for r in runs]  # type: ignore[type-var]
    with ResultsWriter(out) as writer:
        todo = [r for r in stamped if r.id not in writer.state.ids]
        skipped = len(stamped) - len(todo)
        start = time.perf_counter()
        if skipped and progress:
            say_skipped(out, skipped, len(stamped), len(todo))
        finished, failed = run_missing(todo, executor, writer, desc, progress)
    return SweepOutcome(len(runs), skipped, finished, tuple(failed), time.perf_counter() - start)


def rows_of(out: Path, runs: Sequence[Resumable]) -> list[dict[str, Any]]:
    """The result lines of `runs` in a results file, in the runs' order (one each)."""
    wanted = {r.id for r in runs}
    rows = {row["id"]: row for row in read_rows(out) if row["id"] in wanted}
    return [rows[r.id] for r in runs if r.id in rows]


def say_skipped(out: Path, skipped: int, total: int, todo: int) -> None:
    """The resume line: what a rerun finds already done."""
    print(f"{out}: {skipped} of {total} runs already there, running the other {todo}",
          file=sys.stderr)  # fmt: skip


class Finished(Protocol):
    """Where run_missing hands each finished run's row: a results file (ResultsWriter), a
    dataset's records."""

    def append(self, row: dict[str, Any]) -> None: ...


def run_missing(
    todo: Sequence[Any], executor: Executor, writer: Finished, desc: str, progress: bool
) -> tuple[int, list[tuple[str, str]]]:
    """Run `todo` on `executor`, appending each result line to `writer` as it arrives (a
    crash loses no finished run) and naming each failure above the progress bar; returns
    how many finished and the failures (id, error). The sweep, the Euro NCAP grid and the
    dataset all run their runs through here."""
    failed: list[tuple[str, str]] = []
    finished = 0
    with tqdm(
        total=len(todo), unit="run", desc=desc, disable=not progress, dynamic_ncols=True
    ) as bar:

        def on_result(row: dict[str, Any]) -> None:
            nonlocal finished
            if "error" in row:
                failed.append((row["id"], row["error"]))
                bar.write(f"run {row['id']} failed: {row['error'].strip().splitlines()[-1]}")
            else:
                writer.append(row)
                finished += 1
            bar.update(1)

        if todo:
            executor(list(todo), on_result)
    return finished, failed
