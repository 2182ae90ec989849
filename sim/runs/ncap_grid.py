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

The camera (`camera`: the car file's sensor preset, or the command's `--camera`) changes
every scenario's identity, so the ideal camera's and a real one's runs never mix; a row
names it only when it is a real camera.

The tracker (`tracker`: one pedestrian or everyone, sim.runs.run_spec.TRACKERS) enters a
run's id and line only when it is the people tracker, so a one-tracker grid keeps the ids
and lines it always had (sim.runs.closed_loop.OPTIONAL for the outcome's fields).
"""

from __future__ import annotations

import hashlib
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from sim.runs.aeb import AebParams, run_aeb
from sim.runs.closed_loop import outcome_json
from sim.runs.latency import DECLARED, FIXED, MEASURED, LatencySetting
from sim.runs.results_file import check_resumable, without_keys
from sim.runs.run_spec import ONE, TRACKERS
from sim.runs.runner import machine
from sim.runs.sweep import SweepOutcome, rows_of, run_resumable
from sim.scenario.files import ScenarioFile, load
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
from sim.sensor.spec import IDEAL, preset
from sim.world.render import KeptRenderContext

SCHEMA = 1
GRID, VERIFY, NEAR_MISS = "grid", "verify", "near-miss"


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
    """One closed-loop run as a worker receives it (plain, picklable data).

    `replay`: per-frame latencies to apply instead of measuring them (`monopic rerun` of a
    run made with the measured latency); `rrd`: a recording to write of the run ("" none).
    """

    id: str
    scenario: Scenario
    policy: str
    aeb: AebParams
    role: str  # GRID, VERIFY or NEAR_MISS
    index: int  # draw number (near misses: seed number)
    # test, function, speed, impact, draw; the protocol and car files it was made from
    meta: dict[str, Any] = field(default_factory=dict)
    code: str = ""
    latency: LatencySetting = LatencySetting(MEASURED, None)
    replay: tuple[float, ...] | None = None
    rrd: str = ""
    tracker: str = ONE  # whom the policy's pipeline follows (TRACKERS)

    def __post_init__(self) -> None:
        if self.tracker not in TRACKERS:
            raise ValueError(f"tracker must be one of {', '.join(TRACKERS)}, got {self.tracker!r}")
        if self.latency.ms != self.aeb.latency_ms:  # the row must say what the run applied
            raise ValueError(f"latency {self.latency} but AEB {self.aeb}")


def aeb_params(car: CarSpec, latency: LatencySetting) -> AebParams:
    return AebParams(car.brake_delay, car.jerk, car.deceleration, latency.ms)


def run_digest(scenario: Scenario, aeb: AebParams, tracker: str = ONE) -> str:
    """8 hex digits of the scenario, the AEB (brake and applied latency) and the tracker
    (the people tracker only: a one-tracker run keeps its digest): a run's identity."""
    text = f"{scenario_digest(scenario)}|{aeb!r}"
    if tracker != ONE:
        text += f"|tracker={tracker}"
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
    tracker: str = ONE,
) -> list[NcapRun]:
    """Every run of the grid, in a stable order (policy, point, role, draw).

    `latency` None: the car file's declared latency (sim.runs.ncap_grid.latency_setting);
    `tracker`: whom the pipelines follow (TRACKERS).
    """
    latency = latency_setting(car) if latency is None else latency
    n_grid = (car.quick_seeds if quick else car.seeds) if seeds is None else seeds
    points = grid(protocol, tests, quick, speeds)
    nm = protocol.near_misses
    files = [load(path) for path in nm.files] if near_misses else []
    runs = []
    for policy in policies:
        for point in points:
            roles = [(GRID, k) for k in range(n_grid)]
            roles += [(VERIFY, n_grid + k) for k in range(car.verification_seeds)]
            for role, k in roles:
                runs.append(grid_run(protocol, car, policy, point, role, k, latency, tracker))
        for sf in files:
            for v in nm.quick_speeds_kmh if quick else nm.speeds_kmh:
                if speeds is not None and v not in speeds:
                    continue
                for k in range(nm.quick_seeds if quick else nm.seeds):
                    runs.append(near_miss_run(protocol, car, policy, sf, v, k, latency, tracker))
    return runs


def grid_run(
    protocol: Protocol, car: CarSpec, policy: str, point: GridPoint, role: str, k: int,
    latency: LatencySetting, tracker: str = ONE,
) -> NcapRun:  # fmt: skip
    """The `k`-th draw of a grid point (role GRID or VERIFY)."""
    d = draw_for(protocol.tolerances, point.id, k)
    scenario = scenario_for(protocol, car, point, d, seed=k)
    meta = {**asdict(point), "draw": asdict(d), "load_case": protocol.tests[point.test].load_case}
    return _run(protocol, car, policy, point.id, role, k, scenario, meta, latency, tracker)


def near_miss_run(
    protocol: Protocol, car: CarSpec, policy: str, sf: ScenarioFile, speed_kmh: float, k: int,
    latency: LatencySetting, tracker: str = ONE,
) -> NcapRun:  # fmt: skip
    """Seed `k` of a car-scale near miss at `speed_kmh`, braking as the car does."""
    base = sf.scenario({"robot.speed": speed_kmh * KMH}, name=sf.name)
    camera = replace(base.robot.camera, sensor=car.sensor)
    robot = replace(base.robot, max_deceleration=car.deceleration, pitch=car.pitch, camera=camera)
    s = replace(base, robot=robot, seed=k)
    meta = {"test": "near-miss", "family": sf.name, "speed_kmh": speed_kmh}
    key = f"{sf.name}/{speed_kmh:g}kmh"
    return _run(protocol, car, policy, key, NEAR_MISS, k, s, meta, latency, tracker)


