"""`monopic dataset SPEC --out DIR`: render simulated runs into a keypoint/segmentation dataset."""

from __future__ import annotations

import argparse
from pathlib import Path

from tqdm import tqdm

from monopic.cli.args import output_folder
from sim.commands.executor_options import (
    add_executor_options,
    check_executor_options,
    logs_above_the_bar,
    make_executor,
    workers_of,
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "dataset",
        help="render simulated runs into a dataset (images, COCO keypoints, masks, truth)",
        description="Render every run of a dataset spec into DIR. The spec is a sweep spec "
        "([[include]] of scenario files, as `monopic sweep` reads it: the same runs, ids and "
        "seeds; a grid over the nine cases sweeps path.case of "
        "scenarios/datasets/case_grid.toml); see scenarios/datasets/README.md. DIR gets JPEG "
        "images, COCO keypoint files for BlazePose's 33 landmarks and COCO's 17 (one "
        "annotation per visible person per image: boxes, visibility, RLE masks), PNG masks "
        "from MuJoCo's segmentation rendering, per-frame ground truth with case labels, "
        "each run as a MOTChallenge sequence (mot/<run>: gt/gt.txt, seqinfo.ini), the "
        "pipeline's features in the authors' CSV columns, and a README card. Prints a size "
        "and time estimate first. Deterministic for the spec; run it again on the same DIR "
        "to resume.",
    )
    p.add_argument(
        "spec",
        type=Path,
        metavar="SPEC.toml",
        help="a sweep spec: scenarios/datasets/*.toml, scenarios/sweeps/*.toml",
    )
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="DIR",
        help="the dataset folder (made as needed; an unfinished one of the same spec resumes)",
    )
    add_executor_options(p, "DIR must be a folder every node sees at the same path")
    p.add_argument(
        "--estimate-only", action="store_true", help="print the size and time estimate and stop"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sim.dataset.build import (
        build,
        check_folder,
        estimate,
        estimate_duration,
        finished_runs,
        work,
    )
    from sim.dataset.spec import expand, load_spec

    check_executor_options(args)
    spec = load_spec(args.spec)
    out: Path = args.out
    # None: a Ray cluster's CPUs, unknown here (the estimate then gives CPU time).
    workers = workers_of(args)
    check_folder(spec, out)  # the estimate refuses what the build would
    if args.estimate_only:
        runs = expand(spec)
        done = finished_runs(out, runs) if out.is_dir() else {}
        todo = [r for r in runs if r.id not in done]
        print(f"size: {estimate(runs, list(done.values())).text()}")
        print(f"time: {estimate_duration(todo, list(done.values()), workers).text()}")
        return 0
    output_folder(out.parent, "--out")
    executor = make_executor(args, run=work)
    with logs_above_the_bar(args.executor, args.address):
        outcome = build(spec, out, executor, workers, report=tqdm.write)
    if outcome.counts is None:
        print(
            f"{len(outcome.failed)} of {outcome.runs} runs failed, {outcome.finished} rendered "
            f"now, {outcome.skipped} were already there; {out} keeps the finished runs but no "
            "annotations yet: run the same command to render the failed ones"
        )
        for run_id, error in outcome.failed[:3]:
            print(f"failed {run_id}:\n{error}")
        return 1
    counts = outcome.counts
    print(
        f"{counts['runs']} runs, {counts['images']} images, {counts['annotations']} person "
        f"annotations, {counts['feature_rows']} feature rows, {counts['bytes'] / 1e6:.1f} MB "
        f"in {out} (see {out / 'README.md'})"
    )
    return 0
