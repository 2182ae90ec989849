"""The people tracker judged: with bystanders against the same draws without, and before
(the one-pedestrian tracker) against after (the people tracker) on the baseline's runs.

Paired: the judged sweep (scenarios/sweeps/people-judged.toml) draws each family's values
once and runs them with and without bystanders; a pair is the two runs sharing every
drawn value. Recall@1s is of the threatening person (sim.analysis.person_by_person), over
the pairs where someone is on a collision course in both runs; the difference (with
bystanders minus without) gets Newcombe's paired 95 % interval
(sim.analysis.metrics.paired_difference). Near misses: pairs where nobody is ever on
course in either run, and whether each run warned at all.

Before and after: the baseline's runs (scenarios/sweeps/people-baseline.toml, the
one-pedestrian tracker, its warnings attributed by the pipeline's foot point as
docs/people/baseline.md did) and the same runs with the people tracker
(people-baseline-everyone.toml, attributed by their tracks), both judged by one set of
rules (sim.analysis.person_by_person.judge_warned): warned frames for the wrong person,
and threatening people missed.

    .venv/bin/python -m studies.people.judged --judged J.jsonl [--before B.jsonl
        --after A.jsonl] [--out FILE.md]
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

from monopic.errors import UserError
from monopic.output import write_text_atomically
from sim.analysis.metrics import paired_difference, split_method
from sim.analysis.people import warned_people
from sim.analysis.person_by_person import (
    RunVerdict,
    WarnedFrame,
    judge_run,
    judge_warned,
    summarise,
)
from sim.runs.result import RunResult
from sim.runs.results_file import read_results

METHODS = ("rules/image", "rules/ground", "constant-velocity/ground", "tree/image")
GOAL_POINTS = -3.0  # the paired lower bound's goal, points


def pair_key(row: RunResult) -> tuple[str, tuple[tuple[str, str], ...]]:
    """A run's family and drawn values without its people: what a pair shares."""
    return row.family, tuple(sorted((k, str(v)) for k, v in row.params.items() if k != "people"))


def pairs(rows: Sequence[RunResult]) -> list[tuple[RunResult, RunResult]]:
    """(with bystanders, without) for every drawn value set run both ways."""
    by: dict[tuple, dict[bool, RunResult]] = defaultdict(dict)
    for row in rows:
        by[pair_key(row)][bool(row.params.get("people"))] = row
    return [(two[True], two[False]) for two in by.values() if len(two) == 2]


def paired_lines(rows: Sequence[RunResult]) -> list[str]:
    both = pairs(rows)
    lines = [
        f"{len(both)} pairs (with 2-4 bystanders, without), the people tracker in both.",
        "",
        "| method | collision pairs | warned 1 s ahead: with / without | with only | without "
        "only | difference (points) | paired 95 % interval | goal >= -3 | near-miss pairs "
        "| near misses warned: with / without |",
        "| --- | ---: | --- | ---: | ---: | ---: | --- | --- | ---: | --- |",
    ]
    for method in METHODS:
        verdicts = [(judge_run(a, method), judge_run(b, method)) for a, b in both]
        judged = [(a, b) for a, b in verdicts if a is not None and b is not None]
        threat = [(a, b) for a, b in judged if a.threatened and b.threatened]
        n11 = sum(a.warned_1s_for_threat and b.warned_1s_for_threat for a, b in threat)
        n10 = sum(a.warned_1s_for_threat and not b.warned_1s_for_threat for a, b in threat)
        n01 = sum(b.warned_1s_for_threat and not a.warned_1s_for_threat for a, b in threat)
        n00 = len(threat) - n11 - n10 - n01
        diff, low, high = paired_difference(n11, n10, n01, n00) if threat else (0.0, 0.0, 0.0)
        near = [(a, b) for a, b in judged if a.near_miss and b.near_miss]
        warned_with = sum(a.warned_frames > 0 for a, _ in near)
        warned_without = sum(b.warned_frames > 0 for _, b in near)
        met = 100 * low >= GOAL_POINTS and warned_with <= warned_without
        lines.append(
            f"| {method} | {len(threat)} | {n11 + n10} / {n11 + n01} | {n10} | {n01} "
            f"| {100 * diff:+.1f} | [{100 * low:+.1f}, {100 * high:+.1f}] "
            f"| {'met' if met else 'missed'} | {len(near)} | {warned_with} / {warned_without} |"
        )
    return lines


def foot_verdicts(rows: Sequence[RunResult], method: str) -> list[RunVerdict]:
    """The one-pedestrian tracker's lines judged with their warnings attributed by the
    pipeline's foot point (sim.analysis.people), by the same rules as the tracks'."""
    out = []
    for row in rows:
        if not row.people:
            continue
        whom = warned_people(row, method)
        name, key = split_method(method)
        pipeline = row.pipelines.get(name)
        decisions = pipeline.decisions.get(key) if pipeline else None
        if decisions is None:
            continue
        warned = [
            WarnedFrame(k, -1, whom[k]) for k, w in enumerate(decisions.warn) if w and k < len(whom)
        ]
        out.append(judge_warned(row, method, warned))
    return out


def before_after_lines(before: Sequence[RunResult], after: Sequence[RunResult]) -> list[str]:
    lines = [
        f"Before: {len(before)} runs, the one-pedestrian tracker (warnings attributed by the "
        f"foot point); after: {len(after)} runs, the people tracker (by its tracks).",
        "",
        "| method | warned 1 s ahead for the threat | missed threatening people | warned "
        "frames for the wrong person | for nobody (phantom or no foot point) | runs with a "
        "wrong-person warning |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for method in METHODS:
        b = summarise(foot_verdicts(before, method))
        a = summarise([v for v in (judge_run(r, method) for r in after) if v is not None])

        def share(s) -> str:
            said = s.for_threat + s.early + s.wrong_person + s.phantom
            return f"{s.wrong_person}/{said} ({100 * s.wrong_person / said:.0f} %)" if said else "-"

        lines.append(
            f"| {method} | {b.warned_1s}/{b.threat_runs} -> {a.warned_1s}/{a.threat_runs} "
            f"| {b.missed_people}/{b.threat_people} -> {a.missed_people}/{a.threat_people} "
            f"| {share(b)} -> {share(a)} | {b.phantom} -> {a.phantom} "
            f"| {b.runs_wrong_person} -> {a.runs_wrong_person} |"
        )
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--judged", type=Path, required=True, help="the judged sweep's results")
    ap.add_argument("--before", type=Path, help="the baseline's results (one tracker)")
    ap.add_argument("--after", type=Path, help="the same runs with the people tracker")
    ap.add_argument("--out", type=Path, help="write the tables here (Markdown)")
    args = ap.parse_args(argv)
    try:
        if (args.before is None) != (args.after is None):
            raise UserError("--before and --after go together")
        for path in (args.judged, args.before, args.after):
            if path is not None and not path.is_file():
                raise UserError(f"{path}: no such results file")
        lines = ["## With bystanders against without", "", *paired_lines(read_results(args.judged))]
        if args.before is not None:
            before, after = list(read_results(args.before)), list(read_results(args.after))
            lines += ["", "## Before and after", "", *before_after_lines(before, after)]
    except UserError as err:
        print(f"studies.people.judged: error: {err}", file=sys.stderr)
        return 2
    text = "\n".join(lines) + "\n"
    if args.out:
        write_text_atomically(args.out, text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
