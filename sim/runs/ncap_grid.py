"""The Euro NCAP grid as runs: expand it, run what a results file lacks, one line per run.

Every grid point (sim.scenario.ncap) is run `car.seeds` times with jittered deviations
(role "grid": the manufacturer's virtual tests its prediction comes from) and
`car.verification_seeds` more times with further draws (role "verify": the test lab's
verification run the calculator compares the prediction against), once per policy; the
car-scale near misses are run beside them (role "near-miss"). A run's id is its policy,
grid point, role, draw number and a digest of its scenario and its AEB (the latency it
applies included), so re-expanding finds the same runs, a results file resumes as a
sweep's does (sim.runs.results_file: one fsynced JSON line per finished run, the code
version on every line), and runs made with another latency are never taken for these.
Runs execute on the sweep executors (sim.runs.executors: local spawned workers or Ray).

The latency: by default the car file's declared one (a fixed figure, the pipeline's p95
on a named reference host), so the rating depends on the pipeline and not on how loaded
the host is; on request a fixed figure or the host's measured latency per frame. Every
row says which it applied (`latency`) and keeps the pipeline's measured latency of each
frame (`outcome.latencies_ms`), so the report shows the host's latency beside the
declared one and a run made with the measured latency can be replayed exactly.
"""

from __future__ import annotations

import hashlib
import sys
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from monopic.errors import UserError
from sim.runs.aeb import AebParams, run_aeb
from sim.runs.code_version import code_version
from sim.runs.results_file import ResultsWriter, check_unlocked, read_rows, scan
from sim.runs.runner import machine
from sim.runs.sweep import run_missing, say_skipped
from sim.scenario.files import load
from sim.scenario.ncap import (
    KMH,
    CarSpec,
    GridPoint,
    Protocol,
    draw_for,
    grid,
    scenario_digest,
    scenario_for,
)
from sim.scenario.spec import Scenario
from sim.world.render import KeptRenderContext

SCHEMA = 1
GRID, VERIFY, NEAR_MISS = "grid", "verify", "near-miss"
DECLARED, FIXED, MEASURED = "declared", "fixed", "measured"


@dataclass(frozen=True)
class LatencySetting:
    """The latency the AEB applies: the car file's declared figure, a fixed figure given
    on the command line, or the pipeline's measured one per frame (`ms` None)."""

    source: str  # DECLARED, FIXED or MEASURED
    ms: float | None

    def __post_init__(self) -> None:
        if (self.source == MEASURED) != (self.ms is None) or self.source not in (
            DECLARED, FIXED, MEASURED,
        ):  # fmt: skip
            raise ValueError(f"not a latency setting: {self.source!r} {self.ms!r}")

    def describe(self) -> str:
        """As reports say it: "declared 50 ms", "fixed 40 ms", "measured per frame"."""
        return "measured per frame" if self.ms is None else f"{self.source} {self.ms:g} ms"

    def to_json(self) -> dict[str, Any]:
        return {"source": self.source, "applied_ms": self.ms}


def latency_setting(
    car: CarSpec, fixed_ms: float | None = None, measured: bool = False
) -> LatencySetting:
    """The command's choice: measured on request, else the fixed figure given, else the
    car file's declared one (a car file that declares none: measured)."""
    if measured and fixed_ms is not None:
        raise ValueError("a fixed latency or the measured one, not both")
    if measured or (fixed_ms is None and car.latency_ms is None):
        return LatencySetting(MEASURED, None)
    if fixed_ms is not None:
        return LatencySetting(FIXED, float(fixed_ms))
    return LatencySetting(DECLARED, car.latency_ms)


@dataclass(frozen=True)
class NcapRun:
    """One closed-loop run as a worker receives it (plain, picklable data)."""

    id: str
    scenario: Scenario
    policy: str
    aeb: AebParams
    role: str  # GRID, VERIFY or NEAR_MISS
    index: int  # draw number (near misses: seed number)
    meta: dict[str, Any] = field(default_factory=dict)  # test, function, speed, impact, draw
    code: str = ""
    latency: LatencySetting = LatencySetting(MEASURED, None)

    def __post_init__(self) -> None:
        if self.latency.ms != self.aeb.latency_ms:  # the row must say what the run applied
            raise ValueError(f"latency {self.latency} but AEB {self.aeb}")


