"""`monopic closed-loop`: brake on the pipeline's warning and count the contacts avoided."""

from __future__ import annotations

import argparse
import platform
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Any

from monopic.cli.args import (
    deprecated_alias,
    output_file,
    output_folder,
    ranged,
)
from monopic.errors import UserError
from monopic.output import write_text_atomically
from sim.commands.executor_options import (
    add_executor_options,
    check_executor_options,
    logs_above_the_bar,
    make_executor,
)
from sim.commands.tracker_option import add_tracker_option

if TYPE_CHECKING:  # the simulator is imported when the command runs
    from sim.scenario.spec import Scenario

FAMILY_FOLDER = Path("scenarios/families/small")
# The Euro NCAP-style collision families at the small robot's scale.
NCAP_FAMILIES = ("cpna25", "cpna75", "cpfa50", "cpnco50", "cpla25", "cpla50")
DEFAULT_POLICIES = "none,truth,rules/image,rules/ground"
MEET_TIME = 3.0  # s: --cases crossings meet the robot then unless it brakes
CASE_SPEEDS = "1,2,3"  # m/s: --cases has no file to take a speed from
DEFAULT_RESULTS = Path("recordings/closed-loop.jsonl")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "closed-loop",
        help="brake on the pipeline's warning (with its latency): contacts with and without",
        description="Run each scenario in the gymnasium environment once per policy: 'none' "
        "(never brakes), 'truth' (brakes when the ground truth says contact within the "
        "horizon) and PREDICTOR/MODE (brakes at the robot's maximum deceleration when that "
        "predictor warns; the command acts after the pipeline's measured latency, at the "
        "next frame boundary). Prints contact rate, impact speed and minimum footprint gap "
        "per policy, and the runs to look at (a braking policy's contacts, its needless "
        "stops, and its brakes for the wrong person: for nobody or for someone not on a "
        "collision course, named where a run names whom it braked for, i.e. with --tracker "
        "everyone or several people) each with the `monopic rerun` command that runs it "
        "again into a recording. "
        "Default scenarios: the small-robot Euro NCAP-style collision families "
        f"({', '.join(NCAP_FAMILIES)} in {FAMILY_FOLDER}). A scenario file (a default family "
        "too) runs at its own robot speed and seed unless --robot-speeds or --seed replace "
        "them, with the file's checks (e.g. its robot's max_speed). The runs go to local "
        "workers (or Ray) and one result line each to a results file: the same command "
        "again runs only the runs it lacks.",
    )
    p.add_argument(
        "files",
        nargs="*",
        type=Path,
        metavar="SCENARIO.toml",
        help="scenario files, each at its own robot speed or at every --robot-speeds "
        "(default: the families above)",
    )
    p.add_argument(
        "--cases",
        help="instead of files: place_case crossings on a collision course, e.g. 5,6 "
        f"(they meet the robot's front at {MEET_TIME:g} s unless it brakes)",
    )
    speeds = p.add_argument(
        "--robot-speeds",
        metavar="M/S,...",
        help="robot speeds, m/s, comma-separated, as record's --robot-speed (default: each "
        f"file's own robot.speed; --cases: {CASE_SPEEDS})",
    )
    deprecated_alias(p, speeds, "--speeds")
    p.add_argument(
        "--policies",
        default=DEFAULT_POLICIES,
        help="comma-separated: none, truth, or PREDICTOR/MODE with a predictor's registry "
        "name (as results and reports name them, e.g. tree/image) and image or ground "
        "mode (default %(default)s)",
    )
    p.add_argument(
        "--latency-ms",
        type=ranged(0),
        help="apply this fixed latency (ms, >= 0) instead of the measured one",
    )
    p.add_argument(
        "--seed",
        type=ranged(0, 2**31 - 1, integer=True),
        help="environment seed: the gait phase ([0, 2147483647], as a scenario file's seed; "
        "default: each file's own seed; --cases: 0)",
    )
    p.add_argument("--out", type=Path, help="write the tables (Markdown) here")
    p.add_argument(
        "--results",
        type=Path,
        metavar="FILE.jsonl",
        help="results file, one line per finished run, resumable (default: beside --out "
        f"as <out>.jsonl; without --out {DEFAULT_RESULTS})",
    )
    add_tracker_option(p, "figure")
    p.add_argument("--rrd-dir", type=Path, help="record every braking run into this folder")
    add_executor_options(p)
    p.add_argument(
        "--restart",
        action="store_true",
        help="if the results file holds runs made by other code, rename it to "
        "<name>.<code>.jsonl and start over; without it such a file is an error",
    )
    p.set_defaults(func=run)


