"""A run of a results file rebuilt from its line and run again (`monopic rerun`).

A sweep's result line records what made its run: the scenario file (`file`, as the sweep
found it from the folder it ran in), the swept values (`params`), the world seed (`seed`),
the code (`code`, with the intent tree's digest when the sweep ran one) and, by its
pipelines, whether the ablation ran. That is all the run needs. Rebuilding the scenario
from the file with those values gives the run's digest back (the last part of its id)
unless the file has changed since, and the run loop gives the same frames and decisions
for the same scenario and code, so the line of the run done again equals the stored one,
measured times, code and recording name aside.

Each kind of result line is a `LineKind`: how to tell its lines, and how to rebuild and
run one. Sweep lines are the one kind today; a Euro NCAP grid's line (sim.runs.ncap_grid)
becomes a second one once it stores what an exact replay needs.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from monopic.errors import UserError
from sim.runs.result import ABLATION, RunResult
from sim.runs.results_file import read_rows
from sim.runs.run_spec import RunSpec
from sim.runs.sweep import TREE_TAG, run_scenario, tree_digest
from sim.scenario.files import ScenarioFile, load
from sim.scenario.spec import Scenario

# The checkout's top folder (with an editable install; elsewhere no scenario file is there).
CHECKOUT = Path(__file__).resolve().parents[2]


# Keys of a result line that may differ between the sweep and the run done again: measured
# times, the code digest (checked before the run, see code_of), and where the recording went.
IGNORED = ("timing", "code", "recording")


@dataclass(frozen=True)
class Rerun:
    """One line's run done again: the line as stored and as it came out now."""

    stored: dict[str, Any]
    again: dict[str, Any]
    recording: Path


@dataclass(frozen=True)
class Asked:
    """What the user asked of a rerun: the results file, the recording to write, the
    intent tree file (None: the shipped one the line names), and whether a line of other
    code is run anyway."""

    results: Path
    out: Path
    intent_tree: Path | None = None
    anyway: bool = False


@dataclass(frozen=True)
class LineKind:
    """A kind of result line that can be run again.

    `tells(line)`: whether a line is of this kind. `rebuild(line, asked)`: the run as a
    worker receives it, recording into `asked.out` (UserError, one line, when the line
    cannot be rebuilt: nothing is run or written then). `rerun(line, run, asked)`: that
    run done again, beside the stored line."""

    name: str
    tells: Callable[[dict[str, Any]], bool]
    rebuild: Callable[[dict[str, Any], Asked], Any]
    rerun: Callable[[dict[str, Any], Any, Asked], Rerun]


def find_line(results: Path, run_id: str) -> dict[str, Any]:
    """The first line of `run_id` in a results file; UserError naming a few ids if none."""
    ids: list[str] = []
    for row in read_rows(results):
        if row["id"] == run_id:
            return row
        ids.append(row["id"])
    if not ids:
        raise UserError(f"{results}: no finished runs in it yet")
    shown = ", ".join(repr(i) for i in ids[:2])
    raise UserError(
        f"{results}: no run {run_id!r} in it ({len(ids)} runs, ids such as {shown}; "
        f"`monopic report {results}` lists the runs that went wrong)"
    )


def code_of(row: dict[str, Any]) -> str | None:
    """The code version that ran a line, without the intent tree's digest."""
    code = row.get("code")
    return code.partition(TREE_TAG)[0] if isinstance(code, str) and code else None


# -- sweep lines ------------------------------------------------------------------------


def is_sweep_line(row: dict[str, Any]) -> bool:
    return isinstance(row.get("truth"), dict) and isinstance(row.get("pipelines"), dict)


def shipped_trees() -> list[Path]:
    """The tree files shipped inside the pipeline (monopic/tree/*.json)."""
    import monopic.tree

    return sorted(Path(monopic.tree.__file__).parent.glob("*.json"))


def intent_tree_of(row: RunResult, results: Path, given: Path | None) -> Path | None:
    """The intent tree a sweep ran beside the fixed predictors (its digest is in the line's
    code): the given file if its digest is that one, else the shipped tree that has it."""
    digest = (row.code or "").partition(TREE_TAG)[2]
    if not digest:
        if given is not None:
            raise UserError(
                f"--intent-tree {given}: run {row.id} of {results} ran no intent tree; leave it out"
            )
        return None
    if given is not None:
        if not given.is_file():
            raise UserError(f"--intent-tree {given}: no such file")
        if tree_digest(given) != digest:
            raise UserError(
                f"--intent-tree {given}: its digest is {tree_digest(given)}, run {row.id} of "
                f"{results} ran the tree with digest {digest}; give that one (the sweep spec's "
                "intent_tree)"
            )
        return given.resolve()
    for tree in shipped_trees():
        if tree_digest(tree) == digest:
            return tree
    raise UserError(
        f"{results}: run {row.id} ran an intent tree with digest {digest}, not one shipped with "
        "the code: give its file with --intent-tree FILE (the sweep spec's intent_tree)"
    )