def aeb_params(car: CarSpec, latency: LatencySetting) -> AebParams:
    return AebParams(car.brake_delay, car.jerk, car.deceleration, latency.ms)


def run_digest(scenario: Scenario, aeb: AebParams) -> str:
    """8 hex digits of the scenario and the AEB (brake and applied latency): a run's identity."""
    text = f"{scenario_digest(scenario)}|{aeb!r}"
    return hashlib.sha1(text.encode()).hexdigest()[:8]


def expand(
    protocol: Protocol,
    car: CarSpec,
    tests: list[str],
    policies: list[str],
    *,
    quick: bool = False,
    speeds: list[float] | None = None,
    seeds: int | None = None,
    near_misses: bool = True,
    latency: LatencySetting | None = None,
) -> list[NcapRun]:
    """Every run of the grid, in a stable order (policy, point, role, draw).

    `latency` None: the car file's declared latency (sim.runs.ncap_grid.latency_setting).
    """
    latency = latency_setting(car) if latency is None else latency
    aeb = aeb_params(car, latency)
    n_grid = (car.quick_seeds if quick else car.seeds) if seeds is None else seeds
    points = grid(protocol, tests, quick, speeds)
    runs = []
    for policy in policies:
        for point in points:
            roles = [(GRID, k) for k in range(n_grid)]
            roles += [(VERIFY, n_grid + k) for k in range(car.verification_seeds)]
            for role, k in roles:
                d = draw_for(protocol.tolerances, point.id, k)
                scenario = scenario_for(protocol, car, point, d, seed=k)
                meta = {**asdict(point), "draw": asdict(d), "load_case": _case(protocol, point)}
                runs.append(_run(policy, point.id, role, k, scenario, aeb, meta, latency))
        if near_misses:
            runs.extend(_near_misses(protocol, car, policy, aeb, quick, speeds, latency))
    return runs


def _case(protocol: Protocol, point: GridPoint) -> str:
    return protocol.tests[point.test].load_case


def _run(policy: str, key: str, role: str, k: int, s: Scenario, aeb: AebParams,
         meta: dict[str, Any], latency: LatencySetting) -> NcapRun:  # fmt: skip
    rid = f"{policy}/{key}/{role}{k}-{run_digest(s, aeb)}"
    return NcapRun(rid, replace(s, name=rid), policy, aeb, role, k, meta, latency=latency)


def _near_misses(
    protocol: Protocol, car: CarSpec, policy: str, aeb: AebParams, quick: bool,
    speeds: list[float] | None, latency: LatencySetting,
) -> list[NcapRun]:  # fmt: skip
    nm = protocol.near_misses
    out = []
    for path in nm.files:
        sf = load(path)
        for v in nm.quick_speeds_kmh if quick else nm.speeds_kmh:
            if speeds is not None and v not in speeds:
                continue
            base = sf.scenario({"robot.speed": v * KMH}, name=sf.name)
            robot = replace(base.robot, max_deceleration=car.deceleration, pitch=car.pitch)
            for k in range(nm.quick_seeds if quick else nm.seeds):
                s = replace(base, robot=robot, seed=k)
                meta = {"test": "near-miss", "family": sf.name, "speed_kmh": v}
                key = f"{sf.name}/{v:g}kmh"
                out.append(_run(policy, key, NEAR_MISS, k, s, aeb, meta, latency))
    return out


def work(spec: NcapRun, kept: KeptRenderContext | None = None) -> dict[str, Any]:
    """One run in a worker: its result line, or {"id", "error"} (the grid goes on)."""
    try:
        camera = spec.scenario.robot.camera
        context = kept.fitting(camera.width, camera.height) if kept is not None else None
        t0 = time.perf_counter()
        outcome = run_aeb(
            spec.scenario, spec.policy, spec.aeb, seed=spec.index, render_context=context
        )
        return {
            "schema": SCHEMA,
            "id": spec.id,
            "code": spec.code,
            "policy": spec.policy,
            "role": spec.role,
            "index": spec.index,
            **spec.meta,
            "latency": spec.latency.to_json(),
            "outcome": asdict(outcome),
            "wall_s": round(time.perf_counter() - t0, 3),
            "machine": asdict(machine()),  # the CPU's model name, as a sweep's rows have it
        }
    except Exception:  # noqa: BLE001 - reported per run
        return {"id": spec.id, "error": traceback.format_exc()}