def _numbers(text: str, option: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UserError(f"{option}: expected numbers separated by commas, got {text!r}") from None
    if not values or any(not v >= 0 for v in values):
        raise UserError(f"{option}: expected numbers >= 0, got {text!r}")
    return values


def _speeds_seen(scenarios: list[Scenario]) -> str:
    """The robot speeds the scenarios start at, as the footer names them."""
    speeds = sorted({s.robot.speed for s in scenarios})
    return ",".join(f"{v:g}" for v in speeds)


def _seeds_seen(scenarios: list[Scenario]) -> str:
    """The scenarios' seeds, as the footer names them."""
    return ",".join(str(v) for v in sorted({s.seed for s in scenarios}))


def results_path(args: argparse.Namespace) -> Path:
    """--results, or beside --out (<out>.jsonl), or DEFAULT_RESULTS."""
    if args.results is not None:
        return args.results
    if args.out is not None:
        return args.out.with_suffix(".jsonl")
    return DEFAULT_RESULTS


def run(args: argparse.Namespace) -> int:
    from sim.runs import closed_loop_grid as grid
    from sim.runs.closed_loop import NO_BRAKE, check_policy, format_runs, format_table, summarise
    from sim.runs.latency import FIXED, MEASURED, LatencySetting

    check_executor_options(args)
    speeds = None if args.robot_speeds is None else _numbers(args.robot_speeds, "--robot-speeds")
    policies = [p.strip() for p in args.policies.split(",") if p.strip()]
    if not policies:
        raise UserError(f"--policies: no policy in {args.policies!r}")
    for policy in policies:
        try:
            check_policy(policy)
        except ValueError as err:
            raise UserError(f"--policies: {err}") from None
    if NO_BRAKE not in policies:
        policies.insert(0, NO_BRAKE)  # the baseline every other policy is judged against
    if args.cases:
        if args.files:
            raise UserError("give scenario files or --cases, not both")
        case_speeds = speeds if speeds is not None else _numbers(CASE_SPEEDS, "--robot-speeds")
        sources = grid.case_sources(args.cases, case_speeds, MEET_TIME, args.seed)
        source = f"place_case crossings {args.cases} meeting the robot at {MEET_TIME:g} s"
        chosen = "--robot-speeds" if speeds is not None else "the --cases default"
    else:
        files = args.files or [FAMILY_FOLDER / f"{name}.toml" for name in NCAP_FAMILIES]
        sources = grid.file_sources(files, speeds, args.seed)
        source = ", ".join(str(f) for f in files)
        chosen = "--robot-speeds" if speeds is not None else "each file's own"
    scenarios = grid.scenarios_of(sources)
    results = results_path(args)
    if args.out is not None:
        if results.resolve() == args.out.resolve():
            raise UserError(
                f"--out {args.out}: the tables would overwrite the results file {results}; "
                "give another --out or --results"
            )
        output_file(args.out, "--out")
    grid.check_results(results, args.restart)
    output_file(results, "--results")
    if args.rrd_dir is not None:
        output_folder(args.rrd_dir, "--rrd-dir")
    latency = (
        LatencySetting(MEASURED, None)
        if args.latency_ms is None
        else LatencySetting(FIXED, float(args.latency_ms))
    )
    runs = grid.expand(sources, scenarios, policies, latency, args.rrd_dir, args.tracker)
    executor = make_executor(args, run=grid.work)
    with logs_above_the_bar(args.executor, args.address), _temporaries_cleared(args.rrd_dir):
        outcome = grid.run_runs(runs, results, executor)
    if outcome.failed:
        run_id, error = outcome.failed[0]
        raise UserError(
            f"{len(outcome.failed)} runs failed (first: {run_id}: "
            f"{error.strip().splitlines()[-1]}); {results} keeps the others: run the same "
            "command to retry them"
        )
    rows = grid.read_results(results, runs)
    outcomes = [grid.outcome_of(row) for row in rows]
    cam = scenarios[0].robot.camera
    if args.seed is not None:
        seeds = "--seed"
    else:
        seeds = "the --cases default" if args.cases else "each file's own"
    # The default tracker goes unsaid, so the tables it makes read as they always did.
    followed = "" if args.tracker == "one" else ", the people tracker (everyone in view)"
    ran_on = (
        f"{len(scenarios)} scenarios ({source}; robot speeds {_speeds_seen(scenarios)} m/s: "
        f"{chosen}), seed {_seeds_seen(scenarios)} ({seeds}), {cam.width}x{cam.height} frames "
        f"at {1 / scenarios[0].dt:.0f} fps, "
        f"horizon {scenarios[0].horizon:g} s, latency {latency.describe()}{followed}; "
        f"{platform.processor() or platform.machine()}, {platform.node()}"
    )
    table = format_table(summarise(outcomes))
    print(table)
    print(f"\nRan on: {ran_on}")
    print(f"results: {results} ({outcome.finished} runs now, {outcome.skipped} already there)")
    look = _runs_to_look_at(rows, results, args.out.parent if args.out else Path(), args.rrd_dir)
    if args.out is not None:
        text = (
            f"# Closed loop: braking on the warning\n\nRan on: {ran_on}\n\n{table}\n\n"
            f"## Runs\n\n{format_runs(outcomes)}\n\n" + "\n".join(look)
        )
        write_text_atomically(args.out, text)
        print(f"tables: {args.out}")
    else:
        print("\n" + "\n".join(look).rstrip())
    return 0


def _runs_to_look_at(
    rows: list[dict[str, Any]], results: Path, report: Path, rrd_dir: Path | None
) -> list[str]:
    from sim.analysis.triage import Rerunning, loop_triage_lines

    where = Rerunning(results, rrd_dir or results.parent, report)
    return loop_triage_lines(rows, where, recorded=rrd_dir is not None)


def _temporaries_cleared(folder: Path | None) -> AbstractContextManager[None]:
    """The recordings folder cleared of stale temporaries before and after the runs (a
    worker stopped mid-run dies without deleting the recording it was writing)."""
    from monopic.output import stale_temporaries_cleared

    return nullcontext() if folder is None else stale_temporaries_cleared(folder)
