"""`monopic closed-loop` as runs: one per (scenario, policy), on the sweep executors.

Each run gets a stable id, its policy, its scenario's name and a digest of the scenario
(its seed included), the policy and the latency setting, so the same command finds the
same runs again: a results file resumes as a sweep's does (sim.runs.results_file: one
fsynced JSON line per finished run, the code version on every line) and never takes a
run made with another latency for this one. Runs execute on the sweep executors
(sim.runs.executors: local spawned workers or Ray), each worker writing its run's
recording when one is asked for.

A row keeps what an exact replay needs (`monopic rerun`, sim.runs.rebuild): where the
scenario came from (`source`: the scenario file as given and the values given for it, or
the --cases placement), the policy, the seed, the latency applied (`latency`) and the
pipeline's measured latency of every processed frame (`outcome.latencies_ms`: a run made
with the measured latency is made again exactly with them).

The tracker (`tracker`: one pedestrian or everyone, sim.runs.run_spec.TRACKERS) is part of
a run's identity only when it is the people tracker: a one-tracker run keeps the id,
digest and line it always had (no `tracker` key; the outcome's whom-it-braked-for fields
only with several people, sim.runs.closed_loop.OPTIONAL), so earlier results files resume
and compare byte for byte.
"""

from __future__ import annotations

import hashlib
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from monopic.cases import Case
from monopic.errors import UserError
from sim.runs.closed_loop import NO_BRAKE, LoopOutcome, outcome_json, run_closed_loop
from sim.runs.latency import FIXED, MEASURED, LatencySetting
from sim.runs.result import values_said
from sim.runs.results_file import check_resumable, without_keys
from sim.runs.run_spec import ONE, TRACKERS
from sim.runs.runner import machine
from sim.runs.sweep import SweepOutcome, rows_of, run_resumable
from sim.scenario.files import Given, ScenarioFile, load, placed_case
from sim.scenario.spec import Scenario, scenario_text
from sim.world.render import KeptRenderContext

SCHEMA = 1
# The options a given value came from, as refusals name them.
ROBOT_SPEEDS, SEED = "--robot-speeds", "--seed"
OPTIONS = {"robot.speed": ROBOT_SPEEDS, "seed": SEED}


@dataclass(frozen=True)
class Source:
    """Where a run's scenario came from: a scenario file (as the command was given it) or
    a --cases case number placed to meet the robot at `meet_time` s, and the values given
    for it (dotted keys: robot.speed, seed); what the run's scenario is rebuilt from."""

    file: str | None = None
    case: int | None = None
    given: dict[str, Any] = field(default_factory=dict)
    meet_time: float | None = None  # s, a case's

    def __post_init__(self) -> None:
        if (self.file is None) == (self.case is None) or (self.case is None) != (
            self.meet_time is None
        ):
            raise ValueError(f"a scenario file or a placed case, not {self.to_json()}")

    def to_json(self) -> dict[str, Any]:
        return {"file": self.file, "case": self.case, "given": dict(self.given),
                "meet_time": self.meet_time}  # fmt: skip

    @classmethod
    def from_json(cls, data: Any) -> Source:
        """A row's `source` back; ValueError (or TypeError) if it is not one."""
        if not isinstance(data, dict) or set(data) != {"file", "case", "given", "meet_time"}:
            raise ValueError(f"not a scenario source: {data!r}")
        given = data["given"]
        if not isinstance(given, dict) or not set(given) <= set(OPTIONS):
            raise ValueError(f"not a scenario source: {data!r}")
        return cls(data["file"], data["case"], dict(given), data["meet_time"])

    def scenario(self, file: ScenarioFile | None = None) -> Scenario:
        """The scenario: the file (`file`, loaded from `self.file` when not given) with the
        given values through its checks, or the case placed with them."""
        given = [Given(OPTIONS[k], k, v) for k, v in self.given.items()]
        if self.case is not None and self.meet_time is not None:
            speed, seed = self.given["robot.speed"], self.given.get("seed")
            return case_scenario(Case(self.case), speed, self.meet_time, seed)
        sf = file if file is not None else load(self.file or "")
        speed = self.given.get("robot.speed", sf.base.robot.speed)
        return sf.with_given(given, name=f"{sf.name}@{speed:g}")


