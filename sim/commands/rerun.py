"""`monopic rerun RESULTS RUN_ID`: one run of a results file run again with a recording,
checked to give what its line holds."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rerun",
        help="run one run of a sweep, closed loop or Euro NCAP grid again from its results "
        "line, into a rerun recording",
        description="Rebuild one run of a results file from its line and run it again "
        "through the same run loop with a rerun recording. A sweep's line: from the scenario "
        "file, the swept values and the seed; it prints 'same frames and decisions as in "
        "the sweep' or the first difference (exit status 1). A closed loop's (`monopic "
        "closed-loop`) or a Euro NCAP grid's (`monopic ncap`, DIR/results.jsonl): from the "
        "scenario file and the values given (or the placed case), or from the protocol and "
        "car files, with the latency the run applied (a run made with the measured latency "
        "gets the latency it measured on each frame again); it prints 'same outcome as in "
        "the run' or the first difference (exit status 1). The sweep's report, the closed "
        "loop's tables and the Euro NCAP report list the runs that went wrong with this "
        "command for each. Run it from the folder the command ran in: a line names its "
        "files as the command found them.",
    )
    p.add_argument(
        "results",
        type=Path,
        help="results file written by monopic sweep, closed-loop or ncap (.jsonl)",
    )
    p.add_argument(
        "run_id",
        metavar="RUN_ID",
        help="the run's id, e.g. case5/0000-1a2b3c4d or rules/ground/case5@2-1a2b3c4d",
    )
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
        help="run it even if the results were made by other code than this, or its files "
        "no longer give the run (what it gives may then differ: that is the change, shown "
        "as the first difference) (default: refused)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from monopic.cli.args import output_file
    from monopic.errors import UserError
    from sim.commands.report import check_results_file
    from sim.runs.code_version import code_version
    from sim.runs.rebuild import Asked, code_of, find_line, first_difference, kind_of

    results: Path = args.results
    check_results_file(results)
    line = find_line(results, args.run_id)
    kind = kind_of(line)
    if kind is None:
        raise UserError(
            f"{results}: run {args.run_id} is not a run of a sweep, a closed loop or a Euro "
            "NCAP grid; `monopic rerun` runs again the lines `monopic sweep`, `closed-loop` "
            "and `ncap` write"
        )
    made_by, this = code_of(line), code_version()
    if made_by != this and not args.anyway:
        raise UserError(
            f"{results}: run {args.run_id} was made by other code "
            f"({made_by or 'unknown: written before lines carried it'}; this code is {this}), "
            f"so running it again need not give its {kind.same}: check out the code "
            "that made it, or add --anyway to run it with this code and see the first difference"
        )
    if args.intent_tree is not None and kind.name != "sweep":
        raise UserError(
            f"--intent-tree {args.intent_tree}: run {args.run_id} is a {kind.name} run, which "
            "runs no intent tree; leave it out"
        )
    out = args.out or results.with_name(f"{results.stem}_rerun") / f"{args.run_id}.rrd"
    asked = Asked(results, out, args.intent_tree, args.anyway)
    spec = kind.rebuild(line, asked)
    output_file(out, "--out")
    rerun = kind.rerun(line, spec, asked)
    print(f"run {args.run_id} {rerun.said}")
    if rerun.failed is not None:
        print(rerun.failed, file=sys.stderr)
        last = rerun.failed.strip().splitlines()[-1]
        print(f"not the same as in {kind.made_in}: it failed when run again ({last})")
        return 1
    print(f"recording: {rerun.recording}; open it with: monopic view {rerun.recording}")
    difference = first_difference(rerun.stored, rerun.again, kind.made_in)
    if difference is None:
        print(f"same {kind.same} as in {kind.made_in}")
        return 0
    print(f"not the same as in {kind.made_in}: first difference at {difference}")
    return 1