def scenario_file_of(
    row: RunResult, results: Path, anyway: bool = False
) -> tuple[ScenarioFile, Scenario]:
    """The run's scenario file and its scenario at seed 0, rebuilt with the run's params.

    A line names its file as the sweep found it, relative to the folder the sweep ran in
    when the spec was given so; that folder is not recorded, so a relative name is looked
    for from here, from the results file's folder and from the checkout's top folder (where
    `make demo` runs its sweeps). The first that gives the run's digest (the last part of
    its id) is the run's: a file that does not is another file, or the file changed.
    UserError (one line) when none does, unless `anyway` (a line of other code, whose
    scenarios may digest differently): then the first file found."""
    name = Path(row.file)
    bases = [Path()] if name.is_absolute() else [Path(), results.parent, CHECKOUT]
    found = list(dict.fromkeys(b / name for b in bases if (b / name).is_file()))
    if not row.file or not found:
        raise UserError(
            f"{row.file or '(none)'}: no such scenario file (run {row.id} of {results} was made "
            "from it; a relative name is looked for from this folder, the results file's and "
            "the checkout's: run this from the folder the sweep ran in)"
        )
    digests = []
    for path in found:
        scenario_file = load(path)
        _, probe, digest = run_scenario(scenario_file, row.params)
        if row.id.endswith(f"-{digest}"):
            return scenario_file, probe
        digests.append(digest)
    if anyway:
        scenario_file = load(found[0])
        return scenario_file, run_scenario(scenario_file, row.params)[1]
    raise UserError(
        f"{found[0]}: it no longer gives run {row.id} of {results} (with the run's params its "
        f"scenario's digest is {digests[0]}): the file changed since the sweep; restore it "
        "(e.g. from version control) to run it again"
    )


def rebuild(row: RunResult, asked: Asked) -> RunSpec:
    """The RunSpec of a sweep's line, recording into `asked.out`; UserError (one line) when
    the scenario file is missing or no longer gives the run (it changed since the sweep)."""
    scenario_file, probe = scenario_file_of(row, asked.results, asked.anyway)
    return RunSpec(
        id=row.id,
        scenario=replace(probe, name=row.id, seed=row.seed),
        family=scenario_file.family,
        file=row.file,
        kind=scenario_file.kind,
        scale=scenario_file.scale.value,
        params=row.params,
        sweep=row.sweep,
        ablation=ABLATION in row.pipelines,
        record="all",
        record_file=str(asked.out),
        intent_tree=str(intent_tree_of(row, asked.results, asked.intent_tree) or ""),
        code=row.code or "",
    )


def rebuild_sweep_line(line: dict[str, Any], asked: Asked) -> RunSpec:
    return rebuild(RunResult.from_json(line, str(asked.results)), asked)


def rerun_sweep_line(line: dict[str, Any], spec: RunSpec, asked: Asked) -> Rerun:
    """A sweep's run done again on one worker of the sweep's own executor (so in the
    environment every sweep worker has), recording as `spec` says."""
    from sim.runs.executors import local_executor

    came: list[dict[str, Any]] = []
    local_executor(1)([spec], came.append)
    (again,) = came
    if "error" in again:
        raise RuntimeError(f"run {spec.id} failed when run again:\n{again['error']}")
    stored = RunResult.from_json(line, str(asked.results))
    return Rerun(_comparable(stored), _comparable(RunResult.from_json(again)), asked.out)


def _comparable(result: RunResult) -> dict[str, Any]:
    """A line as plain JSON data (as a results file holds it), IGNORED keys left out."""
    plain = json.loads(result.dumps())
    return {k: v for k, v in plain.items() if k not in IGNORED}


SWEEP = LineKind("sweep", is_sweep_line, rebuild_sweep_line, rerun_sweep_line)
KINDS: tuple[LineKind, ...] = (SWEEP,)


def kind_of(line: dict[str, Any]) -> LineKind | None:
    return next((kind for kind in KINDS if kind.tells(line)), None)


# -- comparing --------------------------------------------------------------------------


def first_difference(stored: dict[str, Any], again: dict[str, Any]) -> str | None:
    """Where the line run again first differs from the stored one, in words; None if equal.

    Keys in the line's order, so a different frame count is named before the columns it
    makes differ; a per-frame column names its frame and time."""
    for path, said in _differences(stored, again, ()):
        return f"{_where(path, stored)}: {said}"
    return None


_ABSENT = object()


def _differences(a: Any, b: Any, path: tuple[str | int, ...]) -> Iterator[tuple[tuple, str]]:
    """(path, what differs) of every difference, depth first in the stored line's order."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in [*a, *(k for k in b if k not in a)]:
            yield from _differences(a.get(key, _ABSENT), b.get(key, _ABSENT), (*path, key))
    elif isinstance(a, list) and isinstance(b, list):
        for k, (x, y) in enumerate(zip(a, b, strict=False)):
            yield from _differences(x, y, (*path, k))
        if len(a) != len(b):
            yield path, f"{len(a)} entries in the sweep, {len(b)} now"
    elif a != b or type(a) is not type(b):
        yield path, f"{_shown(a)} in the sweep, {_shown(b)} now"


def _where(path: tuple[str | int, ...], line: dict[str, Any]) -> str:
    """'pipelines.main.decisions.rules/image.warn[12] (frame 12, t = 0.80 s)'."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    frame = next((p for p in path if isinstance(p, int)), None)
    times = line.get("truth", {}).get("t", [])
    if frame is not None and path[0] in ("truth", "pipelines") and frame < len(times):
        text += f" (frame {frame}, t = {times[frame]:.2f} s)"
    return text or "the line"


def _shown(value: Any) -> str:
    return "absent" if value is _ABSENT else repr(value)
