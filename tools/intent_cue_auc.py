"""How well each intent feature alone tells an intent apart, on a ground intent dataset.

For every feature the ground tree may read and every intent, the area under the ROC curve
of the feature's value for rows labelled with that intent against all other rows, among
standing walkers (ground speed below 0.3 m/s) and walking ones. 0.5 is chance; below 0.5
means lower values go with the intent. A diagnostic beside the tree (docs/intent/
ground-tree.md, session 9): a feature can carry the cue and still change no warning if the
tree reads it only in small nodes.

`--decisive` keeps only the rows where a warning is decided: the walker outside the
robot's swept band and constant velocity's point inside it (or within the zone's reach
of it), and adds "hold" (stop or turn away against the rest), the reading the intent
rules need there (docs/intent/ceiling.md).

    .venv/bin/python tools/intent_cue_auc.py recordings/intent/train-s9 recordings/intent/train-b-s9
        [--decisive]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from monopic.errors import UserError
from monopic.replay.intent_training import RunRows, read_dataset
from monopic.tree.intent import INTENT_ATTRIBUTES, INTENTS, ZONE_REACH, IntentSample

STANDING_M_S = 0.3
HOLD = "hold"  # stop or turn away: what the hold-back rule needs to know


def auc(positive: list[float], negative: list[float]) -> float:
    """P(a positive value > a negative one), ties counted half (Mann-Whitney U / n+ n-)."""
    if not positive or not negative:
        return math.nan
    neg = np.sort(np.asarray(negative, dtype=float))
    pos = np.asarray(positive, dtype=float)
    below = np.searchsorted(neg, pos, side="left")  # negatives under each positive
    tied = np.searchsorted(neg, pos, side="right") - below
    return float((below + 0.5 * tied).sum() / (len(pos) * len(neg)))


HOLDS = ("stop", "turn away")


def decisive_rows(runs: list[RunRows]) -> list[IntentSample]:
    """Rows where a warning is decided: the walker outside the robot's swept band (of the
    robot's width), constant velocity's point one horizon ahead within ZONE_REACH of it."""
    out = []
    for run in runs:
        for row in run.rows:
            s = row.sample
            (x, y), (vf, vl) = s.position, s.velocity
            if not all(math.isfinite(v) for v in (x, y, vf, vl)) or x <= 0:
                continue
            half = row.robot.width / 2
            if abs(y) > half and abs(y + vl * run.horizon) < half + ZONE_REACH:
                out.append(s)
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("datasets", nargs="+", type=Path, help="dataset folders (monopic dataset)")
    ap.add_argument("--decisive", action="store_true", help="only rows where a warning is decided")
    args = ap.parse_args()
    runs = []
    for folder in args.datasets:
        try:
            runs += read_dataset(folder)
        except (OSError, ValueError, UserError) as err:
            print(f"intent_cue_auc: {err}", file=sys.stderr)
            return 2
    rows = decisive_rows(runs) if args.decisive else [r.sample for run in runs for r in run.rows]
    which = "decisive rows" if args.decisive else "rows"
    print(f"{len(runs)} runs, {len(rows)} {which}; AUC of each feature alone, intent against rest")
    print()
    print("| walker | intent | rows | " + " | ".join(INTENT_ATTRIBUTES) + " |")
    print("| --- | --- | ---: |" + " ---: |" * len(INTENT_ATTRIBUTES))
    for walker, standing in (("standing", True), ("walking", False)):
        group = [
            s
            for s in rows
            if math.isfinite(s.values["speed"]) and (s.values["speed"] < STANDING_M_S) == standing
        ]
        for intent in (*INTENTS, HOLD) if args.decisive else INTENTS:
            said = (
                (lambda s: s.intent in HOLDS)
                if intent == HOLD
                else (lambda s, i=intent: s.intent == i)
            )
            n = sum(said(s) for s in group)
            cells = []
            for attr in INTENT_ATTRIBUTES:
                known = [s for s in group if math.isfinite(s.values[attr])]
                pos = [s.values[attr] for s in known if said(s)]
                neg = [s.values[attr] for s in known if not said(s)]
                cells.append(f"{auc(pos, neg):.2f}")
            print(f"| {walker} | {intent} | {n} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
