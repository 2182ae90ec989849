"""`monopic closed-loop`: brake on the pipeline's warning and count the contacts avoided."""

from __future__ import annotations

import argparse
import platform
from pathlib import Path
from typing import TYPE_CHECKING

from tqdm import tqdm

from monopic.cli.args import non_negative_float, output_file, output_folder
from monopic.errors import UserError
from monopic.output import write_text_atomically

if TYPE_CHECKING:  # the simulator is imported when the command runs
    from sim.scenario.spec import Scenario

FAMILY_FOLDER = Path("scenarios/families/small")
# The Euro NCAP-style collision families at the small robot's scale.
NCAP_FAMILIES = ("cpna25", "cpna75", "cpfa50", "cpnco50", "cpla25", "cpla50")
DEFAULT_POLICIES = "none,truth,rules/image,rules/ground"
MEET_TIME = 3.0  # s: --cases crossings meet the robot then unless it brakes
CASE_SPEEDS = "1,2,3"  # m/s: --cases has no file to take a speed from


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "closed-loop",
        help="brake on the pipeline's warning (with its latency): contacts with and without",
        description="Run each scenario in the gymnasium environment once per policy: 'none' "
        "(never brakes), 'truth' (brakes when the ground truth says contact within the "
        "horizon) and PREDICTOR/MODE (brakes at the robot's maximum deceleration when that "
        "predictor warns; the command acts after the pipeline's measured latency, at the "
        "next frame boundary). Prints contact rate, impact speed and minimum footprint gap "
        "per policy. Default scenarios: the small-robot Euro NCAP-style collision families "
        f"({', '.join(NCAP_FAMILIES)} in {FAMILY_FOLDER}). A scenario file (a default family "
        "too) runs at its own robot speed and seed unless --speeds or --seed replace them, "
        "with the file's checks (e.g. its robot's max_speed).",
    )
    p.add_argument(
        "files",
        nargs="*",
        type=Path,
        metavar="SCENARIO.toml",
        help="scenario files, each at its own robot speed or at every --speeds (default: "
        "the families above)",
    )
    p.add_argument(
        "--cases",
        help="instead of files: place_case crossings on a collision course, e.g. 5,6 "
        f"(they meet the robot's front at {MEET_TIME:g} s unless it brakes)",
    )
    p.add_argument(
        "--speeds",
        help="robot speeds, m/s, comma-separated (default: each file's own robot.speed; "
        f"--cases: {CASE_SPEEDS})",
    )
    p.add_argument(
        "--policies",
        default=DEFAULT_POLICIES,
        help="comma-separated: none, truth, or PREDICTOR/MODE with a predictor's registry "
        "name (as results and reports name them, e.g. tree/image) and image or ground "
        "mode (default %(default)s)",
    )
    p.add_argument(
        "--latency-ms",
        type=non_negative_float,
        help="apply this fixed latency instead of the measured one",
    )
    p.add_argument(
        "--seed",
        type=int,
        help="environment seed: the gait phase (default: each file's own seed; --cases: 0)",
    )
    p.add_argument("--out", type=Path, help="write the tables (Markdown) here")
    p.add_argument("--rrd-dir", type=Path, help="record every braking run into this folder")
    p.set_defaults(func=run)