def _run(protocol: Protocol, car: CarSpec, policy: str, key: str, role: str, k: int,
         s: Scenario, meta: dict[str, Any], latency: LatencySetting,
         tracker: str = ONE) -> NcapRun:  # fmt: skip
    aeb = aeb_params(car, latency)
    rid = f"{policy}/{key}/{role}{k}-{run_digest(s, aeb, tracker)}"
    # The files a rerun rebuilds the run from (sim.runs.rebuild), as the command was given them.
    meta = {**meta, "protocol": str(protocol.path), "car": str(car.path)}
    meta["lighting"] = s.scene.lighting.name
    if tracker != ONE:  # only the people tracker's lines say it (OPTIONAL's rule)
        meta["tracker"] = tracker
    if car.sensor is not None:  # only a real camera's lines say it, as with the tracker
        meta["camera"] = car.sensor.name
    return NcapRun(
        rid, replace(s, name=rid), policy, aeb, role, k, meta, latency=latency, tracker=tracker
    )


def run_of(protocol: Protocol, car: CarSpec, row: dict[str, Any]) -> NcapRun:
    """The run a results row was made by, rebuilt from the protocol and car files: its id
    is the row's unless the files (or the code placing the runs) changed since. KeyError,
    TypeError or ValueError for a row that is not a grid's line."""
    latency = LatencySetting.from_json(row["latency"])
    policy, role, k = row["policy"], row["role"], int(row["index"])
    tracker = str(row.get("tracker", ONE))
    if tracker not in TRACKERS:
        raise ValueError(f"tracker {tracker!r}")
    camera = str(row.get("camera", IDEAL))
    if camera != car.camera_name:  # a grid run under another camera than the car file's
        car = replace(car, sensor=preset(camera))
    if role == NEAR_MISS:
        for path in protocol.near_misses.files:
            sf = load(path)
            if sf.name == row["family"]:
                speed = float(row["speed_kmh"])
                return near_miss_run(protocol, car, policy, sf, speed, k, latency, tracker)
        raise ValueError(f"{protocol.path}: no near miss {row['family']!r} in near_misses.files")
    if role not in (GRID, VERIFY):
        raise ValueError(f"role {role!r}")
    point = GridPoint(row["test"], row["function"], float(row["speed_kmh"]), float(row["impact"]))
    if point.test not in protocol.tests:
        raise ValueError(f"{protocol.path}: no test {point.test!r}")
    return grid_run(protocol, car, policy, point, role, k, latency, tracker)


def work(spec: NcapRun, kept: KeptRenderContext | None = None) -> dict[str, Any]:
    """One run in a worker: its result line, or {"id", "error"} (the grid goes on)."""
    try:
        camera = spec.scenario.robot.camera
        context = kept.fitting(camera.width, camera.height) if kept is not None else None
        t0 = time.perf_counter()
        outcome = run_aeb(
            spec.scenario,
            spec.policy,
            spec.aeb,
            seed=spec.index,
            render_context=context,
            latencies_ms=spec.replay,
            rrd=Path(spec.rrd) if spec.rrd else None,
            tracker=spec.tracker,
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
            "outcome": outcome_json(outcome, spec.tracker),
            "wall_s": round(time.perf_counter() - t0, 3),
            "machine": asdict(machine()),  # the CPU's model name, as a sweep's rows have it
        }
    except Exception:  # noqa: BLE001 - reported per run
        return {"id": spec.id, "error": traceback.format_exc()}


def run_said(row: dict[str, Any]) -> str:
    """A row's run in words: 'CPNA day AEB 20 km/h, impact 50 %, grid run 0' or
    'nearmiss_kerb_stop at 40 km/h, seed 1'."""
    if row["role"] == NEAR_MISS:
        return f"{row['family']} at {row['speed_kmh']:g} km/h, seed {row['index']}"
    return (f"{row['load_case']} {row['function']} {row['speed_kmh']:g} km/h, impact "
            f"{round(100 * row['impact']):d}%, {row['role']} run {row['index']}")  # fmt: skip


# What a row holds that depends on the host's speed and load, not on the pipeline and the
# settings: with a declared or fixed latency everything else of a row is the same on one
# host at any load (tests/sim/test_ncap.py runs a grid point under an artificial load).
HOST_TIMING = ("wall_s", "machine")
OUTCOME_TIMING = ("latencies_ms", "latency_ms_median")


def without_timing(row: dict[str, Any]) -> dict[str, Any]:
    """A result row without its measured times and machine (see HOST_TIMING)."""
    return without_keys(row, HOST_TIMING, OUTCOME_TIMING)


Executor = Callable[[Sequence[NcapRun], Callable[[dict[str, Any]], None]], None]


def check_results(out: Path, restart: bool) -> None:
    """Refuse (one line) a results file of other code or of a newer schema, unless
    `restart` sets it aside, and one another grid is appending to (as a sweep does)."""
    check_resumable(out, SCHEMA, restart, "--out")


def run_grid(
    runs: list[NcapRun], out: Path, executor: Executor, progress: bool = True
) -> SweepOutcome:
    """Run every run missing from `out`, appending each result line as it finishes."""
    return run_resumable(runs, out, executor, "ncap", progress)


def read_results(out: Path, runs: list[NcapRun]) -> list[dict[str, Any]]:
    """The result lines of `runs` (this code's), in the runs' order."""
    return rows_of(out, runs)
