"""`monopic record SCENARIO`: run one simulated scenario through the pipeline into a .rrd file."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from tqdm import tqdm

from monopic.cases import Case
from monopic.cli.args import output_file
from monopic.errors import UserError

if TYPE_CHECKING:  # the simulator is imported when a command runs, not when the CLI starts
    from sim.scenario.spec import Scenario

DEFAULT_FOLDER = Path("recordings")
SCENARIO_HELP = """\
SCENARIO is a case number 1-9 or its name (e.g. 5, case5, perpendicular-right), or
`crossing` (an adult crossing into the robot's path; contact at 2.7 s unless it
brakes), or a scenario file (scenarios/**/*.toml: its base scenario, without its sweep).
Cases are placed by sim.scenario.cases.CasePlacement; the options below set its parameters.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "record",
        help="record a simulated scenario run (camera, pipeline, truth, world) to .rrd",
        description="Render a scenario, run every frame through the pipeline (all predictors, "
        "image and ground mode) and write a rerun recording: the camera with the pose, "
        "predictions and the ground truth, a 3D world view, highway-env's top-down view, "
        "time series and warnings. Open it with `monopic view FILE.rrd`.\n\n" + SCENARIO_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenario", metavar="SCENARIO", help="a case, 'crossing' or a scenario file")
    p.add_argument("--rrd", type=Path, help="output file (default recordings/<scenario>.rrd)")
    p.add_argument(
        "--topdown-every",
        type=int,
        default=3,
        metavar="N",
        help="log highway-env's top-down view every N frames (0: never; default 3)",
    )
    p.add_argument(
        "--after-contact",
        action="store_true",
        help="keep running after the footprints meet (default: stop at contact)",
    )
    add_case_options(p)
    p.set_defaults(func=run)


# CasePlacement's parameters the command offers (defaults and ranges are the placement's).
CASE_OPTIONS = ("distance", "lateral_offset", "pedestrian_speed", "robot_speed", "duration", "seed")


def add_case_options(p: argparse.ArgumentParser) -> None:
    """CasePlacement's parameters, for scenarios given as a case."""
    from sim.scenario.cases import PLACEMENT_FIELDS, placement_help

    g = p.add_argument_group("case placement (SCENARIO given as a case)")
    for name in CASE_OPTIONS:
        f = PLACEMENT_FIELDS[name]
        g.add_argument(
            f"--{name.replace('_', '-')}",
            type=int if f.type in (int, "int") else float,
            default=f.default,
            help=placement_help(name),
        )


def parse_case(text: str) -> Case | None:
    """A case from '5', 'case5' or 'perpendicular-right'; None if it is none of these."""
    key = text.strip().lower().replace("_", "-").replace(" ", "-")
    number = key.removeprefix("case")
    if number.isdigit():
        value = int(number)
        if not 1 <= value <= 9:
            raise UserError(f"scenario {text!r}: case numbers run from 1 to 9")
        return Case(value)
    for case in Case:
        if key == case.label.replace(" ", "-"):
            return case
    return None


def resolve_scenario(text: str, args: argparse.Namespace) -> Scenario:
    """The Scenario named on the command line (see SCENARIO_HELP)."""
    from sim.scenario.cases import CasePlacement, default_crossing
    from sim.scenario.families import PlacementError
    from sim.scenario.files import load, street_problem
    from sim.scenario.toml_table import show

    if text.endswith(".toml") or Path(text).is_file():
        return load(Path(text)).base
    if text.strip().lower() == "crossing":
        return default_crossing()
    case = parse_case(text)
    if case is None:
        raise UserError(
            f"scenario {text!r}: not a case number 1-9, a case name (e.g. perpendicular-right), "
            "'crossing' or an existing .toml file"
        )
    try:
        placement = CasePlacement(case, **{name: getattr(args, name) for name in CASE_OPTIONS})
    except PlacementError as err:
        flag = f"--{err.field.replace('_', '-')}"
        raise UserError(f"{flag} {err.value:g}: {err.reason}") from None
    scenario = placement.scenario()
    problem = street_problem(scenario)  # what a scenario file with these values is told
    if problem is not None:
        if problem.field == "robot.speed":
            raise UserError(f"--robot-speed {problem.value:g}: {problem.reason}")
        raise UserError(
            f"--distance {args.distance:g} --lateral-offset {args.lateral_offset:g}: "
            f"{problem.reason}; at {show(problem.value)}"
        )
    return scenario


def run(args: argparse.Namespace) -> int:
    from sim.runs.record import record_run

    if args.topdown_every < 0:
        raise UserError(f"--topdown-every: must be >= 0, got {args.topdown_every}")
    scenario = resolve_scenario(args.scenario, args)
    path = output_file(args.rrd or DEFAULT_FOLDER / f"{scenario.name}.rrd", "--rrd")
    with tqdm(total=scenario.frames, unit="frame", desc=scenario.name) as bar:
        summary = record_run(
            scenario,
            path,
            topdown_every=args.topdown_every,
            stop_at_contact=not args.after_contact,
            on_frame=lambda _: bar.update(1),
        )
    contact = (
        f"contact at {summary.contact_time:.2f} s" if summary.contact_time is not None else "none"
    )
    warned = ", ".join(f"{k} {v}" for k, v in summary.warned.items()) or "none"
    print(
        f"{summary.frames} frames ({scenario.dt * summary.frames:.1f} s), pose found in "
        f"{summary.found}; true collision within the horizon in {summary.collision_frames}; "
        f"contact: {contact}"
    )
    print(f"frames with a warning: {warned}")
    print(f"recording: {path} ({summary.bytes / 1e6:.1f} MB); open it with: monopic view {path}")
    return 0
