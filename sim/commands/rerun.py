"""`monopic rerun RESULTS RUN_ID`: one run of a results file run again with a recording,
checked to give the frames and decisions its line holds."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rerun",
        help="run one run of a sweep again from its results line, into a rerun recording",
        description="Rebuild one run of a sweep's results file from its line (the scenario "
        "file, the swept values and the seed the line records), run it again through the "
        "same run loop with a rerun recording, and check the frames and decisions against "
        "the line: it prints 'same frames and decisions as in the sweep' or the first "
        "difference (exit status 1). `monopic report` lists the runs that went wrong with "
        "this command for each. Run it from the folder the sweep ran in: a line names its "
        "scenario file as the sweep found it.",
    )
    p.add_argument("results", type=Path, help="results file written by monopic sweep (.jsonl)")
    p.add_argument("run_id", metavar="RUN_ID", help="the run's id, e.g. case5/0000-1a2b3c4d")
    p.add_argument(
        "--out",
        type=Path,
        help="the recording (default: beside RESULTS, <name>_rerun/<RUN_ID>.rrd)",
    )
    p.add_argument(
        "--intent-tree",
        type=Path,
        metavar="FILE",
        help="the intent tree the sweep ran (its spec's intent_tree), for a run whose code "
        "names one (default: the tree shipped with the code that has the run's digest)",
    )
    p.add_argument(
        "--anyway",
        action="store_true",
        help="run it even if the results were made by other code than this (the frames and "
        "decisions may then differ: that is the change in the code, shown as the first "
        "difference) (default: refused)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from monopic.cli.args import output_file
    from monopic.errors import UserError
    from sim.analysis.triage import describe
    from sim.commands.report import check_results_file
    from sim.runs.code_version import code_version
    from sim.runs.rebuild import Asked, code_of, find_line, first_difference, kind_of

    results: Path = args.results
    if not results.is_file():
        raise UserError(f"{results}: no such results file")
    check_results_file(results)
    line = find_line(results, args.run_id)
    kind = kind_of(line)
    if kind is None:
        what = "a Euro NCAP grid's" if "policy" in line and "outcome" in line else "not a sweep's"
        raise UserError(
            f"{results}: run {args.run_id} is {what} run; `monopic rerun` runs a sweep's runs "
            "again (the lines `monopic sweep` writes)"
        )
    made_by, this = code_of(line), code_version()
    if made_by != this and not args.anyway:
        raise UserError(
            f"{results}: run {args.run_id} was made by other code "
            f"({made_by or 'unknown: written before lines carried it'}; this code is {this}), "
            "so running it again need not give its frames and decisions: check out the code "
            "that made it, or add --anyway to run it with this code and see the first difference"
        )
    out = args.out or results.with_name(f"{results.stem}_rerun") / f"{args.run_id}.rrd"
    asked = Asked(results, out, args.intent_tree, args.anyway)
    spec = kind.rebuild(line, asked)
    output_file(out, "--out")
    rerun = kind.rerun(line, spec, asked)
    params = line.get("params") if isinstance(line.get("params"), dict) else {}
    print(f"run {args.run_id} ({line.get('family', '?')}, {describe(params)}): "
          f"{rerun.again.get('frames')} frames, contact "
          f"{_contact(rerun.again.get('contact_time'))}")  # fmt: skip
    print(f"recording: {rerun.recording}; open it with: monopic view {rerun.recording}")
    difference = first_difference(rerun.stored, rerun.again)
    if difference is None:
        print("same frames and decisions as in the sweep")
        return 0
    print(f"not the same as in the sweep: first difference at {difference}")
    return 1


def _contact(time: object) -> str:
    return f"at {time:.2f} s" if isinstance(time, int | float) else "none"
