"""`monopic record SCENARIO`: run one simulated scenario through the pipeline into a .rrd file."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from tqdm import tqdm

from monopic.cases import Case
from monopic.cli.args import deprecated_alias, output_file, ranged
from monopic.errors import UserError

if TYPE_CHECKING:  # the simulator is imported when a command runs, not when the CLI starts
    from sim.scenario.files import Given
    from sim.scenario.spec import Scenario

DEFAULT_FOLDER = Path("recordings")
SCENARIO_HELP = """\
SCENARIO is a case number 1-9 or its name (e.g. 5, case5, perpendicular-right), or
`crossing` (an adult crossing into the robot's path; contact at 2.7 s unless it
brakes), or a scenario file (scenarios/**/*.toml: its base scenario, without its sweep).
A case is placed by sim.scenario.cases.CasePlacement as a small-scale scenario file with
path.kind = "case" would place it, with that file's checks; the options below set its
values, and for a scenario file they replace the file's own (distance and lateral offset
only where its path.kind is "case").
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
    out = p.add_argument(
        "--out",
        type=Path,
        metavar="FILE.rrd",
        help="the recording to write (default recordings/<scenario>.rrd)",
    )
    deprecated_alias(p, out, "--rrd")
    p.add_argument(
        "--topdown-every",
        type=ranged(0, integer=True),
        default=3,
        metavar="N",
        help="log highway-env's top-down view every N frames (>= 0; 0: never; default 3)",
    )
    p.add_argument(
        "--after-contact",
        action="store_true",
        help="keep running after the footprints meet (default: stop at contact)",
    )
    add_case_options(p)
    p.set_defaults(func=run)


# The options that set a case's values (or a scenario file's), and the file keys they set.
CASE_OPTIONS = {"distance": "path.distance", "lateral_offset": "path.lateral_offset",
                "pedestrian_speed": "pedestrian.speed", "robot_speed": "robot.speed",
                "duration": "duration", "seed": "seed"}  # fmt: skip


def option_range(name: str) -> tuple[float, float, bool]:
    """(low, high, low excluded) of a case option: the values it can take on the command
    line, where a case is a small-scale file's (max_speed 3 m/s) on PLACED_SCENE's street.

    Each is the placement's range narrowed by the file's checks: a standing pedestrian must
    stand on the street (distance, lateral offset), the robot under its max_speed."""
    from sim.scenario.cases import PLACEMENT_FIELDS
    from sim.scenario.families import SMALL, street_bounds
    from sim.scenario.files import PLACED_SCENE

    meta = PLACEMENT_FIELDS[name].metadata
    low, high = meta["low"], meta["high"]
    x0, x1, y0, y1 = street_bounds(PLACED_SCENE.road)
    if name == "distance":
        low, high = max(low, x0), min(high, x1)
    elif name == "lateral_offset":
        low, high = max(low, y0), min(high, y1)
    elif name == "robot_speed":
        high = min(high, SMALL.robot.max_speed)
    return low, high, bool(meta.get("open_low"))


OPTION_NOTES = {
    "distance": "to the street's end, where a standing pedestrian still stands on it; a "
    "walking one's whole path must stay on the street",
    "lateral_offset": "the street's width, as for --distance",
    "pedestrian_speed": "a scenario file's pedestrian.speed may also be 0, on other paths: "
    "a case walks at least at the ground mode's walking speed",
    "robot_speed": "under the small robot's max_speed",
}


def option_help(name: str) -> str:
    """A case option's meaning, range (option_range) and default, for --help."""
    from sim.scenario.cases import PLACEMENT_FIELDS

    meta, default = PLACEMENT_FIELDS[name].metadata, PLACEMENT_FIELDS[name].default
    low, high, open_low = option_range(name)

    def shown(v: float) -> str:
        return str(v) if isinstance(v, int) else f"{v:g}"

    unit = f" {meta['unit']}" if meta["unit"] else ""
    note = f" ({OPTION_NOTES[name]})" if name in OPTION_NOTES else ""
    span = f"{'(' if open_low else '['}{shown(low)}, {shown(high)}]{unit}"
    return f"{meta['doc']}: {span}{note}; default {shown(default)}"


def add_case_options(p: argparse.ArgumentParser) -> None:
    """The case values (see SCENARIO_HELP); None when not given, so a file keeps its own."""
    from sim.scenario.cases import PLACEMENT_FIELDS

    g = p.add_argument_group(
        "scenario values (default: the case placement's, or a scenario file's own)",
        "A case is checked as a small-scale scenario file with these values: each in the "
        "range below, and together the robot on its road for the whole run and the "
        "pedestrian on the street. For a scenario file the file's own checks apply (its "
        "robot's max_speed, its road).",
    )
    for name in CASE_OPTIONS:
        f = PLACEMENT_FIELDS[name]
        g.add_argument(
            f"--{name.replace('_', '-')}",
            type=int if f.type in (int, "int") else float,
            help=option_help(name),
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


def given_values(args: argparse.Namespace) -> list[Given]:
    """The case options given on the command line, as values of a scenario file's keys."""
    from sim.scenario.files import Given

    return [
        Given(f"--{name.replace('_', '-')}", key, getattr(args, name))
        for name, key in CASE_OPTIONS.items()
        if getattr(args, name, None) is not None
    ]


def resolve_scenario(text: str, args: argparse.Namespace) -> Scenario:
    """The Scenario named on the command line (see SCENARIO_HELP), with the values given."""
    from sim.scenario.cases import default_crossing
    from sim.scenario.files import load, placed_case

    given = given_values(args)
    if text.endswith(".toml") or Path(text).is_file():
        return load(Path(text)).with_given(given)
    if text.strip().lower() == "crossing":
        if given:
            raise UserError(
                f"{given[0].text}: 'crossing' is a fixed scenario; to set its values, place "
                "case 5 (e.g. record 5 --distance 6 --duration 5)"
            )
        return default_crossing()
    case = parse_case(text)
    if case is None:
        raise UserError(
            f"scenario {text!r}: not a case number 1-9, a case name (e.g. perpendicular-right), "
            "'crossing' or an existing .toml file"
        )
    return placed_case(case, given)


def run(args: argparse.Namespace) -> int:
    from sim.runs.record import record_run

    scenario = resolve_scenario(args.scenario, args)
    path = output_file(args.out or DEFAULT_FOLDER / f"{scenario.name}.rrd", "--out")
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
