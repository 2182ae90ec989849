"""`monopic tree train|show`: fit the ID3 tree on authors' logs, inspect a tree file."""

from __future__ import annotations

import argparse
from pathlib import Path

from monopic.cli.args import (
    non_negative_float,
    output_file,
    output_folder,
    parameter_limit,
    positive_float,
    positive_int,
    ranged,
)
from monopic.errors import UserError
from monopic.output import write_text_atomically
from monopic.predict.base import Mode
from monopic.replay.dataset import prepare
from monopic.replay.judge import (
    VELOCITY_WINDOW_S,
    candidate_grid,
    format_table,
    judge_leave_one_out,
)
from monopic.replay.logs import read_log
from monopic.replay.training import (
    DEFAULT_MIN_SAMPLES,
    DISCRETISERS,
    LEAF_VALUES,
    TrainOptions,
    train_on_logs,
)
from monopic.tree.discretise import AUTHORS_DEAD_ZONE
from monopic.tree.intent import INTENT_ATTRIBUTES, IntentTreeModel
from monopic.tree.intent_training import read_dataset, split_runs, train_intent_tree
from monopic.tree.report import intent_summary, intent_tree_dot, summary, tree_dot
from monopic.tree.serialise import (
    load_any_model,
    load_default_model,
    load_intent_model,
    save_model,
)

JUDGE_DESCRIPTION = """\
Judge the image-mode tree at the real 1 s horizon, leave one file out: for each log, a
tree is trained on the other logs (the paper's ID3 on the next-second case, leaves
carrying velocity gains that correct constant velocity) with its depth, dead zone and
shrinkage chosen by leave-one-out inside those training logs, never on the judged one;
then it is judged on the held-out log beside constant velocity (same velocity window)
and the shipped tree. Prints a Markdown table: median and 90th-percentile error per
method, the share of rows where the tree differs from constant velocity and the errors
there, and case accuracy against the next second's case. Needs at least 3 logs.
"""


def add_training_options(p: argparse.ArgumentParser) -> None:
    """Options shared by `tree train` and `replay` (which trains leave-one-file-out)."""
    p.add_argument(
        "--discretiser",
        choices=DISCRETISERS,
        default="authors",
        help="authors: their notebook's bins (default); entropy: Fayyad-Irani MDL cut points",
    )
    p.add_argument(
        "--dead-zone",
        type=non_negative_float,
        default=AUTHORS_DEAD_ZONE,
        help="dead zone of the authors' bins, degrees and px/s (>= 0; default %(default)g)",
    )
    p.add_argument(
        "--max-depth",
        type=positive_int,
        default=None,
        help="deepest split level (>= 1; default: none)",
    )
    p.add_argument(
        "--min-samples",
        type=positive_int,
        default=DEFAULT_MIN_SAMPLES,
        help="a node with fewer training rows is not split (>= 1; default %(default)d)",
    )


def add_leaf_options(p: argparse.ArgumentParser) -> None:
    """`tree train` only: what the leaves carry and which velocity the rows use."""
    p.add_argument(
        "--leaf-value",
        choices=LEAF_VALUES,
        default=LEAF_VALUES[0],
        help="displacement: the leaf's mean displacement (default, the shipped tree); "
        "velocity-gain: gains on the measured velocity, shrunk toward constant velocity",
    )
    p.add_argument(
        "--shrink",
        type=non_negative_float,
        default=10.0,
        help="velocity-gain leaves: gains pulled toward 1 by n / (n + SHRINK) (>= 0; "
        "default %(default)g rows)",
    )
    p.add_argument(
        "--velocity-window",
        type=positive_float,
        default=None,
        metavar="S",
        help="velocity as the least-squares slope over the last S seconds (> 0; default: the "
        "pipeline's 4-frame estimator, as the shipped tree)",
    )