# What a row holds that depends on the host's speed and load, not on the pipeline and the
# settings: with a declared or fixed latency everything else of a row is the same on one
# host at any load (tests/sim/test_ncap.py runs a grid point under an artificial load).
HOST_TIMING = ("wall_s", "machine")
OUTCOME_TIMING = ("latencies_ms", "latency_ms_median")


def without_timing(row: dict[str, Any]) -> dict[str, Any]:
    """A result row without its measured times and machine (see HOST_TIMING)."""
    out = {k: v for k, v in row.items() if k not in HOST_TIMING}
    if isinstance(out.get("outcome"), dict):
        out["outcome"] = {k: v for k, v in out["outcome"].items() if k not in OUTCOME_TIMING}
    return out


def replay_latencies(row: dict[str, Any]) -> list[float] | None:
    """What `run_aeb(..., latencies_ms=)` needs to make a row's run again exactly.

    A run that applied the measured latency: its measured per-frame latencies. A run that
    applied a declared or fixed figure: None (its NcapRun's AebParams carry the figure,
    and nothing else of the run depended on the host).
    """
    if row["latency"]["source"] != MEASURED:
        return None
    return [float(v) for v in row["outcome"]["latencies_ms"]]


Executor = Callable[[Sequence[NcapRun], Callable[[dict[str, Any]], None]], None]


@dataclass(frozen=True)
class GridOutcome:
    total: int
    skipped: int
    finished: int
    failed: tuple[tuple[str, str], ...]
    seconds: float


def check_results(out: Path, restart: bool) -> None:
    """Refuse (one line) a results file of other code or of a newer schema, unless
    `restart` sets it aside, and one another grid is appending to (as a sweep does)."""
    if not out.exists():
        return
    code = code_version()
    state = scan(out)
    other = state.other_code(code)
    newer = state.newer_schema(SCHEMA)
    if newer and not restart:
        raise UserError(
            f"{out}:{newer[0]}: a result of schema {newer[1]}, newer than this code's "
            f"{SCHEMA} (written by newer code, which alone reads it); use another --out, or "
            "--restart to set the file aside and start over"
        )
    if other and not restart:
        raise UserError(
            f"{out}: holds runs of other code ({', '.join(other)}; this code is {code}); "
            "use another --out, or --restart to set them aside and start over"
        )
    check_unlocked(out)
    if other or newer:
        tag = (next(iter(other)) if len(other) == 1 else "mixed") if other else f"schema{newer[1]}"
        target = out.with_name(f"{out.stem}.{tag}{out.suffix}")
        if target.exists():
            raise UserError(f"{target}: already there; move it away to restart {out}")
        out.rename(target)
        print(f"set aside: {out} -> {target}", file=sys.stderr)


def run_grid(
    runs: list[NcapRun], out: Path, executor: Executor, progress: bool = True
) -> GridOutcome:
    """Run every run missing from `out`, appending each result line as it finishes."""
    code = code_version()
    runs = [replace(r, code=code) for r in runs]
    with ResultsWriter(out) as writer:
        todo = [r for r in runs if r.id not in writer.state.ids]
        skipped = len(runs) - len(todo)
        start = time.perf_counter()
        if skipped and progress:
            say_skipped(out, skipped, len(runs), len(todo))
        finished, failed = run_missing(todo, executor, writer, "ncap", progress)
    return GridOutcome(len(runs), skipped, finished, tuple(failed), time.perf_counter() - start)


def read_results(out: Path, runs: list[NcapRun]) -> list[dict[str, Any]]:
    """The result lines of `runs` (this code's), in the runs' order."""
    wanted = {r.id for r in runs}
    rows = {row["id"]: row for row in read_rows(out) if row["id"] in wanted}
    return [rows[r.id] for r in runs if r.id in rows]
