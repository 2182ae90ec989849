"""How well each intent feature alone tells an intent apart, on a ground intent dataset.

For every feature the ground tree may read and every intent, the area under the ROC curve
of the feature's value for rows labelled with that intent against all other rows, among
standing walkers (ground speed below 0.3 m/s) and walking ones. 0.5 is chance; below 0.5
means lower values go with the intent. A diagnostic beside the tree (docs/intent/
ground-tree.md, session 9): a feature can carry the cue and still change no warning if the
tree reads it only in small nodes.

    .venv/bin/python tools/intent_cue_auc.py recordings/intent/train-s9 recordings/intent/train-b-s9
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from monopic.errors import UserError
from monopic.replay.intent_training import read_dataset
from monopic.tree.intent import INTENT_ATTRIBUTES, INTENTS

STANDING_M_S = 0.3


def auc(positive: list[float], negative: list[float]) -> float:
    """P(a positive value > a negative one), ties counted half (Mann-Whitney U / n+ n-)."""
    if not positive or not negative:
        return math.nan
    neg = np.sort(np.asarray(negative, dtype=float))
    pos = np.asarray(positive, dtype=float)
    below = np.searchsorted(neg, pos, side="left")  # negatives under each positive
    tied = np.searchsorted(neg, pos, side="right") - below
    return float((below + 0.5 * tied).sum() / (len(pos) * len(neg)))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("datasets", nargs="+", type=Path, help="dataset folders (monopic dataset)")
    args = ap.parse_args()
    runs = []
    for folder in args.datasets:
        try:
            runs += read_dataset(folder)
        except (OSError, ValueError, UserError) as err:
            print(f"intent_cue_auc: {err}", file=sys.stderr)
            return 2
    rows = [row.sample for run in runs for row in run.rows]
    print(f"{len(runs)} runs, {len(rows)} rows; AUC of each feature alone, intent against rest")
    print()
    print("| walker | intent | rows | " + " | ".join(INTENT_ATTRIBUTES) + " |")
    print("| --- | --- | ---: |" + " ---: |" * len(INTENT_ATTRIBUTES))
    for walker, standing in (("standing", True), ("walking", False)):
        group = [
            s
            for s in rows
            if math.isfinite(s.values["speed"]) and (s.values["speed"] < STANDING_M_S) == standing
        ]
        for intent in INTENTS:
            n = sum(s.intent == intent for s in group)
            cells = []
            for attr in INTENT_ATTRIBUTES:
                known = [s for s in group if math.isfinite(s.values[attr])]
                pos = [s.values[attr] for s in known if s.intent == intent]
                neg = [s.values[attr] for s in known if s.intent != intent]
                cells.append(f"{auc(pos, neg):.2f}")
            print(f"| {walker} | {intent} | {n} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
