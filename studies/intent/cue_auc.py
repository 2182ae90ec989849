"""How well each intent feature alone tells an intent apart, on a ground intent dataset.

For every feature the ground tree may read and every intent, the area under the ROC curve
of the feature's value for rows labelled with that intent against all other rows, among
standing walkers (ground speed below 0.3 m/s) and walking ones. 0.5 is chance; below 0.5
means lower values go with the intent. A diagnostic beside the tree (docs/intent/
ground-tree.md): a feature can carry the cue and still change no warning if the tree reads
it only in small nodes.

`--decisive` keeps only the rows where a warning is decided: the walker outside the
robot's swept band and constant velocity's point inside it (or within the zone's reach
of it), and adds "hold" (stop or turn away against the rest), the reading the intent
rules need there (docs/intent/ceiling.md).

    .venv/bin/python -m studies.intent.cue_auc recordings/intent/train-s9 \
        recordings/intent/train-b-s9 [--decisive | --by-family]

`--by-family` prints, per family, the decisive rows' medians of time into the run, speed
and acceleration, split by whether a stop or turn away lies ahead (are the near-miss
walkers of the families' default run-up still starting when the warning is decided?).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from monopic.errors import UserError
from monopic.tree.intent import INTENT_ATTRIBUTES, INTENTS, ZONE_REACH, IntentSample
from monopic.tree.intent_training import LabelledRow, RunRows, read_dataset

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


def decisive(runs: list[RunRows]) -> list[tuple[RunRows, LabelledRow]]:
    """Rows where a warning is decided, with their run: the walker outside the robot's
    swept band (of the robot's width), constant velocity's point one horizon ahead within
    ZONE_REACH of it."""
    out = []
    for run in runs:
        for row in run.rows:
            s = row.sample
            (x, y), (vf, vl) = s.position, s.velocity
            if not all(math.isfinite(v) for v in (x, y, vf, vl)) or x <= 0:
                continue
            half = row.robot.width / 2
            if abs(y) > half and abs(y + vl * run.horizon) < half + ZONE_REACH:
                out.append((run, row))
    return out


def decisive_rows(runs: list[RunRows]) -> list[IntentSample]:
    """The samples of `decisive`."""
    return [row.sample for _, row in decisive(runs)]


Medians = tuple[str, bool, int, float, float, float, float, float, float]
TRUE_ACC_S = 0.2  # s: the truth's speed change over this much before the frame


def true_speeds(folder: Path, run: str) -> dict[float, float]:
    """The truth's walking speed (m/s) at each frame time of a dataset run."""
    path = folder / "truth" / f"{run}.jsonl"
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
        return {round(t["time"], 3): float(t["speed"]) for t in map(json.loads, lines)}
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise UserError(f"{path}: cannot read the truth's speed: {err}") from None


def family_medians(
    runs: list[RunRows], truth: Mapping[str, Mapping[float, float]] | None = None
) -> list[Medians]:
    """Per family and reading (stop or turn away ahead, or not), on the decisive rows: the
    row count and the medians of the time into the run (s), the pipeline's window speed
    (m/s) and acceleration along the walk (m/s^2), and, from `truth` (run -> time ->
    true speed), the true speed and its change over the last TRUE_ACC_S (NaN without),
    and last the speed of the Kalman track constant velocity extrapolates (m/s).
    Shows whether a walker still starting up when the warning is decided can show a
    slowing cue at all, and what the pipeline's window (centred about 0.5 s back) reads
    of it."""
    groups: dict[tuple[str, bool], list[tuple[float, ...]]] = {}
    for run, row in decisive(runs):
        v = row.sample.values
        speeds = (truth or {}).get(run.run, {})
        now = speeds.get(round(row.time, 3), math.nan)
        before = speeds.get(round(row.time - TRUE_ACC_S, 3), math.nan)
        key = (run.family, row.sample.intent in HOLDS)
        groups.setdefault(key, []).append(
            (
                row.time,
                v.get("speed", math.nan),
                v.get("acceleration", math.nan),
                now,
                (now - before) / TRUE_ACC_S,
                math.hypot(*row.sample.velocity),
            )
        )
    out = []
    for (family, hold), values in sorted(groups.items()):
        a = np.asarray(values, dtype=float)
        med = [float(np.nanmedian(c)) if np.isfinite(c).any() else math.nan for c in a.T]
        out.append((family, hold, len(values), *med))
    return out


def plot_runs(
    runs: list[RunRows], truth: Mapping[str, Mapping[float, float]], path: Path
) -> list[str]:
    """One panel per family: its first run with a decisive row (preferring one where a
    stop or turn away lies ahead), the truth's speed beside the window's and the Kalman
    track's over time, the decisive frames marked. Returns the runs drawn."""
    from matplotlib.figure import Figure

    from monopic.output import atomic_path

    rows_of = decisive(runs)
    chosen: dict[str, RunRows] = {}
    for prefer_hold in (True, False):
        for run, row in rows_of:
            if (row.sample.intent in HOLDS) == prefer_hold:
                chosen.setdefault(run.family, run)
    families = sorted(chosen)
    if not families:
        raise UserError(f"{path}: nothing to draw: no decisive rows in these datasets")
    decisive_times = {(run.run, row.time) for run, row in rows_of}
    cols = 2 if len(families) > 1 else 1
    fig = Figure(figsize=(6 * cols, 3.2 * math.ceil(len(families) / cols)), layout="constrained")
    for i, family in enumerate(families):
        run = chosen[family]
        ax = fig.add_subplot(math.ceil(len(families) / cols), cols, i + 1)
        t = [row.time for row in run.rows]
        true = [truth.get(run.run, {}).get(round(x, 3), math.nan) for x in t]
        ax.plot(t, true, color="black", label="true speed")
        ax.plot(t, [r.sample.values.get("speed", math.nan) for r in run.rows], label="1 s window")
        ax.plot(t, [math.hypot(*r.sample.velocity) for r in run.rows], label="Kalman track")
        marks = [x for x in t if (run.run, x) in decisive_times]
        ax.plot(marks, [0.05] * len(marks), "|", color="red", markersize=12, label="decisive")
        ax.set_title(f"{family}: {run.run.split('/')[-1]}", fontsize=9)
        ax.set_xlabel("time into the run (s)")
        ax.set_ylabel("speed (m/s)")
        ax.set_ylim(0, 2.5)
        ax.grid(True, alpha=0.3)
        if i == 0:
            ax.legend(fontsize=7, loc="upper left")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    return [chosen[f].run for f in families]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("datasets", nargs="+", type=Path, help="dataset folders (monopic dataset)")
    ap.add_argument("--decisive", action="store_true", help="only rows where a warning is decided")
    ap.add_argument(
        "--by-family",
        action="store_true",
        help="instead: per family, medians of time, speed and acceleration on decisive rows",
    )
    ap.add_argument(
        "--plot",
        type=Path,
        help="with --by-family: also draw one run per family (truth, window, track speed)",
    )
    args = ap.parse_args()
    if args.plot and not args.by_family:
        print("cue_auc: --plot draws the --by-family view; give both", file=sys.stderr)
        return 2
    runs = []
    truth: dict[str, dict[float, float]] = {}
    for folder in args.datasets:
        try:
            these = read_dataset(folder)
            if args.by_family:
                truth.update({r.run: true_speeds(folder, r.run) for r in these})
        except (OSError, ValueError, UserError) as err:
            print(f"cue_auc: {err}", file=sys.stderr)
            return 2
        runs += these
    if args.by_family:
        print(f"{len(runs)} runs; decisive rows per family, medians. Speed and acceleration:")
        print("the pipeline's 1 s window, read about 0.5 s back; true acceleration: over the")
        print(f"last {TRUE_ACC_S} s; track speed: the Kalman track constant velocity extrapolates")
        print()
        print(
            "| family | stop or turn away ahead | rows | time into run | speed | acceleration"
            " | true speed | true acceleration | track speed |"
        )
        print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for family, hold, n, t, speed, acc, true, true_acc, track in family_medians(runs, truth):
            print(
                f"| {family} | {'yes' if hold else 'no'} | {n} | {t:.2f} s | {speed:.2f} m/s"
                f" | {acc:+.2f} m/s² | {true:.2f} m/s | {true_acc:+.2f} m/s² | {track:.2f} m/s |"
            )
        if args.plot:
            try:
                drawn = plot_runs(runs, truth, args.plot)
            except UserError as err:
                print(f"cue_auc: {err}", file=sys.stderr)
                return 2
            print(f"\n{args.plot}: runs {', '.join(drawn)}")
        return 0
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
