"""How far the intent rules could go with a perfect intent reading: their ceiling.

The intent tree's rules move constant velocity's point: hold it back when the tree says
stop or turn away, move it toward the robot's path when it says start crossing
(monopic.tree.intent.place). Trained trees missed the intent stage's goal (near-miss
runs warned at most a third of constant velocity's, recall@1s no more than 3 points
lower: docs/intent/verdict.md). Is the reading the limit, or the rules themselves? This
replays a sweep's own foot points through the shipped ground track and the real warning
(studies.ground_replay) with the rules fed the truth's intent label of each frame, which
no pipeline has, with the truth's current velocity in place of the Kalman track's (how
much of constant velocity's near-miss warnings is its lag), and with the true
future point itself. Nothing here is tuned or shipped: it bounds what any tree with these
rules, or any better velocity estimate, could do on those runs.

    .venv/bin/python -m studies.intent.ceiling RESULTS.jsonl [--tree monopic/tree/ground_tree.json]
        [--out docs/intent/ceiling.md]
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from monopic.errors import UserError
from monopic.features.ground import GroundMotion
from monopic.output import write_text_atomically
from monopic.predict.base import Prediction, with_ground_point
from monopic.tree.intent import START_CROSSING, IntentRules, LeafReading, place
from monopic.tree.serialise import load_intent_model
from sim.analysis.metrics import LEAD_GOAL, RunOutcome, paired_recall
from sim.runs.result import RunResult
from sim.runs.results_file import read_results
from studies.ground_replay import PointRule, ReplayFrame, judge_warnings, replay

BASELINE = "constant velocity (replayed)"
HOLDS = ("stop", "turn away")


def oracle_rule(row: RunResult, rules: IntentRules, hold: bool, earlier: bool) -> PointRule:
    """The intent rules given the truth's intent label of each frame."""
    horizon, labels = row.scenario.horizon, row.truth.intent

    def point(f: ReplayFrame) -> Prediction | None:
        intent = labels[f.k] if f.k < len(labels) else None
        if intent is None:
            return None
        reading = LeafReading(
            f.constant_velocity.case,
            intent,
            1.0,
            rules.min_rows,
            (0.0, 0.0),
            hold_share=1.0 if hold and intent in HOLDS else 0.0,
            hold_intent=intent if intent in HOLDS else "stop",
            start_share=1.0 if earlier and intent == START_CROSSING else 0.0,
        )
        g = f.features.ground
        assert g is not None
        at, _, _ = place(g.position, g.velocity, reading, rules, horizon, horizon, g.path_distance)
        return with_ground_point(f.features, f.constant_velocity.case, horizon, at)

    return point


def perfect_point(row: RunResult) -> PointRule:
    """The true position one horizon later: no predictor of a point can do better."""
    horizon, future = row.scenario.horizon, row.truth.future

    def point(f: ReplayFrame) -> Prediction | None:
        end = future[f.k]
        if end is None:
            return None
        return with_ground_point(f.features, f.constant_velocity.case, horizon, tuple(end))

    return point


def true_velocity_point(row: RunResult) -> PointRule:
    """Constant velocity from the pipeline's own foot point with the truth's current
    velocity instead of the Kalman track's: how much of constant velocity's near-miss
    warnings is the track's lag, not the walker's intent. The velocity is
    the truth's position change over the last frame plus the robot's own travel, in the
    robot's axes: exact for a robot driving straight, as in every intent family."""
    horizon, truth = row.scenario.horizon, row.truth

    def point(f: ReplayFrame) -> Prediction | None:
        k = f.k
        if k < 1:
            return None
        t0, t1 = truth.t[k - 1], truth.t[k]
        x0, x1 = truth.forward[k - 1], truth.forward[k]
        y0, y1 = truth.lateral[k - 1], truth.lateral[k]
        speed = truth.robot_speed[k]
        if None in (t0, t1, x0, x1, y0, y1, speed) or not t1 > t0:
            return None
        dt = t1 - t0
        vf, vl = (x1 - x0) / dt + speed, (y1 - y0) / dt
        g = f.features.ground
        assert g is not None
        at = (g.position[0] + vf * horizon, g.position[1] + vl * horizon)
        return with_ground_point(f.features, f.constant_velocity.case, horizon, at)

    return point


