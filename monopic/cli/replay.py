"""`monopic replay LOG.csv...`: judge our stages on logs in the authors' CSV format."""

from __future__ import annotations

import argparse
from pathlib import Path

from monopic.cli.args import output_file, positive_int
from monopic.cli.tree import add_training_options, training_options
from monopic.errors import UserError
from monopic.output import write_text_atomically
from monopic.predict.base import Mode
from monopic.replay.dataset import prepare
from monopic.replay.logs import read_log
from monopic.replay.run import format_report, predictions_csv, replay
from monopic.tree.serialise import load_model

DESCRIPTION = """\
Replay logs in the authors' CSV format through our velocity estimate, tree and
prediction, and print per-file and overall scores: the paper metric (position one frame
later within 51 px), the error at the real 1 s horizon (median, mean, share within
50 px) and the case accuracy, for our tree, the authors' own predictions, constant
velocity, the rule cascade and standing still.

Which tree judges a file: --tree judges every file; without it, two or more files are
judged leave-one-file-out (each by a tree trained on the others with the training
options below); a single file is judged by the default tree shipped in the package.
A file that is in the judging tree's training data is flagged IN-SAMPLE.
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "replay",
        help="score our predictions on logged tracks (authors' CSV format)",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "logs", nargs="+", type=Path, metavar="LOG.csv", help="logs in the authors' CSV format"
    )
    p.add_argument("--tree", type=Path, metavar="TREE.json", help="judge with this tree")
    p.add_argument(
        "--person",
        type=positive_int,
        metavar="ID",
        help="in logs of several people (monopic video's CSV, column personId), read this "
        "person's rows (>= 1)",
    )
    p.add_argument(
        "--csv",
        type=Path,
        metavar="OUT.csv",
        help="write our prediction for every input row: file, row, time, horizon, "
        "predicted x and y, case",
    )
    add_training_options(p)
    p.set_defaults(func=_replay)


def _replay(args: argparse.Namespace) -> int:
    out: Path | None = args.csv
    model = load_model(args.tree) if args.tree is not None else None
    if model is not None and model.mode is not Mode.IMAGE:
        raise UserError(f"{args.tree}: a {model.mode.value}-mode tree; replay needs image mode")
    prepared = [prepare(read_log(path, args.person)) for path in args.logs]
    if out is not None:
        output_file(out, "--csv")
    try:
        results = replay(prepared, model, training_options(args))
    except ValueError as err:
        raise UserError(str(err)) from err
    if out is not None:
        write_text_atomically(out, predictions_csv(results))
    print(format_report(results), end="")
    if out is not None:
        print(f"predictions written to {out}")
    return 0
