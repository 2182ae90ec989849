"""Would gating the intent rules on the head turn pay? The chosen rules on validation, gated.

Validation rows only (the trainer's own split of the datasets; nothing judged): a ground
intent tree's chosen rules, with the release time varied, and

- the turn-away hold-back applied only while the head turns away from the robot
  (`head_toward` at or below a threshold; stop hold-backs unchanged, an unseen head not
  gated): before a turn away the head leads the turn, away from the traffic;
- a warn-earlier at any start-crossing share (0.05) for standing walkers whose head
  turns away (a check toward the traffic just ended, before a step-off);
- no hold-back for those same standing walkers (where the hold-back costs recall: the
  walkers who wait, then cross).

Each line: collision runs warned 1 s ahead, near-miss runs warned, mean lead, as the
trainer's release table counts them. A gate pays if it reaches fewer near misses at the
same collision count with more lead than the release times alone (docs/intent/
ground-tree.md, session 9).

    .venv/bin/python tools/intent_cue_gate.py recordings/intent/ground-s9.json \
        recordings/intent/train-s9 recordings/intent/train-b-s9
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from monopic.errors import UserError
from monopic.tree.intent import IntentRules, IntentSample, LeafReading, place
from monopic.tree.intent_training import (
    RunCount,
    count_runs,
    read_dataset,
    split_runs,
    warned_frames,
)
from monopic.tree.serialise import load_intent_model

STANDING_M_S = 0.3
RELEASES = (1.1, 1.2, 1.4, 2.0, math.inf)
TURN_GATES = (10.0, 0.0, -5.0, -10.0)  # deg of head_toward at or below which to hold back
START_GATES = (-5.0, -10.0, -15.0)
Gate = Callable[[float, IntentSample, LeafReading], bool]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("tree", type=Path, help="a ground intent tree (monopic tree train)")
    ap.add_argument("datasets", nargs="+", type=Path, help="the datasets it was trained on")
    args = ap.parse_args()
    try:
        model = load_intent_model(args.tree)
        runs = [r for folder in args.datasets for r in read_dataset(folder)]
    except (OSError, ValueError, UserError) as err:
        print(f"intent_cue_gate: {err}", file=sys.stderr)
        return 2
    split = split_runs(runs)
    val = [row.sample for r in split.validation for row in r.rows]
    rows = [row for r in split.validation for row in r.rows]
    paths = [model.tree.path(model.discretiser.discretise(s.values)) for s in val]
    horizon = model.horizon

    def count(rules: IntentRules, hold: Gate | None = None, start: Gate | None = None) -> RunCount:
        points = []
        for s, path in zip(val, paths, strict=True):
            reading = LeafReading.on_path(path, rules.min_rows)
            r, head = rules, s.values.get("head_toward", math.nan)
            if hold is not None and math.isfinite(head) and not hold(head, s, reading):
                r = replace(r, hold_back_support=1.01)
            if start is not None and math.isfinite(head) and start(head, s, reading):
                r = replace(r, warn_support=min(r.warn_support, 0.05))
            distance = s.values.get("path_distance", math.nan)
            points.append(place(s.position, s.velocity, reading, r, horizon, horizon, distance)[0])
        return count_runs(warned_frames(points, rows, horizon), split.validation)

    def line(label: str, c: RunCount) -> None:
        print(f"  {label}: {c.describe()}, mean lead {c.mean_lead:.2f} s")

    base = model.rules
    print(f"{args.tree}: {len(split.validation)} validation runs, {len(val)} rows")
    line("constant velocity", count(IntentRules(min_rows=base.min_rows)))
    for release in RELEASES:
        rules = replace(base, release_s=release)
        said = f"{release:g} s" if math.isfinite(release) else "no bound"
        print(f"release {said}")
        line("as chosen", count(rules))
        for t in TURN_GATES:
            gate: Gate = lambda h, s, rd, t=t: rd.hold_intent == "stop" or h <= t  # noqa: E731
            line(f"turn-away hold-back only at head_toward <= {t:g}", count(rules, hold=gate))
        for t in START_GATES:
            gate = lambda h, s, rd, t=t: s.values["speed"] < STANDING_M_S and h <= t  # noqa: E731
            line(f"warn earlier standing at head_toward <= {t:g}", count(rules, start=gate))
        for t in START_GATES:
            gate = lambda h, s, rd, t=t: not (s.values["speed"] < STANDING_M_S and h <= t)  # noqa: E731
            line(f"no hold-back standing at head_toward <= {t:g}", count(rules, hold=gate))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
