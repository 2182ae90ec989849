"""`monopic ncap`: the Euro NCAP 2026 pedestrian grid at car scale, scored by the calculator."""

from __future__ import annotations

import argparse
import shutil
import time
from dataclasses import replace
from pathlib import Path

from monopic.cli.args import deprecated_alias, non_negative_float, output_folder, positive_int
from monopic.errors import UserError
from monopic.output import write_text_atomically
from sim.commands.executor_options import (
    add_executor_options,
    check_executor_options,
    logs_above_the_bar,
    make_executor,
)
from sim.commands.tracker_option import add_tracker_option
from sim.sensor.spec import PRESETS as CAMERAS

PROTOCOL = Path("scenarios/ncap/protocol.toml")
CAR = Path("scenarios/ncap/car.toml")
# The protocol's tests this grid runs, by their protocol.toml names (a test checks): the
# day matrices and the night ones.
TESTS = ("cpna", "cpfa", "cpnco", "cpla", "cpna-night", "cpfa-night", "cpnco-night", "cpla-night")
LEFT_UNSCORED = (
    "CPTA (turning: needs a robot that turns and a truth that follows it); the "
    "extended range (impact locations outside the standard range, filled Red); the "
    "robustness layers (all claimed NO); every cyclist, car and motorcycle load case (not "
    "claimed)"
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ncap",
        help="Euro NCAP 2026 pedestrian tests at car scale, scored by the official calculator",
        description="Run the Euro NCAP 2026 pedestrian frontal-collision grid (CPNA, CPFA, "
        "CPNCO, CPLA; day) at car scale in closed loop: the car brakes on the pipeline's "
        "warning after its latency (by default the car file's declared one, so the score "
        "does not move with the host's load) and a brake delay, jerk-limited, its camera "
        "dipping as it brakes; every grid point is run with jittered seeds (worst and mean "
        "reported) plus an independent verification run; car-scale near misses beside. "
        "Then the official rating calculator (extra [ncap]) scores it: generate-template, "
        "preprocess, compute-score. Writes DIR/results.jsonl (resumable), DIR/report.md, "
        "its matrix pictures and DIR/calculator/*.xlsx. Protocol and car: "
        f"{PROTOCOL}, {CAR}.",
    )
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder")
    p.add_argument(
        "--tests",
        default=",".join(TESTS),
        help=f"comma-separated, of {', '.join(TESTS)} (car-to-pedestrian nearside adult, "
        "farside adult, nearside child obstructed, longitudinal adult, by day and at night: "
        "low beams, 1 lux, the published night roads' lamps; default: all eight)",
    )
    p.add_argument("--quick", action="store_true", help="the thin grid (CI and the demo)")
    speeds = p.add_argument(
        "--speeds-kmh",
        metavar="KMH",
        help="only these car speeds, km/h, comma-separated, e.g. 20,40 (default: every "
        "speed of the grid)",
    )
    deprecated_alias(p, speeds, "--speeds")
    p.add_argument("--policies", help="default: the car file's (--quick: its primary)")
    runs = p.add_argument(
        "--runs-per-point",
        type=positive_int,
        metavar="N",
        help="jittered runs per grid point (>= 1; default: the car file's seeds, or "
        "quick_seeds with --quick)",
    )
    deprecated_alias(p, runs, "--seeds")
    p.add_argument("--no-near-misses", action="store_true", help="skip the near misses")
    latency = p.add_mutually_exclusive_group()
    latency.add_argument(
        "--latency-ms",
        type=non_negative_float,
        help="apply this fixed latency (>= 0) instead of the car file's declared latency_ms",
    )
    latency.add_argument(
        "--measured-latency",
        action="store_true",
        help="apply the pipeline's latency measured on this host per frame instead of the "
        "declared one (the score then moves with the host's speed and load)",
    )
    add_tracker_option(p, "rating")
    p.add_argument(
        "--camera",
        choices=tuple(CAMERAS),
        help="the camera's sensor preset for every run (default: the car file's [camera] "
        "preset; ideal: the renderer's frames as they are, as every grid before the camera "
        "model had)",
    )
    p.add_argument(
        "--beside",
        type=Path,
        metavar="DIR",
        help="another grid's output folder (e.g. the same grid under the ideal camera): its "
        "calculator points are shown beside this grid's in the report",
    )
    add_executor_options(p)
    p.add_argument("--restart", action="store_true", help="set aside other code's results")
    p.add_argument(
        "--protocol",
        type=Path,
        default=PROTOCOL,
        help="the protocol's grid, speeds and tolerances (default %(default)s)",
    )
    p.add_argument(
        "--car",
        type=Path,
        default=CAR,
        help="the car under test: brake, pitch, policies (default %(default)s)",
    )
    p.set_defaults(func=run)


def _speeds(text: str | None) -> list[float] | None:
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values:
        raise UserError(f"--speeds-kmh: expected km/h numbers separated by commas, got {text!r}")
    return values