def outcomes(
    rows: Sequence[RunResult], rule: Callable[[RunResult], PointRule | None], name: str
) -> list[RunOutcome]:
    return [judge_warnings(row, replay(row, GroundMotion(), rule(row))[0], name) for row in rows]


def table(methods: dict[str, list[RunOutcome]], families: list[str]) -> list[str]:
    base = methods[BASELINE]
    lines = [
        f"| method | family | recall@{LEAD_GOAL:g}s | - constant velocity [95 % interval] "
        "| near-miss runs warned | constant velocity |",
        "| --- | --- | ---: | ---: | ---: | ---: |",
    ]
    for name, outs in methods.items():
        if name == BASELINE:
            continue
        for family in [*families, "all"]:
            pick = (lambda o: True) if family == "all" else (lambda o, f=family: o.family == f)
            p = paired_recall([o for o in outs if pick(o)], [o for o in base if pick(o)])
            recall = f"{p.warned_1s[0]}/{p.collision_runs}" if p.collision_runs else "-"
            diff = (
                f"{100 * p.difference:+.0f} [{100 * p.low:+.0f}, {100 * p.high:+.0f}]"
                if p.collision_runs
                else "-"
            )
            near = (
                (f"{p.near_miss_warned[0]}/{p.near_miss_runs}", f"{p.near_miss_warned[1]}")
                if p.near_miss_runs
                else ("-", "-")
            )
            lines.append(f"| {name} | {family} | {recall} | {diff} | {near[0]} | {near[1]} |")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", type=Path, help="a sweep's results file (monopic sweep)")
    ap.add_argument(
        "--tree",
        type=Path,
        default=Path("monopic/tree/ground_tree.json"),
        help="whose rules (start speed, release time) the oracle applies",
    )
    ap.add_argument("--out", type=Path, help="also write the table to this Markdown file")
    args = ap.parse_args(argv)
    try:
        if not args.results.is_file():
            raise UserError(
                f"{args.results}: no such results file (write one with `monopic sweep`)"
            )
        rows = list(read_results(args.results))
        if not rows:
            raise UserError(f"{args.results}: no result lines")
        rules = load_intent_model(args.tree).rules
    except UserError as err:
        print(err, file=sys.stderr)
        return 1
    no_bound = replace(rules, release_s=math.inf, hold_back_support=0.5, warn_support=0.5)
    bound = replace(no_bound, release_s=rules.release_s)
    methods: dict[str, list[RunOutcome]] = {}
    plans: list[tuple[str, Callable[[RunResult], PointRule | None]]] = [
        (BASELINE, lambda row: None),
        ("oracle hold-back + warn-earlier", lambda row: oracle_rule(row, no_bound, True, True)),
        ("oracle hold-back only", lambda row: oracle_rule(row, no_bound, True, False)),
    ]
    if math.isfinite(rules.release_s):
        plans.append(
            (
                f"oracle, hold-back released at {rules.release_s:g} s",
                lambda row: oracle_rule(row, bound, True, True),
            )
        )
    plans.append(("constant velocity, the truth's current velocity", true_velocity_point))
    plans.append(("true future point", perfect_point))
    for name, rule in plans:
        print(f"replaying {len(rows)} runs: {name}", file=sys.stderr, flush=True)
        methods[name] = outcomes(rows, rule, name)
    families = sorted({o.family for o in methods[BASELINE]})
    lines = [
        f"{len(rows)} runs of `{args.results}`, replayed from their own foot points "
        f"(studies/intent/ceiling.py, rules of `{args.tree}`: start speed "
        f"{rules.start_speed:g} m/s). Each method beside constant velocity on the same "
        "runs; recall counts collision runs warned at least 1 s before contact.",
        "",
        *table(methods, families),
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        write_text_atomically(args.out, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
