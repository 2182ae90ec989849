"""`monopic sweep SPEC`: run a scenario sweep through the pipeline, one JSON line per run."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from monopic.cli.args import positive_int
from monopic.output import is_temporary
from sim.commands.executor_options import (
    add_executor_options,
    check_executor_options,
    logs_above_the_bar,
    make_executor,
    workers_of,
)

if TYPE_CHECKING:  # the simulator is imported when the command runs
    from sim.runs.run_spec import RunSpec
    from sim.runs.sweep import SweepSpec


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sweep",
        help="run a scenario sweep (scenarios/sweeps/*.toml) and append results as JSON lines",
        description="Expand a sweep spec into runs (scenario files and how to sample them, "
        "scenarios/README.md), render each through every predictor in image and ground mode "
        "(plus the ground-truth-crop ablation) on local workers or a Ray cluster, and append "
        "one JSON line per finished run to the results file. Running it again with the same "
        "--out resumes: runs already there (made by the same code) are skipped. --dry-run "
        "shows the runs per family and the estimated time first.",
    )
    p.add_argument("spec", type=Path, help="sweep spec, e.g. scenarios/sweeps/demo.toml")
    p.add_argument(
        "--out", type=Path, help="results file to append to (default: recordings/<name>.jsonl)"
    )
    add_executor_options(p)
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
    p.add_argument(
        "--limit", type=positive_int, help="run at most this many new runs (>= 1), then stop"
    )
    p.add_argument(
        "--restart",
        action="store_true",
        help="if OUT holds runs made by other code, rename it (and its recordings) to "
        "<name>.<code>.jsonl and start over; without it such a file is an error",
    )
    p.add_argument(
        "--dry-run",
        action="store_true",
        help="check the spec; print its runs per family and the estimated time; run nothing",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sim.runs.sweep import load_spec, recordings_folder, run_sweep

    check_executor_options(args)
    spec = load_spec(args.spec)
    out = args.out or Path("recordings") / f"{spec.name}.jsonl"
    if args.dry_run:
        dry_run(spec, out, args)
        return 0
    executor = make_executor(args)
    with logs_above_the_bar(args.executor, args.address):
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
        print(kept_recordings(recordings_folder(out, args.recordings), args.record))
    for run_id, error in outcome.failed[:3]:
        print(f"failed {run_id}:\n{error}")
    return 1 if outcome.failed else 0


def kept_recordings(folder: Path, record: str) -> str:
    """What the recordings folder holds, once the folders of dropped recordings are gone.

    Each run makes its family's folder before it knows whether its recording is kept;
    the empty ones are removed here, after the workers have finished. A recording still
    being written (a temporary of another sweep sharing the folder) is not one kept."""
    if folder.is_dir():
        for sub in sorted(folder.rglob("*"), key=lambda p: len(p.parts), reverse=True):
            if sub.is_dir() and not any(sub.iterdir()):
                sub.rmdir()
        if not any(folder.iterdir()):
            folder.rmdir()
    kept = [p for p in folder.rglob("*.rrd") if not is_temporary(p)] if folder.is_dir() else []
    which = "missed collisions and false alarms" if record == "failed" else "every run"
    if not kept:
        return f"recordings ({which}): none kept"
    return f"recordings ({which}): {len(kept)} in {folder}"


def _bench_of_line(row: dict) -> float:
    """The benchmark's seconds per frame for a finished run's line: its camera, ablation,
    people and tracker (what the estimate scales by the line's measured time)."""
    from dataclasses import replace

    from sim.runs.estimate import bench_frame_seconds
    from sim.runs.result import ABLATION
    from sim.runs.run_spec import EVERYONE, ONE
    from sim.scenario.spec import CameraSpec

    summary = row.get("scenario") if isinstance(row.get("scenario"), dict) else {}
    camera = summary.get("camera") if isinstance(summary.get("camera"), dict) else {}
    size = CameraSpec()
    size = replace(size, width=int(camera.get("width", size.width)),
                   height=int(camera.get("height", size.height)))  # fmt: skip
    pipelines = row.get("pipelines") if isinstance(row.get("pipelines"), dict) else {}
    people = row.get("people") if isinstance(row.get("people"), list) else []
    tracker = EVERYONE if row.get("tracker") == EVERYONE else ONE
    return bench_frame_seconds(size, ABLATION in pipelines, max(len(people), 1), tracker)


def dry_run(spec: SweepSpec, out: Path, args: argparse.Namespace) -> None:
    """Runs per family, what the results file already holds and the estimated time.

    It makes the run's checks (the spec's runs, then sim.runs.sweep.check_output): what
    the run would refuse, it refuses with the same line."""
    from sim.runs.estimate import SWEEP_START_S, bench_frame_seconds, estimate_time
    from sim.runs.results_file import read_rows
    from sim.runs.sweep import check_output, expand_spec

    runs = expand_spec(spec)
    check = check_output(spec, out, args.record, args.recordings, args.restart)
    for source, target in check.moves:
        print(f"would set aside (--restart): {source} -> {target}")
    state = check.state
    done = check.done
    todo = [r for r in runs if r.id not in done]
    already = len(runs) - len(todo)
    limit = f" (--limit {args.limit})" if args.limit is not None else ""
    if args.limit is not None:
        todo = todo[: args.limit]
    todo_ids = {r.id for r in todo}
    families: dict[str, list[RunSpec]] = {}
    for r in runs:
        families.setdefault(r.family, []).append(r)
    print(f"{spec.path}: {len(runs)} runs in {len(families)} families, {already} already in "
          f"{out}, {len(todo)} to run{limit}")  # fmt: skip
    if spec.intent_tree is not None:
        print(f"  also predictor intent-tree/ground with {spec.intent_tree}")
    if spec.camera is not None:
        print(f"  every run with the {spec.camera} camera (the spec's `camera`)")
    width = max(len("family"), *(len(f) for f in families))
    scales = {f: "/".join(sorted({r.scale for r in m})) for f, m in families.items()}
    scale_width = max(len("scale"), *(len(v) for v in scales.values()))
    print(f"  {'family':<{width}}  {'kind':<9}  {'scale':<{scale_width}}  runs  to run  "
          "frames (at most)")  # fmt: skip
    for family, members in sorted(families.items()):
        first = members[0]
        left = [r for r in members if r.id in todo_ids]
        frames = sum(r.scenario.frames for r in left)
        print(f"  {family:<{width}}  {first.kind:<9}  {scales[family]:<{scale_width}}  "
              f"{len(members):>4}  {len(left):>6}  {frames:>6}")  # fmt: skip
    measured = []
    if state is not None:
        for row in read_rows(out):
            timing = row.get("timing") if isinstance(row.get("timing"), dict) else {}
            wall, frames = timing.get("wall_s"), row.get("frames")
            if isinstance(wall, int | float) and isinstance(frames, int):
                measured.append((frames, float(wall), _bench_of_line(row)))

    def ablation(r: RunSpec) -> bool:
        return r.ablation if args.ablation is None else args.ablation

    def bench(r: RunSpec) -> float:
        people = len(r.scenario.people)
        return bench_frame_seconds(r.scenario.robot.camera, ablation(r), people, r.tracker)

    workers = workers_of(args)
    time = estimate_time(
        [(r.scenario.frames, bench(r)) for r in todo],
        measured,
        workers,
        f"in {out}",
        SWEEP_START_S,
    )  # fmt: skip
    print(f"time: {time.text()}")