def run(args: argparse.Namespace) -> int:
    # Everything is checked before anything is written.
    from sim.analysis.ncap_score import require_calculator
    from sim.scenario.ncap import load_car, load_protocol

    check_executor_options(args)
    version = require_calculator()
    protocol = load_protocol(args.protocol)
    car = load_car(args.car)
    if args.camera is not None:
        car = replace(car, sensor=CAMERAS[args.camera])
    from sim.analysis.ncap_report import beside_scores

    beside = None if args.beside is None else beside_scores(args.beside)
    tests = [t.strip().lower() for t in args.tests.split(",") if t.strip()]
    for t in tests:
        if t not in protocol.tests:
            raise UserError(
                f"--tests: unknown test {t!r} (known: {', '.join(protocol.tests)}; turning "
                "tests are not in this grid)"
            )
    if not tests:
        raise UserError("--tests: name at least one test")
    speeds = _speeds(args.speeds_kmh)
    if speeds is not None:
        for v in speeds:
            ranges = [protocol.tests[t].speed_range for t in tests]
            known = {s for t in tests for row in protocol.tests[t].rows for s in row.speeds_kmh}
            if v not in known:
                spans = ", ".join(
                    f"{t} {lo:g}-{hi:g}" for t, (lo, hi) in zip(tests, ranges, strict=True)
                )
                raise UserError(
                    f"--speeds-kmh {v:g}: not a test speed of the protocol's grid ({spans} km/h "
                    "in 10 km/h steps)"
                )
    default = (car.primary,) if args.quick else car.policies  # quick: the primary only
    policies = default if args.policies is None else tuple(
        p.strip() for p in args.policies.split(",") if p.strip()
    )  # fmt: skip
    from monopic.predict.base import Mode
    from monopic.predict.registry import predictor_names

    for policy in policies:
        name, _, mode = policy.partition("/")
        if mode not in {m.value for m in Mode} or name not in predictor_names():
            raise UserError(f"--policies: {policy!r} is not PREDICTOR/MODE "
                            f"({', '.join(predictor_names())}; image or ground)")  # fmt: skip
    if args.out.exists() and not args.out.is_dir():
        raise UserError(f"--out {args.out}: is a file, not a folder")

    from sim.analysis import ncap_report as rep
    from sim.analysis.ncap_score import score, score_halves
    from sim.runs import ncap_grid

    latency = ncap_grid.latency_setting(car, args.latency_ms, args.measured_latency)
    runs = ncap_grid.expand(
        protocol, car, tests, list(policies), quick=args.quick, speeds=speeds,
        seeds=args.runs_per_point, near_misses=not args.no_near_misses, latency=latency,
        tracker=args.tracker,
    )  # fmt: skip
    output_folder(args.out, "--out")
    results = args.out / "results.jsonl"
    ncap_grid.check_results(results, args.restart)
    executor = make_executor(args, run=ncap_grid.work)
    t0 = time.perf_counter()
    with logs_above_the_bar(args.executor, args.address):
        outcome = ncap_grid.run_grid(runs, results, executor)
    wall = time.perf_counter() - t0
    if outcome.failed:
        raise UserError(
            f"{len(outcome.failed)} runs failed (first: {outcome.failed[0][0]}); "
            f"{results} keeps the others: run the same command to retry them"
        )
    rows = ncap_grid.read_results(results, runs)
    points = rep.summarise(rows)
    claimed = {protocol.tests[t].load_case.split(" ")[0] for t in tests}
    scores, halves = {}, {}
    for policy in policies:
        folder = args.out / "calculator" / policy.replace("/", "-")
        if folder.exists():
            shutil.rmtree(folder)
        cells = rep.cells(points, policy)
        scores[policy] = score(folder, cells, claimed)
        halves[policy] = score_halves(folder, cells, claimed)
    pictures = []
    for policy in policies:
        name = f"matrix-{policy.replace('/', '-')}.png"
        rep.plot_matrices(protocol, points, policy, tests, args.out / name)
        pictures.append((policy, name))
    from sim.runs.runner import machine as this_machine

    m = this_machine()
    machine = f"{m.cpu}, {m.cores} cores, host {m.host}"
    text = rep.render(
        protocol=protocol,
        car=car,
        tests=tests,
        quick=args.quick,
        speeds=speeds,
        seeds=args.runs_per_point or (car.quick_seeds if args.quick else car.seeds),
        rows=rows,
        points=points,
        scores=scores,
        pictures=pictures,
        command=_command(args),
        machine=machine,
        wall_s=wall,
        ran_now=outcome.finished,
        version=version,
        left_unscored=LEFT_UNSCORED,
        out=args.out,
        latency=latency,
        beside=beside,
        halves=halves,
    )
    write_text_atomically(args.out / "report.md", text)
    print(rep.score_table(scores, claimed))
    if any(halves.values()):
        print(rep.halves_table(halves, claimed, tests, protocol))
    print(rep.latency_line(latency, car, rows))
    print(f"report: {args.out / 'report.md'}")
    return 0


def _command(args: argparse.Namespace) -> str:
    parts = ["monopic ncap"]
    if args.tests != ",".join(TESTS):
        parts.append(f"--tests {args.tests}")
    if args.quick:
        parts.append("--quick")
    for flag in ("speeds_kmh", "policies", "runs_per_point", "workers"):
        if getattr(args, flag) is not None:
            parts.append(f"--{flag.replace('_', '-')} {getattr(args, flag)}")
    if args.no_near_misses:
        parts.append("--no-near-misses")
    if args.latency_ms is not None:
        parts.append(f"--latency-ms {args.latency_ms:g}")
    if args.measured_latency:
        parts.append("--measured-latency")
    if args.tracker != "one":
        parts.append(f"--tracker {args.tracker}")
    if args.camera is not None:
        parts.append(f"--camera {args.camera}")
    if args.beside is not None:
        parts.append(f"--beside {args.beside}")
    parts.append(f"--out {args.out}")
    return " ".join(parts)