def training_options(args: argparse.Namespace) -> TrainOptions:
    leaf_value = getattr(args, "leaf_value", LEAF_VALUES[0])
    return TrainOptions(
        discretiser=args.discretiser,
        dead_zone=args.dead_zone,
        min_samples=args.min_samples,
        max_depth=args.max_depth,
        leaf_value=leaf_value,
        shrink=args.shrink if leaf_value != LEAF_VALUES[0] else 0.0,
    )


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "tree",
        help="train or inspect the ID3 decision tree",
        description="The ID3 decision tree over the discretised (phi, vx, vy), and the "
        "ground intent tree: `tree train` fits one (on logs in the authors' CSV format, or "
        "on datasets with --mode ground), `tree show` prints a tree file, `tree judge` "
        "judges the tree and the rules on logs at the real horizon, `tree sensitivity` "
        "replays ground intent trees on datasets' recorded features per cue value.",
    )
    sub = p.add_subparsers(dest="tree_command", required=True, metavar="ACTION")

    t = sub.add_parser(
        "train",
        help="fit a tree on logs in the authors' CSV format, or a ground tree on datasets",
        description="Image mode (default): fit an ID3 tree on the scored rows of the logs "
        "(rows after the 0.5 s warm-up with a full next second), labelled with the case of "
        "the next second of motion; print the gain table and the tree; write versioned "
        "JSON. Ground mode (--mode ground): DATA are dataset folders (`monopic dataset`); "
        "fit the intent tree (labels case/intent, leaves correcting constant velocity) on "
        "the pipeline's features joined to the truth, its bins, depth and intent rules "
        "chosen on a validation split by (family, seed) that it prints; the predictor "
        "`intent-tree` reads the file (docs/intent/ground-tree.md).",
    )
    t.add_argument(
        "data",
        nargs="+",
        type=Path,
        metavar="DATA",
        help="image mode: logs in the authors' CSV format; ground mode: dataset folders",
    )
    t.add_argument(
        "--mode",
        choices=[m.value for m in Mode],
        default=Mode.IMAGE.value,
        help="image: the paper's tree on authors' logs (default); ground: the intent tree "
        "on datasets",
    )
    t.add_argument(
        "--validation-share",
        type=ranged(0.0, 1.0, open_low=True, open_high=True),
        default=0.25,
        metavar="F",
        help="ground mode: share of (family, seed) groups validated on, by a fixed hash "
        "((0, 1); default %(default)g)",
    )
    t.add_argument(
        "--validate-family",
        action="append",
        default=[],
        metavar="FAMILY",
        help="ground mode: validate on this family (repeatable; instead of the hash share)",
    )
    t.add_argument(
        "--validate-above",
        action="append",
        default=[],
        type=parameter_limit,
        metavar="PARAM=VALUE",
        help="ground mode: validate on the runs with this swept parameter at or above VALUE "
        "(repeatable: any of them), e.g. pedestrian.speed=1.35, so that the rules are "
        "chosen on walkers beyond those trained on, as the judged draws are",
    )
    t.add_argument(
        "--exclude-family",
        action="append",
        default=[],
        metavar="FAMILY",
        help="ground mode: leave this family out entirely, e.g. a judged one (repeatable)",
    )
    t.add_argument(
        "--without",
        action="append",
        default=[],
        choices=INTENT_ATTRIBUTES,
        metavar="ATTR",
        help="ground mode: grow the tree without this feature (repeatable; e.g. the body "
        f"features phi, phi_rate, head_yaw, head_toward for a motion-only tree; one of "
        f"{', '.join(INTENT_ATTRIBUTES)})",
    )
    t.add_argument(
        "--out", required=True, type=Path, metavar="TREE.json", help="the tree file to write"
    )
    add_training_options(t)
    add_leaf_options(t)
    t.set_defaults(func=_train)

    j = sub.add_parser(
        "judge",
        help="leave-one-file-out judge of a retrained tree at the 1 s horizon",
        description=JUDGE_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    j.add_argument(
        "data", nargs="+", type=Path, metavar="DATA.csv", help="logs in the authors' CSV format"
    )
    j.add_argument(
        "--velocity-window",
        type=positive_float,
        default=VELOCITY_WINDOW_S,
        metavar="S",
        help="constant velocity's and the tree's velocity: least-squares slope over the "
        "last S seconds (> 0; default %(default)g)",
    )
    j.add_argument("--out", type=Path, metavar="TABLE.md", help="also write the table here")
    j.set_defaults(func=_judge)

    v = sub.add_parser(
        "sensitivity",
        help="replay ground trees beside constant velocity per cue setting of a dataset",
        description="Replay constant velocity and each ground intent tree given on the "
        "recorded features of dataset folders (no rendering): per value of each cue "
        "parameter the runs vary, collision runs warned 1 s ahead, near-miss runs warned "
        "and the median point error; and the runs without body cues beside the others. "
        "Writes DIR/report.md and DIR/sensitivity.png (docs/intent/ground-tree.md).",
    )
    v.add_argument("data", nargs="+", type=Path, metavar="DATA", help="dataset folders")
    v.add_argument(
        "--tree",
        action="append",
        required=True,
        metavar="NAME=TREE.json",
        help="a ground tree to replay, under NAME (repeatable)",
    )
    v.add_argument(
        "--by",
        action="append",
        metavar="KEY",
        help="a run parameter to group by (repeatable; default the four cue keys: "
        "pedestrian.behaviour.head_check_probability, head_check_lead, stop_lead, turn_lead)",
    )
    v.add_argument("--out", required=True, type=Path, metavar="DIR", help="the report folder")
    v.set_defaults(func=_sensitivity)

    s = sub.add_parser(
        "show",
        help="print a tree file (text, gains, operation counts)",
        description="Print a tree file: its nodes as text, the root's information gains, "
        "its provenance and the operations a prediction costs (or Graphviz DOT with --dot).",
    )
    s.add_argument("tree", type=Path, metavar="TREE.json", help="a file `tree train` wrote")
    s.add_argument("--dot", action="store_true", help="print Graphviz DOT instead")
    s.set_defaults(func=_show)


def _train(args: argparse.Namespace) -> int:
    if args.mode == Mode.GROUND.value:
        return _train_ground(args)
    if args.without:
        raise UserError(
            f"--without {args.without[0]}: ground mode only (the image tree reads phi, vx, vy)"
        )
    logs = [prepare(read_log(path), velocity_window=args.velocity_window) for path in args.data]
    try:
        model = train_on_logs(logs, training_options(args))
    except ValueError as err:
        raise UserError(str(err)) from err
    out = output_file(args.out, "--out")
    save_model(model, out)
    print(summary(model))
    print(f"\nwrote {out}")
    return 0


IMAGE_ONLY = (
    ("discretiser", "--discretiser", "authors"),
    ("dead_zone", "--dead-zone", AUTHORS_DEAD_ZONE),
    ("leaf_value", "--leaf-value", LEAF_VALUES[0]),
    ("velocity_window", "--velocity-window", None),
    ("max_depth", "--max-depth", None),
)


def _train_ground(args: argparse.Namespace) -> int:
    """The intent tree on dataset folders (options chosen on validation, not given)."""
    for attr, option, default in IMAGE_ONLY:
        if getattr(args, attr) != default:
            raise UserError(
                f"{option}: image mode only (ground mode chooses its bins and depth on "
                "the validation split)"
            )
    runs = []
    sources = []
    for folder in args.data:
        if not folder.is_dir():
            raise UserError(
                f"{folder}: not a dataset folder (ground mode reads `monopic dataset` output)"
            )
        got = read_dataset(folder)
        runs.extend(got)
        sources.append({"folder": str(folder), "runs": len(got)})
    ids = [r.run for r in runs]
    dup = next((i for n, i in enumerate(ids) if i in ids[:n]), None)
    if dup is not None:
        raise UserError(
            f"run {dup!r} is in two datasets given (it could be trained on and validated)"
        )
    split = split_runs(
        runs,
        args.validation_share,
        args.validate_family,
        args.exclude_family,
        dict(args.validate_above),
    )
    attributes = [a for a in INTENT_ATTRIBUTES if a not in args.without]
    if not attributes:
        raise UserError("--without: every feature left out; the tree needs at least one")
    result = train_intent_tree(
        runs, split, min_samples=args.min_samples, sources=sources, attributes=attributes
    )
    out = output_file(args.out, "--out")
    save_model(result.model, out)
    print(result.report)
    print()
    print(intent_summary(result.model))
    print(f"\nwrote {out}")
    return 0


def _judge(args: argparse.Namespace) -> int:
    if len(args.data) < 3:
        raise UserError(
            f"tree judge: {len(args.data)} log(s) given; at least 3 are needed (each judged "
            "by a tree trained on the others, its options chosen inside them)"
        )
    names = [p.resolve() for p in args.data]
    dup = next((p for i, p in enumerate(names) if p in names[:i]), None)
    if dup is not None:
        raise UserError(f"{dup}: given twice (it would be trained on and judged)")
    logs = [read_log(path) for path in args.data]
    out = output_file(args.out, "--out") if args.out is not None else None
    judged = [prepare(log, velocity_window=args.velocity_window) for log in logs]
    views = [prepare(log) for log in logs]
    try:
        results = judge_leave_one_out(judged, views, load_default_model(), candidate_grid())
    except ValueError as err:
        raise UserError(str(err)) from err
    table = format_table(results)
    print(table, end="")
    if out is not None:
        write_text_atomically(out, table)
        print(f"\nwrote {out}")
    return 0


def _sensitivity(args: argparse.Namespace) -> int:
    from monopic.tree.intent_sensitivity import CUE_KEYS, sensitivity, write

    trees = {}
    for text in args.tree:
        name, sep, file = text.partition("=")
        if not sep or not name or not file:
            raise UserError(f"--tree {text!r}: give NAME=TREE.json")
        if name in trees:
            raise UserError(f"--tree {name}: given twice")
        trees[name] = load_intent_model(Path(file))
    runs = []
    for folder in args.data:
        if not folder.is_dir():
            raise UserError(f"{folder}: not a dataset folder (`monopic dataset` output)")
        runs.extend(read_dataset(folder))
    result = sensitivity(runs, trees, args.by or CUE_KEYS)
    out = output_folder(args.out, "--out")
    markdown = write(result, out, [str(d) for d in args.data])
    print(f"wrote {markdown} and {out / 'sensitivity.png'}")
    return 0


def _show(args: argparse.Namespace) -> int:
    model = load_any_model(args.tree)
    if isinstance(model, IntentTreeModel):
        print(
            intent_tree_dot(model) if args.dot else intent_summary(model),
            end="" if args.dot else "\n",
        )
        return 0
    print(tree_dot(model) if args.dot else summary(model), end="" if args.dot else "\n")
    return 0
