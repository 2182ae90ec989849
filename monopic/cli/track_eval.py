"""`monopic track-eval TRACKS.txt --gt GT`: score multi-person tracks against MOTChallenge
ground truth (monopic.evaluation.mot)."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from monopic.cli.args import output_file, ranged
from monopic.evaluation.mot import FrameRange, TrackScores, evaluate_files, parse_frame_range
from monopic.output import write_text_atomically

DESCRIPTION = """\
Score a tracks file against MOTChallenge ground truth with motmetrics (the [tracking]
extra): MOTA, MOTP (mean IoU of the matched boxes), IDF1, IDP, IDR, identity switches,
fragmentations, recall, precision, false positives, misses, ground-truth identities and
how many are mostly tracked (>= 80% of their frames), partially tracked or mostly lost
(< 20%); then, per ground-truth person, the frames they are in, the share of them some
track matched (detection recall per person) and the distinct tracks that matched them
(identity fragmentation).

Both files are MOTChallenge text, one line per person per frame, frames counted from 1:
frame,id,bb_left,bb_top,bb_width,bb_height,conf,... (`monopic video --tracks` writes
this). Ground-truth rows with conf 0 are not scored; in files with a class column
(MOT16 and later) only pedestrians are, and track boxes on distractors (static people,
reflections...) are taken out first, as the official evaluation does.

HOTA is not given: motmetrics 1.4.0, its latest release, has no HOTA, and the official
HOTA code (trackeval) needs opencv-python, which clashes with opencv-python-headless.
"""


def _frame_range(text: str) -> FrameRange:
    try:
        return parse_frame_range(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "track-eval",
        help="score multi-person tracks against MOTChallenge ground truth (MOTA, IDF1)",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "tracks", type=Path, metavar="TRACKS.txt", help="tracks in the MOTChallenge format"
    )
    p.add_argument(
        "--gt",
        type=Path,
        required=True,
        metavar="GT",
        help="the ground truth: a MOTChallenge gt.txt, or a sequence folder holding gt/gt.txt",
    )
    p.add_argument(
        "--frames",
        type=_frame_range,
        metavar="FIRST-LAST",
        help="score these frames only, both ends included, counted from 1 "
        "(default: every frame either file has)",
    )
    p.add_argument(
        "--iou",
        type=ranged(0, 1, open_low=True),
        default=0.5,
        metavar="IOU",
        help="the least IoU at which a track box matches a ground-truth box, in (0, 1] "
        "(default: 0.5, MOTChallenge's)",
    )
    p.add_argument(
        "--json",
        type=Path,
        metavar="OUT.json",
        help="also write every figure and the per-person table to this file",
    )
    p.set_defaults(func=run)


def _ratio(value: float) -> str:
    return "n/a" if not math.isfinite(value) else f"{value:.3f}"


def format_scores(scores: TrackScores) -> str:
    """The figures as a short table for the terminal."""
    s = scores
    lines = [
        f"frames {s.frames}, a match needs IoU >= {s.min_iou:g}",
        f"MOTA {_ratio(s.mota)}  MOTP {_ratio(s.motp)}  IDF1 {_ratio(s.idf1)}  "
        f"IDP {_ratio(s.idp)}  IDR {_ratio(s.idr)}",
        f"recall {_ratio(s.recall)}  precision {_ratio(s.precision)}  "
        f"identity switches {s.switches}  fragmentations {s.fragmentations}",
        f"ground-truth boxes {s.gt_boxes}  track boxes {s.track_boxes}  matched {s.matches}  "
        f"misses {s.misses}",
        f"false positives {s.false_positives}, of which on people the ground truth leaves "
        f"unscored (conf 0): {s.false_positives_on_unscored}",
        *(
            [f"track boxes on distractors, taken out: {s.distractor_boxes}"]
            if s.distractor_boxes
            else []
        ),
        f"ground-truth identities {s.gt_identities}: mostly tracked {s.mostly_tracked}, "
        f"partially tracked {s.partially_tracked}, mostly lost {s.mostly_lost}",
        "HOTA: not computed (motmetrics 1.4.0 has none)",
        "",
        f"{'gt id':>6} {'frames':>7} {'matched':>8} {'recall':>7}  tracks",
    ]
    for i in s.identities:
        shown = ", ".join(str(t) for t in i.track_ids) or "-"
        lines.append(
            f"{i.gt_id:>6} {i.frames:>7} {i.matched:>8} {_ratio(i.recall):>7}  "
            f"{len(i.track_ids)}: {shown}"
        )
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    scores = evaluate_files(args.tracks, args.gt, args.frames, args.iou)
    print(format_scores(scores))
    if args.json is not None:
        output_file(args.json, "--json")
        document = {"tracks": str(args.tracks), "gt": str(args.gt), **scores.to_json()}
        write_text_atomically(args.json, json.dumps(document, indent=2) + "\n")
        print(f"wrote {args.json}")
    return 0
