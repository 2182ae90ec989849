"""`monopic report RESULTS`: Markdown report with plots from a sweep's results, headline printed."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "report",
        help="write the Markdown report of a sweep's results file",
        description="Read a sweep's results file and write report.md with its plots into a "
        "folder: collision-warning recall and lead time per predictor and family, precision "
        "and false alarms, near misses warned, case accuracy, position error, found share and "
        "phi, each saying what it ran on (runs, seeds, frame size, machine, code). Prints the "
        "headline table.",
    )
    p.add_argument("results", type=Path, help="results file written by monopic sweep (.jsonl)")
    p.add_argument(
        "--out",
        type=Path,
        help="report folder, made as needed (default: beside RESULTS, <name>_report/)",
    )
    p.add_argument(
        "--beside",
        type=Path,
        metavar="OTHER.jsonl",
        help="another sweep's results file (the same families, e.g. human beside rail "
        "walkers): the report adds its figures beside this one's, per method and family "
        "(default: none)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from monopic.cli.args import output_folder
    from monopic.errors import UserError
    from sim.analysis.metrics import compute
    from sim.analysis.report import ran_on, sweeps_line, write_report
    from sim.analysis.triage import triage_summary
    from sim.runs.results_file import read_results

    results: Path = args.results
    check_results_file(results)
    rows = list(read_results(results))
    if not rows:
        raise UserError(f"{results}: no finished runs in it yet")
    out = output_folder(args.out or results.with_name(f"{results.stem}_report"), "--out")
    metrics = compute(rows)
    beside = None
    if args.beside is not None:
        check_results_file(args.beside, "--beside")
        other = list(read_results(args.beside))
        if not other:
            raise UserError(f"--beside {args.beside}: no finished runs in it yet")
        beside = (args.beside.stem, compute(other))
    report = write_report(metrics, rows, results, out, beside)
    print(report.headline)
    print(f"\n{ran_on(metrics)}")
    print(sweeps_line(rows).replace("`", ""))
    triage = triage_summary(metrics)
    if triage:
        print(triage)
    print(f"report: {report.markdown} ({len(report.plots)} plots)")
    return 0


def check_results_file(path: Path, option: str | None = None) -> None:
    """UserError unless the file exists (named with `option` when it came from one) and
    its first line (blank ones skipped) is a sweep's result line (JSON with an id).

    A CSV or any other file given by mistake is named as such here, rather than by the
    results reader's advice for a bad line in a sweep's own file."""
    import json

    from monopic.errors import UserError

    if not path.is_file():
        named = f"{option} {path}" if option else str(path)
        raise UserError(f"{named}: no such results file")
    with path.open("rb") as fh:  # a results file has no blank line: any other file may
        first = next((line for line in fh if line.strip()), b"")
    if not first:
        return  # empty: the caller says there are no runs yet
    try:
        row = json.loads(first)
        ok = isinstance(row, dict) and isinstance(row.get("id"), str)
    except ValueError:
        ok = False
    if not ok:
        shown = first[:40].decode("utf-8", "replace").strip()
        raise UserError(
            f"{path}: not a sweep's results file (its first line, {shown!r}, is not a JSON "
            "result line): give the .jsonl that `monopic sweep` writes"
        )