def source_said(source: dict[str, Any]) -> str:
    """A row's `source` in words: 'case 5, robot.speed = 2' or 'my/child.toml, the file's
    values'."""
    where = f"case {source['case']}" if source.get("case") is not None else str(source["file"])
    given = source.get("given") or {}
    return f"{where}, {values_said(given)}" if given else f"{where}, the file's values"


def case_scenario(case: Case, speed: float, meet_time: float, seed: int | None = None) -> Scenario:
    """A crossing on a collision course meeting the robot's front at `meet_time` s unless
    it brakes, placed as a small-scale scenario file with path.kind = "case" would place it
    (sim.scenario.files.placed_case): its checks."""
    if case.lateral == 0:
        raise UserError(f"--cases: case {int(case)} ({case.label}) does not cross the path")
    if speed <= 0:
        raise UserError(f"{ROBOT_SPEEDS}: a crossing needs a moving robot (> 0 m/s)")
    given = [Given(ROBOT_SPEEDS, "robot.speed", speed)]
    if seed is not None:
        given.append(Given(SEED, "seed", seed))
    fixed = {"path.distance": speed * meet_time, "path.meet_time": meet_time,
             "duration": meet_time + 1.0}  # fmt: skip
    name = f"case{int(case)}@{speed:g}"
    return placed_case(case, given, fixed, name=name, where=f"case {int(case)}: ")


def case_sources(
    cases: str, speeds: list[float], meet_time: float, seed: int | None = None
) -> list[Source]:
    """--cases 5,6 at each speed (and `seed`), meeting the robot at `meet_time` s."""
    out = []
    for text in cases.split(","):
        try:
            case = Case(int(text))
        except ValueError:
            raise UserError(f"--cases: {text!r} is not a case number 1-9") from None
        for v in speeds:
            given: dict[str, Any] = {"robot.speed": v}
            if seed is not None:
                given["seed"] = seed
            out.append(Source(case=int(case), given=given, meet_time=meet_time))
    return out


def file_sources(files: list[Path], speeds: list[float] | None, seed: int | None) -> list[Source]:
    """Each file at its own robot speed and seed, or at each of `speeds` and at `seed`."""
    out = []
    for path in files:
        for v in speeds if speeds is not None else [None]:
            given: dict[str, Any] = {} if v is None else {"robot.speed": v}
            if seed is not None:
                given["seed"] = seed
            out.append(Source(file=str(path), given=given))
    return out


def scenarios_of(sources: Sequence[Source]) -> list[Scenario]:
    """Every source's scenario, each file read once; a value the file's checks refuse is
    one line naming the option, the file and the field."""
    files: dict[str, ScenarioFile] = {}
    out = []
    for source in sources:
        if source.file is not None and source.file not in files:
            files[source.file] = load(source.file)
        out.append(source.scenario(files.get(source.file or "")))
    return out


@dataclass(frozen=True)
class LoopRun:
    """One closed-loop run as a worker receives it (plain, picklable data).

    `replay`: per-frame latencies to apply instead of measuring them (`monopic rerun` of a
    run made with the measured latency); `rrd`: the recording to write ("" none)."""

    id: str
    scenario: Scenario
    policy: str
    source: Source
    latency: LatencySetting
    rrd: str = ""
    code: str = ""
    replay: tuple[float, ...] | None = None
    tracker: str = ONE  # whom the policy's pipeline follows (TRACKERS)

    def __post_init__(self) -> None:
        if self.tracker not in TRACKERS:
            raise ValueError(f"tracker must be one of {', '.join(TRACKERS)}, got {self.tracker!r}")
        if self.latency.source not in (FIXED, MEASURED):
            raise ValueError(f"the closed loop applies a fixed or the measured latency, not "
                             f"{self.latency.describe()}")  # fmt: skip


def run_digest(scenario: Scenario, policy: str, latency: LatencySetting, tracker: str = ONE) -> str:
    """8 hex digits of the scenario (seed included), the policy, the latency setting and
    the tracker (the people tracker only: a one-tracker run keeps its digest)."""
    text = f"{scenario_text(replace(scenario, name=''))}|{policy}|{latency.to_json()}"
    if tracker != ONE:
        text += f"|tracker={tracker}"
    return hashlib.sha1(text.encode()).hexdigest()[:8]