def _numbers(text: str, option: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UserError(f"{option}: expected numbers separated by commas, got {text!r}") from None
    if not values or any(not v >= 0 for v in values):
        raise UserError(f"{option}: expected numbers >= 0, got {text!r}")
    return values


def case_scenarios(cases: str, speeds: list[float], seed: int | None = None) -> list[Scenario]:
    """Crossings on a collision course, each placed as a small-scale scenario file with
    path.kind = "case" would place it (sim.scenario.files.placed_case): its checks."""
    from monopic.cases import Case
    from sim.scenario.files import Given, placed_case

    out = []
    for text in cases.split(","):
        try:
            case = Case(int(text))
        except ValueError:
            raise UserError(f"--cases: {text!r} is not a case number 1-9") from None
        if case.lateral == 0:
            raise UserError(f"--cases: case {int(case)} ({case.label}) does not cross the path")
        for v in speeds:
            if v <= 0:
                raise UserError("--speeds: a crossing needs a moving robot (> 0 m/s)")
            given = [Given("--speeds", "robot.speed", v)]
            if seed is not None:
                given.append(Given("--seed", "seed", seed))
            fixed = {"path.distance": v * MEET_TIME, "path.meet_time": MEET_TIME,
                     "duration": MEET_TIME + 1.0}  # fmt: skip
            name = f"case{int(case)}@{v:g}"
            out.append(placed_case(case, given, fixed, name=name, where=f"case {int(case)}: "))
    return out


def file_scenarios(
    files: list[Path], speeds: list[float] | None, seed: int | None
) -> list[Scenario]:
    """Each file at its own robot speed and seed, or at each of `speeds` and at `seed`:
    given values go through the file's checks (ScenarioFile.with_given)."""
    from sim.scenario.files import Given, load

    out = []
    for path in files:
        sf = load(path)
        seeds = [] if seed is None else [Given("--seed", "seed", seed)]
        for v in speeds if speeds is not None else [sf.base.robot.speed]:
            given = [Given("--speeds", "robot.speed", v)] if speeds is not None else []
            out.append(sf.with_given(given + seeds, name=f"{sf.name}@{v:g}"))
    return out


def _speeds_seen(scenarios: list[Scenario]) -> str:
    """The robot speeds the scenarios start at, as the footer names them."""
    speeds = sorted({s.robot.speed for s in scenarios})
    return ",".join(f"{v:g}" for v in speeds)


def _seeds_seen(scenarios: list[Scenario]) -> str:
    """The scenarios' seeds, as the footer names them."""
    return ",".join(str(v) for v in sorted({s.seed for s in scenarios}))


def run(args: argparse.Namespace) -> int:
    from sim.runs.closed_loop import (
        NO_BRAKE,
        check_policy,
        format_runs,
        format_table,
        run_closed_loop,
        summarise,
    )

    speeds = None if args.speeds is None else _numbers(args.speeds, "--speeds")
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
        case_speeds = speeds if speeds is not None else _numbers(CASE_SPEEDS, "--speeds")
        scenarios = case_scenarios(args.cases, case_speeds, args.seed)
        source = f"place_case crossings {args.cases} meeting the robot at {MEET_TIME:g} s"
        chosen = "--speeds" if speeds is not None else "the --cases default"
    else:
        files = args.files or [FAMILY_FOLDER / f"{name}.toml" for name in NCAP_FAMILIES]
        scenarios = file_scenarios(files, speeds, args.seed)
        source = ", ".join(str(f) for f in files)
        chosen = "--speeds" if speeds is not None else "each file's own"
    if args.out is not None:
        output_file(args.out, "--out")
    if args.rrd_dir is not None:
        output_folder(args.rrd_dir, "--rrd-dir")
    outcomes = []
    with tqdm(total=len(scenarios) * len(policies), unit="run") as bar:
        for scenario in scenarios:
            for policy in policies:
                bar.set_description(f"{scenario.name} {policy}")
                rrd = None
                if args.rrd_dir is not None and policy != NO_BRAKE:
                    rrd = args.rrd_dir / f"{scenario.name}-{policy.replace('/', '-')}.rrd"
                try:
                    outcomes.append(
                        run_closed_loop(
                            scenario,
                            policy,
                            seed=scenario.seed,
                            latency_ms=args.latency_ms,
                            rrd=rrd,
                        )
                    )
                except ValueError as err:
                    raise UserError(f"policy {policy!r}: {err}") from None
                bar.update(1)
    cam = scenarios[0].robot.camera
    latency = "measured per frame" if args.latency_ms is None else f"fixed {args.latency_ms:g} ms"
    if args.seed is not None:
        seeds = "--seed"
    else:
        seeds = "the --cases default" if args.cases else "each file's own"
    ran_on = (
        f"{len(scenarios)} scenarios ({source}; robot speeds {_speeds_seen(scenarios)} m/s: "
        f"{chosen}), seed {_seeds_seen(scenarios)} ({seeds}), {cam.width}x{cam.height} frames "
        f"at {1 / scenarios[0].dt:.0f} fps, "
        f"horizon {scenarios[0].horizon:g} s, latency {latency}; "
        f"{platform.processor() or platform.machine()}, {platform.node()}"
    )
    table = format_table(summarise(outcomes))
    print(table)
    print(f"\nRan on: {ran_on}")
    if args.out is not None:
        text = (
            f"# Closed loop: braking on the warning\n\nRan on: {ran_on}\n\n{table}\n\n"
            f"## Runs\n\n{format_runs(outcomes)}\n"
        )
        write_text_atomically(args.out, text)
        print(f"tables: {args.out}")
    return 0
