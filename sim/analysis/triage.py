"""The runs to look at: collision runs a predictor missed or warned late, near misses it
warned on, each with the command that runs it again into a recording (`monopic rerun`).

The three come from the run-level definitions of sim.analysis.metrics, so the list counts
what the report's tables count: missed is a collision run without a warning onset before
contact (not in recall); late is an onset less than LEAD_GOAL before contact (in recall,
not in recall@1s); a near miss warned is a near-miss run with any warned frame (the
table's "near-miss warned").
"""

from __future__ import annotations

import os
import shlex
from collections import Counter, defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sim.analysis.markdown import table
from sim.analysis.metrics import LEAD_GOAL, MAIN, RunOutcome, SweepMetrics, split_method
from sim.runs.result import RunResult

MISSED, LATE, NEAR_MISS = "missed", "late", "near miss warned"
WHATS = (MISSED, LATE, NEAR_MISS)  # also the order of the list: the worst first
PER_FAMILY = 5  # runs listed per family; the others are counted


def went_wrong(o: RunOutcome) -> str | None:
    """MISSED, LATE or NEAR_MISS for a run that went wrong for its method, else None."""
    if o.collision_run:
        if o.lead is None:
            return MISSED
        return LATE if o.lead < LEAD_GOAL else None
    return NEAR_MISS if o.near_miss and o.warned else None


def severity(o: RunOutcome) -> tuple[int, float]:
    """Sort key, the worst first: missed, then late by lead, then near misses by how many
    frames warned."""
    what = went_wrong(o)
    if what == LATE:
        return WHATS.index(LATE), o.lead or 0.0
    if what == NEAR_MISS:
        return WHATS.index(NEAR_MISS), -float(o.frames.fp + o.frames.tp)
    return (WHATS.index(MISSED) if what else len(WHATS)), 0.0


def how(o: RunOutcome) -> str:
    """'missed', 'late: 0.42 s before contact', 'near miss warned (7 frames)'."""
    what = went_wrong(o)
    if what == LATE:
        return f"late: {o.lead:.2f} s before contact"
    if what == NEAR_MISS:
        return f"near miss warned ({o.frames.fp + o.frames.tp} frames)"
    return str(what)


def plural(n: int, word: str) -> str:
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def primary(m: SweepMetrics) -> str | None:
    """The primary predictor of the real pipeline: the first main method (rules/image in
    the metrics' order, the pipeline's own primary, whose warning is the robot's)."""
    return next((x for x in m.methods if split_method(x)[0] == MAIN), None)


def describe(params: dict[str, Any]) -> str:
    """'robot.speed = 2, duration = 2' (the swept values), or 'the file's values'."""
    if not params:
        return "the file's values"
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in params.items())  # fmt: skip


@dataclass(frozen=True)
class Rerunning:
    """How the report points at a results file's runs: the results path as the user gave
    it, the sweep's recordings folder, the report's folder (links are relative to it), and
    the digests of the intent trees shipped with the code (`monopic rerun` finds those)."""

    results: Path
    recordings: Path
    report: Path
    shipped_trees: frozenset[str] = frozenset()

    @classmethod
    def of(cls, results: Path, report: Path) -> Rerunning:
        from sim.runs.rebuild import shipped_trees
        from sim.runs.sweep import recordings_folder, tree_digest

        trees = frozenset(tree_digest(t) for t in shipped_trees())
        return cls(results, recordings_folder(results), report, trees)

    def needs_tree(self, code: str | None) -> bool:
        """A run of a sweep that ran an intent tree not shipped with the code (its `code`
        names the tree's digest): its rerun needs the tree's file (--intent-tree)."""
        from sim.runs.sweep import TREE_TAG

        digest = (code or "").partition(TREE_TAG)[2]
        return bool(digest) and digest not in self.shipped_trees

    def command(self, run_id: str, code: str | None) -> str:
        """`monopic rerun RESULTS RUN_ID`, quoted for a POSIX shell."""
        command = shlex.join(["monopic", "rerun", str(self.results), run_id])
        return command + (" --intent-tree TREE" if self.needs_tree(code) else "")

    def link(self, row: RunResult) -> str | None:
        """A Markdown link to the run's kept recording, None when none is there."""
        if not row.recording or not (self.recordings / row.recording).is_file():
            return None
        return _link(row.recording, self.recordings / row.recording, self.report)


