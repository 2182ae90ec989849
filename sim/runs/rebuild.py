"""A run of a results file rebuilt from its line and run again (`monopic rerun`).

A sweep's result line records what made its run: the scenario file (`file`, as the sweep
found it from the folder it ran in), the swept values (`params`), the world seed (`seed`),
the code (`code`, with the intent tree's digest when the sweep ran one and the camera
when its spec named one, sim.runs.sweep.sweep_code) and, by its pipelines, whether the
ablation ran. That is all the run needs. Rebuilding the scenario
from the file with those values gives the run's digest back (the last part of its id)
unless the file has changed since, and the run loop gives the same frames and decisions
for the same scenario and code, so the line of the run done again equals the stored one,
measured times, code and recording name aside.

Each kind of result line is a `LineKind`: how to tell its lines, and how to rebuild and
run one. Three kinds: a sweep's lines; a closed loop's (sim.runs.closed_loop_grid: the
scenario's source, file and given values or the placed case, the policy, the latency
setting); a Euro NCAP grid's (sim.runs.ncap_grid: the protocol and car files, the grid
point, role and draw, the latency setting). The closed-loop and grid runs compare their
outcome, the host's times left out; a run made with the measured latency is replayed
with the latency it measured on each frame (`outcome.latencies_ms`), so it is the same.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from monopic.errors import UserError
from sim.runs.result import ABLATION, RunResult, values_said
from sim.runs.results_file import read_rows
from sim.runs.run_spec import ONE, TRACKERS, RunSpec
from sim.runs.sweep import (
    CAMERA_TAG,
    PEOPLE_TAG,
    TREE_TAG,
    camera_of_code,
    run_scenario,
    tree_digest,
    with_camera,
)
from sim.scenario.files import ScenarioFile, load
from sim.scenario.spec import Scenario

# The checkout's top folder (with an editable install; elsewhere no scenario file is there).
CHECKOUT = Path(__file__).resolve().parents[2]


# Keys of a result line that may differ between the sweep and the run done again: measured
# times, the code digest (checked before the run, see code_of), and where the recording went.
IGNORED = ("timing", "code", "recording")


@dataclass(frozen=True)
class Rerun:
    """One line's run done again: the line as stored and as it came out now (the keys
    compared), the recording, the run in words ("(case5, robot.speed = 2): 30 frames,
    contact at 1.93 s") and, if it failed when run again, its error."""

    stored: dict[str, Any]
    again: dict[str, Any]
    recording: Path
    said: str = ""
    failed: str | None = None


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
    run done again, beside the stored line. `same`: what a rerun that matches its line
    gave ("frames and decisions"); `made_in`: where the line was made, as a difference
    names it ("the sweep")."""

    name: str
    tells: Callable[[dict[str, Any]], bool]
    rebuild: Callable[[dict[str, Any], Asked], Any]
    rerun: Callable[[dict[str, Any], Any, Asked], Rerun]
    same: str = "outcome"
    made_in: str = "the run"


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
        f"{results}: no run {run_id!r} in it ({len(ids)} runs, ids such as {shown}; a sweep's "
        "report, the closed loop's tables and the Euro NCAP report.md list the runs that went "
        "wrong, each with its command)"
    )


def code_of(row: dict[str, Any]) -> str | None:
    """The code version that ran a line, without the intent tree's digest, the camera's
    tag or the people tracker's tag (sim.runs.sweep.sweep_code)."""
    code = row.get("code")
    if not isinstance(code, str) or not code:
        return None
    return code.partition(TREE_TAG)[0].partition(CAMERA_TAG)[0].removesuffix(PEOPLE_TAG)


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
    found = files_named(row.file or "(none)", "scenario", row.id, results, "sweep")
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
    scenario = replace(probe, name=row.id, seed=row.seed)
    camera = camera_of_code(row.code)
    if camera is not None:  # the sweep's spec named the camera: its tag in the line's code
        scenario = with_camera(scenario, camera, asked.results)
    return RunSpec(
        id=row.id,
        scenario=scenario,
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
        tracker=row.tracker or ONE,
        code=row.code or "",
    )


def rebuild_sweep_line(line: dict[str, Any], asked: Asked) -> RunSpec:
    return rebuild(RunResult.from_json(line, str(asked.results)), asked)


def rerun_sweep_line(line: dict[str, Any], spec: RunSpec, asked: Asked) -> Rerun:
    """A sweep's run done again on one worker of the sweep's own executor (so in the
    environment every sweep worker has), recording as `spec` says."""
    from sim.runs.executors import work

    again, failed = _on_one_worker(spec, work)
    stored = _comparable(RunResult.from_json(line, str(asked.results)))
    params = line.get("params") if isinstance(line.get("params"), dict) else {}
    said = f"({line.get('family', '?')}, {values_said(params)})"
    if failed is not None:
        return Rerun(stored, {}, asked.out, said, failed)
    made = RunResult.from_json(again)
    said += f": {made.frames} frames, contact {_contact(made.contact_time)}"
    return Rerun(stored, _comparable(made), asked.out, said)


def _on_one_worker(
    spec: Any, work: Callable[..., dict[str, Any]]
) -> tuple[dict[str, Any], str | None]:
    """`spec` run by `work` on one local worker of the executors every command uses (in
    the environment each of their workers has): its row as plain JSON data, or its error."""
    from sim.runs.executors import local_executor

    came: list[dict[str, Any]] = []
    local_executor(1, run=work)([spec], came.append)
    (again,) = came
    # As a results file holds it (tuples are lists there), to compare with a stored line.
    return json.loads(json.dumps(again)), again.get("error")


def _contact(time: object) -> str:
    return f"at {time:.2f} s" if isinstance(time, int | float) else "none"


def _comparable(result: RunResult) -> dict[str, Any]:
    """A line as plain JSON data (as a results file holds it), IGNORED keys left out."""
    plain = json.loads(result.dumps())
    return {k: v for k, v in plain.items() if k not in IGNORED}


SWEEP = LineKind(
    "sweep",
    is_sweep_line,
    rebuild_sweep_line,
    rerun_sweep_line,
    same="frames and decisions",
    made_in="the sweep",
)


# -- files named by a line ---------------------------------------------------------------


def found_files(name: str, results: Path) -> list[Path]:
    """The files a line's relative `name` may be: from this folder, the results file's
    and the checkout's top folder (where `make demo` runs); an absolute name as it is."""
    path = Path(name)
    bases = [Path()] if path.is_absolute() else [Path(), results.parent, CHECKOUT]
    return list(dict.fromkeys(b / path for b in bases if (b / path).is_file()))


def files_named(name: str, what: str, run_id: str, results: Path, made_by: str) -> list[Path]:
    """found_files, or UserError (one line) saying where a missing file was looked for."""
    found = found_files(name, results)
    if not found:
        raise UserError(
            f"{name}: no such {what} file (run {run_id} of {results} was made from it; a "
            "relative name is looked for from this folder, the results file's and the "
            f"checkout's: run this from the folder the {made_by} ran in)"
        )
    return found


def _not_a_line(line: dict[str, Any], asked: Asked, what: str, err: Exception) -> UserError:
    return UserError(
        f"{asked.results}: run {line.get('id')} is not {what} line as this code reads them "
        f"({type(err).__name__}: {err})"
    )


# -- closed-loop lines --------------------------------------------------------------------


def is_loop_line(row: dict[str, Any]) -> bool:
    return isinstance(row.get("source"), dict) and isinstance(row.get("outcome"), dict)


def rebuild_loop_line(line: dict[str, Any], asked: Asked) -> Any:
    """The closed-loop run of a line (sim.runs.closed_loop_grid.LoopRun), its scenario
    rebuilt from the file and the values given (or the placed case), with the latencies it
    measured when it applied the measured latency; UserError (one line) when the scenario
    file is missing or no longer gives the run (the id's digest), unless `asked.anyway`."""
    from sim.runs import closed_loop_grid as grid
    from sim.runs.latency import LatencySetting, replay_latencies

    try:
        source = grid.Source.from_json(line["source"])
        latency = LatencySetting.from_json(line["latency"])
        policy = str(line["policy"])
        tracker = str(line.get("tracker", ONE))  # only the people tracker's lines say it
        if tracker not in TRACKERS:
            raise ValueError(f"tracker {tracker!r}")
        replay = replay_latencies(line)
    except (KeyError, TypeError, ValueError) as err:
        raise _not_a_line(line, asked, "a closed loop's", err) from None
    files: list[Path | None] = [None]
    if source.file is not None:
        files = list(files_named(source.file, "scenario", line["id"], asked.results, "closed loop"))
    made = []
    for path in files:
        scenario = source.scenario(load(path) if path is not None else None)
        made.append(grid.loop_run(scenario, policy, source, latency, str(asked.out), tracker))
        if made[-1].id == line["id"]:
            break
    else:
        if not asked.anyway:
            where = files[0] if files[0] is not None else f"case {source.case}"
            raise UserError(
                f"{where}: it no longer gives run {line['id']} of {asked.results} (with the "
                f"values given its run is {made[0].id}): the scenario changed since the "
                "closed loop ran; restore it (e.g. from version control) to run it again"
            )
    run = made[-1] if made[-1].id == line["id"] else made[0]
    return replace(
        run,
        id=line["id"],
        scenario=replace(run.scenario, name=str(line.get("scenario", run.scenario.name))),
        replay=None if replay is None else tuple(replay),
    )


def rerun_loop_line(line: dict[str, Any], run: Any, asked: Asked) -> Rerun:
    """A closed-loop run done again on one worker, its row compared without the host's
    times (sim.runs.closed_loop_grid.without_timing)."""
    from sim.runs import closed_loop_grid as grid

    again, failed = _on_one_worker(run, grid.work)
    said = f"({grid.source_said(line['source'])}, policy {line['policy']})"
    if failed is not None:
        return Rerun(grid.without_timing(line), {}, asked.out, said, failed)
    o = again["outcome"]
    said += f": {o['frames']} frames, contact {_contact(o['contact_time'])}"
    return Rerun(grid.without_timing(line), grid.without_timing(again), asked.out, said)


LOOP = LineKind("closed-loop", is_loop_line, rebuild_loop_line, rerun_loop_line)


# -- Euro NCAP grid lines -----------------------------------------------------------------


def is_ncap_line(row: dict[str, Any]) -> bool:
    from sim.runs.ncap_grid import GRID, NEAR_MISS, VERIFY

    return isinstance(row.get("outcome"), dict) and row.get("role") in (GRID, VERIFY, NEAR_MISS)


def rebuild_ncap_line(line: dict[str, Any], asked: Asked) -> Any:
    """The grid's run of a line (sim.runs.ncap_grid.NcapRun), re-made from the protocol
    and car files the line names (lines without them: the shipped ones) and matched by
    its id, with the latencies it measured when it applied the measured latency;
    UserError (one line) when a file is missing or they no longer give the run."""
    from sim.runs import ncap_grid
    from sim.runs.latency import replay_latencies
    from sim.scenario.ncap import CAR_FILE, PROTOCOL_FILE, load_car, load_protocol

    named = {"protocol": line.get("protocol") or str(PROTOCOL_FILE),
             "car": line.get("car") or str(CAR_FILE)}  # fmt: skip
    found = {
        key: files_named(str(name), key, str(line.get("id")), asked.results, "grid")
        for key, name in named.items()
    }
    made = []
    try:
        replay = replay_latencies(line)
        for protocol_path, car_path in [(p, c) for p in found["protocol"] for c in found["car"]]:
            protocol, car = load_protocol(protocol_path), load_car(car_path)
            made.append(ncap_grid.run_of(protocol, car, line))
            if made[-1].id == line["id"]:
                break
    except (KeyError, TypeError, ValueError) as err:
        raise _not_a_line(line, asked, "a Euro NCAP grid's", err) from None
    run = made[-1]
    if run.id != line["id"]:
        if not asked.anyway:
            raise UserError(
                f"{found['protocol'][0]}, {found['car'][0]}: they no longer give run "
                f"{line['id']} of {asked.results} (rebuilt from them it is {made[0].id}): a "
                "file changed since the grid ran; restore it (e.g. from version control) to "
                "run it again"
            )
        run = made[0]
    # The row names the files as the grid's command was given them, not as found here.
    meta = {k: v for k, v in run.meta.items() if k not in named or k in line}
    meta.update({k: line[k] for k in named if k in line})
    return replace(
        run,
        id=line["id"],
        scenario=replace(run.scenario, name=line["id"]),
        meta=meta,
        replay=None if replay is None else tuple(replay),
        rrd=str(asked.out),
    )


def _ncap_comparable(row: dict[str, Any]) -> dict[str, Any]:
    from sim.runs.ncap_grid import without_timing

    return {k: v for k, v in without_timing(row).items() if k != "code"}


def rerun_ncap_line(line: dict[str, Any], run: Any, asked: Asked) -> Rerun:
    """A grid's run done again on one worker, its row compared without the host's times
    and the code (sim.runs.ncap_grid.without_timing)."""
    from sim.runs import ncap_grid

    again, failed = _on_one_worker(run, ncap_grid.work)
    said = f"({ncap_grid.run_said(line)}, policy {line['policy']})"
    if failed is not None:
        return Rerun(_ncap_comparable(line), {}, asked.out, said, failed)
    o = again["outcome"]
    hit = f"contact at {3.6 * o['impact_speed']:.1f} km/h" if o["contact"] else "no contact"
    said += f": {o['frames']} frames, {hit}"
    return Rerun(_ncap_comparable(line), _ncap_comparable(again), asked.out, said)


NCAP = LineKind("Euro NCAP", is_ncap_line, rebuild_ncap_line, rerun_ncap_line)
KINDS: tuple[LineKind, ...] = (SWEEP, LOOP, NCAP)


def kind_of(line: dict[str, Any]) -> LineKind | None:
    return next((kind for kind in KINDS if kind.tells(line)), None)


# -- comparing --------------------------------------------------------------------------


def first_difference(
    stored: dict[str, Any], again: dict[str, Any], made_in: str = "the sweep"
) -> str | None:
    """Where the line run again first differs from the stored one, in words; None if equal.

    Keys in the line's order, so a different frame count is named before the columns it
    makes differ; a per-frame column names its frame and time. `made_in`: where the line
    was made ("the sweep", "the run"), as the words say it."""
    for path, said in _differences(stored, again, (), made_in):
        return f"{_where(path, stored)}: {said}"
    return None


_ABSENT = object()


def _differences(
    a: Any, b: Any, path: tuple[str | int, ...], made_in: str
) -> Iterator[tuple[tuple, str]]:
    """(path, what differs) of every difference, depth first in the stored line's order."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in [*a, *(k for k in b if k not in a)]:
            yield from _differences(a.get(key, _ABSENT), b.get(key, _ABSENT), (*path, key), made_in)
    elif isinstance(a, list) and isinstance(b, list):
        for k, (x, y) in enumerate(zip(a, b, strict=False)):
            yield from _differences(x, y, (*path, k), made_in)
        if len(a) != len(b):
            yield path, f"{len(a)} entries in {made_in}, {len(b)} now"
    elif a != b or type(a) is not type(b):
        yield path, f"{_shown(a)} in {made_in}, {_shown(b)} now"


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
