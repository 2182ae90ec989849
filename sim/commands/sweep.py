"""`monopic sweep SPEC`: run a scenario sweep through the pipeline, one JSON line per run."""

from __future__ import annotations

import argparse
from pathlib import Path

from monopic.cli.args import output_file, positive_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sweep",
        help="run a scenario sweep (scenarios/sweeps/*.toml) and append results as JSON lines",
    )
    p.add_argument("spec", type=Path, help="sweep spec, e.g. scenarios/sweeps/demo.toml")
    p.add_argument(
        "--out", type=Path, help="results file to append to (default: recordings/<name>.jsonl)"
    )
    p.add_argument(
        "--workers", type=positive_int, help="local worker processes (default: all cores)"
    )
    p.add_argument("--executor", choices=("local", "ray"), default="local")
    p.add_argument("--address", help="Ray cluster address for --executor ray (e.g. host:6379)")
    p.add_argument(
        "--ablation",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="also run the ground-truth-crop ablation (default: as the spec says)",
    )
    p.add_argument(
        "--record",
        choices=("failed", "all", "none"),
        default="failed",
        help="which runs keep a rerun recording: missed collisions and false alarms "
        "(default), every run, or none",
    )
    p.add_argument(
        "--recordings", type=Path, help="folder for the .rrd files (default: <out>_rrd/ beside it)"
    )
    p.add_argument("--limit", type=positive_int, help="run at most this many new runs, then stop")
    p.add_argument(
        "--restart",
        action="store_true",
        help="if OUT holds runs made by other code, rename it (and its recordings) to "
        "<name>.<code>.jsonl and start over; without it such a file is an error",
    )
    p.add_argument("--dry-run", action="store_true", help="expand and check the spec, run nothing")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from monopic.errors import UserError
    from sim.runs.code_version import code_version
    from sim.runs.executors import local_executor, ray_executor
    from sim.runs.results_file import scan
    from sim.runs.sweep import expand_spec, load_spec, recordings_folder, run_sweep

    if args.address and args.executor != "ray":
        raise UserError("--address is for --executor ray")
    if args.workers and args.executor == "ray":
        raise UserError("--workers is for --executor local (Ray schedules by the cluster's CPUs)")
    spec = load_spec(args.spec)
    out = args.out or Path("recordings") / f"{spec.name}.jsonl"
    if args.dry_run:
        runs = expand_spec(spec)
        state = scan(out) if out.exists() else None
        done = state.ids if state else frozenset()
        families = sorted({r.family for r in runs})
        print(f"{spec.path}: {len(runs)} runs in {len(families)} families, "
              f"{sum(r.id in done for r in runs)} already in {out}")  # fmt: skip
        other = state.other_code(code_version()) if state else None
        if other:
            print(f"{out}: {sum(other.values())} of its runs were made by other code "
                  "(a sweep would stop; --restart sets them aside)")  # fmt: skip
        return 0
    output_file(out, "--out")
    if args.executor == "ray":
        executor = ray_executor(args.address)
    else:
        executor = local_executor(args.workers)
    outcome = run_sweep(
        spec,
        out,
        executor,
        ablation=args.ablation,
        limit=args.limit,
        record=args.record,
        record_dir=args.recordings,
        restart=args.restart,
    )
    rate = outcome.finished / outcome.seconds if outcome.seconds > 0 else 0.0
    print(
        f"{outcome.finished} runs finished in {outcome.seconds:.0f} s "
        f"({rate * 60:.1f} runs/min), {outcome.skipped} were already there, "
        f"{len(outcome.failed)} failed; {outcome.total} in the sweep"
    )
    print(f"results: {out}  (report: monopic report {out})")
    if args.record != "none":
        print(f"recordings ({args.record} runs): {recordings_folder(out, args.recordings)}")
    for run_id, error in outcome.failed[:3]:
        print(f"failed {run_id}:\n{error}")
    return 1 if outcome.failed else 0
