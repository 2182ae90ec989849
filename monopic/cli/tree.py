"""`monopic tree train|show`: fit the ID3 tree on authors' logs, inspect a tree file."""

from __future__ import annotations

import argparse
from pathlib import Path

from monopic.cli.args import non_negative_float, output_file, positive_int
from monopic.errors import UserError
from monopic.replay.dataset import prepare
from monopic.replay.logs import read_log
from monopic.replay.training import DEFAULT_MIN_SAMPLES, DISCRETISERS, TrainOptions, train_on_logs
from monopic.tree.discretise import AUTHORS_DEAD_ZONE
from monopic.tree.report import summary, tree_dot
from monopic.tree.serialise import load_model, save_model


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
        help="dead zone of the authors' bins, degrees and px/s (default %(default)g)",
    )
    p.add_argument(
        "--max-depth", type=positive_int, default=None, help="deepest split level (default: none)"
    )
    p.add_argument(
        "--min-samples",
        type=positive_int,
        default=DEFAULT_MIN_SAMPLES,
        help="a node with fewer training rows is not split (default %(default)d)",
    )


def training_options(args: argparse.Namespace) -> TrainOptions:
    return TrainOptions(
        discretiser=args.discretiser,
        dead_zone=args.dead_zone,
        min_samples=args.min_samples,
        max_depth=args.max_depth,
    )


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "tree",
        help="train or inspect the ID3 decision tree",
        description="The ID3 decision tree over the discretised (phi, vx, vy): `tree train` "
        "fits one on logs in the authors' CSV format, `tree show` prints a tree file.",
    )
    sub = p.add_subparsers(dest="tree_command", required=True, metavar="ACTION")

    t = sub.add_parser(
        "train",
        help="fit a tree on logs in the authors' CSV format",
        description="Fit an image-mode ID3 tree on the scored rows of the logs (rows after "
        "the 0.5 s warm-up with a full next second), labelled with the case of the next "
        "second of motion; print the gain table and the tree; write versioned JSON.",
    )
    t.add_argument(
        "data", nargs="+", type=Path, metavar="DATA.csv", help="logs in the authors' CSV format"
    )
    t.add_argument(
        "--out", required=True, type=Path, metavar="TREE.json", help="the tree file to write"
    )
    add_training_options(t)
    t.set_defaults(func=_train)

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
    logs = [prepare(read_log(path)) for path in args.data]
    try:
        model = train_on_logs(logs, training_options(args))
    except ValueError as err:
        raise UserError(str(err)) from err
    out = output_file(args.out, "--out")
    save_model(model, out)
    print(summary(model))
    print(f"\nwrote {out}")
    return 0


def _show(args: argparse.Namespace) -> int:
    model = load_model(args.tree)
    print(tree_dot(model) if args.dot else summary(model), end="" if args.dot else "\n")
    return 0