def _link(text: str, target: Path, base: Path) -> str:
    rel = Path(os.path.relpath(target.resolve(), base.resolve())).as_posix()
    return f"[{text}](<{rel}>)" if " " in rel else f"[{text}]({rel})"


def triage_lines(m: SweepMetrics, rows: Sequence[RunResult], where: Rerunning) -> list[str]:
    """The report's section: the primary predictor's runs that went wrong, at most
    PER_FAMILY per family, each with its parameters, recording and command; then every
    main predictor's counts per family."""
    first = primary(m)
    if first is None:
        return []
    by_id = {r.id: r for r in rows}
    mains = [x for x in m.methods if split_method(x)[0] == MAIN]
    others = {x: {o.id: o for o in m.outcomes[x]} for x in mains if x != first}
    wrong = sorted((o for o in m.outcomes[first] if went_wrong(o)), key=severity)
    lines = [
        "## Runs to look at",
        "",
        f"The runs where the primary predictor, {first} (its warning is the robot's), missed",
        "a collision (no warning before contact), warned late (less than "
        f"{LEAD_GOAL:g} s before contact:",
        f"counted by recall, not by recall@{LEAD_GOAL:g}s) or warned on a near miss; at most "
        f"{PER_FAMILY} per family, the",
        "worst first (missed, then late by lead, then near misses by frames warned), the rest",
        "counted. Each command runs its run again into a rerun recording and checks that it",
        "gives the same frames and decisions (run it from the folder the sweep ran in: a",
        "results line names its scenario file as the sweep found it); `monopic view FILE.rrd`",
        "opens a recording, one lane per predictor.",
        "",
    ]
    if not wrong:
        lines += [f"None: {first} missed no collision, warned none late and no near miss.", ""]
    families: dict[str, list[RunOutcome]] = defaultdict(list)
    for o in wrong:
        families[o.family].append(o)
    for family, outcomes in sorted(families.items()):
        runs = sum(o.family == family for o in m.outcomes[first])
        count = Counter(went_wrong(o) for o in outcomes)
        said = ", ".join(f"{count[w]} {w}" for w in WHATS if count[w])
        lines += [f"**{family}**: {said} of {plural(runs, 'run')}", ""]
        for o in outcomes[:PER_FAMILY]:
            row = by_id.get(o.id)  # the metrics' rows (a caller may pass none)
            also = [f"{x} {went_wrong(others[x][o.id])}" for x in others
                    if went_wrong(others[x][o.id])]  # fmt: skip
            link = where.link(row) if row else None
            lines += [
                f"- `{o.id}` ({describe(row.params if row else {})}): **{how(o)}**"
                + (f"; also {', '.join(also)}" if also else "")
                + f"; recording {link or 'not kept'}",
                f"  `{where.command(o.id, row.code if row else None)}`",
            ]
        rest = outcomes[PER_FAMILY:]
        if rest:
            count = Counter(went_wrong(o) for o in rest)
            more = ", ".join(f"{count[w]} {w}" for w in WHATS if count[w])
            lines.append(f"- and {len(rest)} more ({more})")
        lines.append("")
    if any(where.needs_tree(r.code) for r in rows):
        lines += [
            "TREE: the intent tree file the sweep spec names (`intent_tree`); these runs ran "
            "one not shipped with the code.",
            "",
        ]
    kept = [r for r in rows if where.link(r)]
    if kept:
        folder = _link(f"{where.recordings.name}/", where.recordings, where.report)
        lines += [f"The sweep kept {plural(len(kept), 'recording')}, in {folder}.", ""]
    lines += [
        "Per predictor (main pipeline), runs missed / warned late / near misses warned:",
        "",
        *_counts_table(m, mains),
        "",
    ]
    return lines


def _counts_table(m: SweepMetrics, methods: Sequence[str]) -> list[str]:

    rows = []
    for family in [*m.families, "all"]:
        cells = [family]
        for x in methods:
            count = Counter(went_wrong(o) for o in m.outcomes[x] if family in ("all", o.family))
            cells.append(" / ".join(str(count[w]) for w in WHATS))
        rows.append(cells)
    return table(["family", *methods], rows)


def triage_summary(m: SweepMetrics) -> str | None:
    """One line for the terminal: the primary predictor's runs that went wrong."""
    first = primary(m)
    if first is None:
        return None
    count = Counter(went_wrong(o) for o in m.outcomes[first])
    said = ", ".join(f"{count[w]} {w}" for w in WHATS)
    return f"runs to look at ({first}): {said}; each with its `monopic rerun` command in the report"