def loop_run(
    scenario: Scenario,
    policy: str,
    source: Source,
    latency: LatencySetting,
    rrd: str = "",
    tracker: str = ONE,
) -> LoopRun:
    rid = f"{policy}/{scenario.name}-{run_digest(scenario, policy, latency, tracker)}"
    return LoopRun(rid, scenario, policy, source, latency, rrd, tracker=tracker)


def expand(
    sources: Sequence[Source],
    scenarios: Sequence[Scenario],
    policies: Sequence[str],
    latency: LatencySetting,
    rrd_dir: Path | None = None,
    tracker: str = ONE,
) -> list[LoopRun]:
    """Every (scenario, policy) run, scenario by scenario, in the policies' order, the
    pipelines following `tracker`; with `rrd_dir`, each braking run (not the baseline)
    records to <scenario>-<policy>.rrd."""
    runs = []
    for source, scenario in zip(sources, scenarios, strict=True):
        for policy in policies:
            rrd = ""
            if rrd_dir is not None and policy != NO_BRAKE:
                rrd = str(rrd_dir / f"{scenario.name}-{policy.replace('/', '-')}.rrd")
            runs.append(loop_run(scenario, policy, source, latency, rrd, tracker))
    return runs


def work(spec: LoopRun, kept: KeptRenderContext | None = None) -> dict[str, Any]:
    """One run in a worker: its result line, or {"id", "error"} (the others go on)."""
    try:
        camera = spec.scenario.robot.camera
        context = kept.fitting(camera.width, camera.height) if kept is not None else None
        t0 = time.perf_counter()
        outcome = run_closed_loop(
            spec.scenario,
            spec.policy,
            seed=spec.scenario.seed,
            latency_ms=spec.latency.ms,
            rrd=Path(spec.rrd) if spec.rrd else None,
            latencies_ms=spec.replay,
            render_context=context,
            tracker=spec.tracker,
        )
        row = {
            "schema": SCHEMA,
            "id": spec.id,
            "code": spec.code,
            "source": spec.source.to_json(),
            "scenario": spec.scenario.name,
            "family": spec.scenario.family,
            "lighting": spec.scenario.scene.lighting.name,
            "policy": spec.policy,
            "seed": spec.scenario.seed,
            "latency": spec.latency.to_json(),
            "outcome": outcome_json(outcome, spec.tracker),
            "recording": spec.rrd,
            "wall_s": round(time.perf_counter() - t0, 3),
            "machine": asdict(machine()),
        }
        if spec.tracker != ONE:  # only the people tracker's lines say it (OPTIONAL's rule)
            row["tracker"] = spec.tracker
        return row
    except Exception:  # noqa: BLE001 - reported per run
        return {"id": spec.id, "error": traceback.format_exc()}


def outcome_of(row: dict[str, Any]) -> LoopOutcome:
    """A row's outcome as the run returned it (the tables are made from these)."""
    o = dict(row["outcome"])
    o["latencies_ms"] = tuple(o["latencies_ms"])
    o["delays"] = tuple(o["delays"])
    return LoopOutcome(**o)


# What a row holds that depends on the host and the moment, not on the pipeline and the
# settings (a rerun compares the rest), and where the run's recording went.
HOST_TIMING = ("wall_s", "machine", "code", "recording")
OUTCOME_TIMING = ("latencies_ms",)


def without_timing(row: dict[str, Any]) -> dict[str, Any]:
    """A row without its measured times, machine, code and recording (HOST_TIMING)."""
    return without_keys(row, HOST_TIMING, OUTCOME_TIMING)


Executor = Callable[[Sequence[LoopRun], Callable[[dict[str, Any]], None]], None]


def check_results(out: Path, restart: bool) -> None:
    """The results file's checks before any run (sim.runs.results_file.check_resumable)."""
    check_resumable(out, SCHEMA, restart, "--results")


def run_runs(
    runs: list[LoopRun], out: Path, executor: Executor, progress: bool = True
) -> SweepOutcome:
    """Run every run missing from `out`, appending each result line as it finishes."""
    return run_resumable(runs, out, executor, "closed-loop", progress)


def read_results(out: Path, runs: list[LoopRun]) -> list[dict[str, Any]]:
    """The result lines of `runs` (this code's), in the runs' order."""
    return rows_of(out, runs)
