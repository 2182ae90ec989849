"""The runs to look at: collision runs a predictor missed or warned late, near misses it
warned on, each with the command that runs it again into a recording (`monopic rerun`).

The three come from the run-level definitions of sim.analysis.metrics, so the list counts
what the report's tables count: missed is a collision run without a warning onset before
contact (not in recall); late is an onset less than LEAD_GOAL before contact (in recall,
not in recall@1s); a near miss warned is a near-miss run with any warned frame (the
table's "near-miss warned").

Lines of the people tracker add two (sim.analysis.person_by_person): a run where the
primary predictor warned for someone not on a collision course that frame (the wrong
person), or for a track paired with no one (a phantom); a run already listed for the
three says so after "also".
"""

from __future__ import annotations

import os
import shlex
from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sim.analysis.markdown import table
from sim.analysis.metrics import LEAD_GOAL, MAIN, RunOutcome, SweepMetrics, split_method
from sim.analysis.person_by_person import is_everyone, judge_run
from sim.runs.result import RunResult, values_said

MISSED, LATE, NEAR_MISS = "missed", "late", "near miss warned"
WHATS = (MISSED, LATE, NEAR_MISS)  # also the order of the list: the worst first
PER_FAMILY = 5  # runs listed per family; the others are counted
WRONG_PERSON, PHANTOM = "wrong person warned", "phantom warned"
SWEEP_WHATS = (*WHATS, WRONG_PERSON, PHANTOM)  # the sweep report's list, the worst first


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


@dataclass(frozen=True)
class PersonTrouble:
    """A people-tracker run's warnings for the wrong person or for nobody (one method)."""

    what: str  # WRONG_PERSON or PHANTOM
    how: str  # in words, naming whom
    frames: int


def person_trouble(row: RunResult, method: str) -> list[PersonTrouble]:
    """The wrong-person then phantom warnings of `method` on a people-tracker line; []
    for other lines and for runs without them."""
    v = judge_run(row, method) if is_everyone(row) else None
    if v is None:
        return []
    out = []
    if v.wrong_people:
        names = " and ".join(row.people[i].name for i in v.wrong_people)
        verb = "was" if len(v.wrong_people) == 1 else "were"
        how = f"warned for {names} who {verb} not on a collision course"
        out.append(PersonTrouble(WRONG_PERSON, how, v.wrong_person_frames))
    if v.phantom_frames:
        out.append(PersonTrouble(PHANTOM, "warned for nobody (a phantom)", v.phantom_frames))
    return out


def said_trouble(t: PersonTrouble) -> str:
    return f"{t.how} ({plural(t.frames, 'frame')})"


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


@dataclass(frozen=True)
class Listed:
    """One run in a list of runs to look at: its group (a family, a policy), what went
    wrong (one of the list's kinds) and how (in words), its values in words, the command
    that runs it again, what else went wrong in it, and its recording (the words the list
    says about it; None: nothing, the command makes one)."""

    id: str
    group: str
    what: str
    how: str
    values: str
    command: str
    also: tuple[str, ...] = ()
    recording: str | None = None


def listed_lines(
    listed: Sequence[Listed], whats: Sequence[str], runs: Mapping[str, int]
) -> list[str]:
    """Per group, in name order: what went wrong of how many runs (`runs` per group), its
    first PER_FAMILY runs as `listed` orders them (the worst first), the rest counted.
    The sweep's report, the closed loop's tables and the Euro NCAP report all list so."""
    lines: list[str] = []
    groups: dict[str, list[Listed]] = defaultdict(list)
    for item in listed:
        groups[item.group].append(item)
    for group, items in sorted(groups.items()):
        count = Counter(item.what for item in items)
        said = ", ".join(f"{count[w]} {w}" for w in whats if count[w])
        lines += [f"**{group}**: {said} of {plural(runs.get(group, 0), 'run')}", ""]
        for item in items[:PER_FAMILY]:
            tail = [f"also {', '.join(item.also)}"] if item.also else []
            tail += [item.recording] if item.recording else []
            lines += [
                f"- `{item.id}` ({item.values}): **{item.how}**" + "".join(f"; {t}" for t in tail),
                f"  `{item.command}`",
            ]
        rest = items[PER_FAMILY:]
        if rest:
            count = Counter(item.what for item in rest)
            more = ", ".join(f"{count[w]} {w}" for w in whats if count[w])
            lines.append(f"- and {len(rest)} more ({more})")
        lines.append("")
    return lines


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
    trouble = {r.id: person_trouble(r, first) for r in rows}
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
    if any(is_everyone(r) for r in rows):
        lines += [
            "With the people tracker, also the runs where it warned for someone not on a",
            "collision course that frame (wrong person warned) or for a track paired with no",
            "one (phantom warned), as the section person by person judges them.",
            "",
        ]
    if not wrong and not any(trouble.values()):
        people = ", none for the wrong person or nobody" if any(map(is_everyone, rows)) else ""
        lines += [
            f"None: {first} missed no collision, warned none late and no near miss{people}.",
            "",
        ]
    listed = []
    for o in wrong:
        row = by_id.get(o.id)  # the metrics' rows (a caller may pass none)
        also = [f"{x} {went_wrong(others[x][o.id])}" for x in others
                if went_wrong(others[x][o.id])]  # fmt: skip
        also += [said_trouble(t) for t in trouble.get(o.id, [])]
        link = where.link(row) if row else None
        listed.append(
            Listed(
                id=o.id,
                group=o.family,
                what=str(went_wrong(o)),
                how=how(o),
                values=values_said(row.params if row else {}),
                command=where.command(o.id, row.code if row else None),
                also=tuple(also),
                recording=f"recording {link or 'not kept'}",
            )
        )
    listed += _troubled(rows, trouble, {o.id for o in wrong}, others, where)
    runs = Counter(o.family for o in m.outcomes[first])
    lines += listed_lines(listed, SWEEP_WHATS, runs)
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


def _troubled(
    rows: Sequence[RunResult],
    trouble: Mapping[str, Sequence[PersonTrouble]],
    listed: set[str],
    others: Mapping[str, Mapping[str, RunOutcome]],
    where: Rerunning,
) -> list[Listed]:
    """Runs not listed for the three whose primary predictor warned for the wrong person
    or for nobody: wrong persons first, then by frames so warned, then by id."""
    found = [(r, trouble[r.id]) for r in rows if trouble.get(r.id) and r.id not in listed]
    found.sort(key=lambda f: (SWEEP_WHATS.index(f[1][0].what), -f[1][0].frames, f[0].id))
    out = []
    for row, troubles in found:
        also = [f"{x} {went_wrong(by[row.id])}" for x, by in others.items()
                if row.id in by and went_wrong(by[row.id])]  # fmt: skip
        link = where.link(row)
        out.append(
            Listed(
                id=row.id,
                group=row.family,
                what=troubles[0].what,
                how=said_trouble(troubles[0]),
                values=values_said(row.params),
                command=where.command(row.id, row.code),
                also=(*(said_trouble(t) for t in troubles[1:]), *also),
                recording=f"recording {link or 'not kept'}",
            )
        )
    return out


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


# -- closed-loop and Euro NCAP runs -----------------------------------------------------


def loop_triage_lines(
    rows: Sequence[dict[str, Any]], where: Rerunning, recorded: bool = False
) -> list[str]:
    """The closed loop's runs to look at (sim.runs.closed_loop.went_wrong: a braking
    policy's contacts and needless stops), per policy, each with its scenario, recording
    (`recorded`: the command kept recordings) and rerun command."""
    from sim.runs.closed_loop import CONTACT, WENT_WRONG, WRONG_PERSON, went_wrong
    from sim.runs.closed_loop_grid import outcome_of, source_said

    outcomes = [outcome_of(row) for row in rows]
    wrong = [
        (row, o, what)
        for row, o, what in zip(rows, outcomes, went_wrong(outcomes), strict=True)
        if what is not None
    ]
    wrong.sort(key=lambda w: (WENT_WRONG.index(w[2]), -(w[1].impact_speed or 0.0)))
    lines = [
        "## Runs to look at",
        "",
        "The runs where a braking policy still hit the pedestrian (contact) or braked although",
        "the same scenario without braking ended without contact (braked without need), per",
        f"policy, at most {PER_FAMILY} each, the worst first (contacts by impact speed), the "
        "rest counted.",
        "Each command runs its run again into a recording and checks that it gives the same",
        "outcome (a run made with the measured latency is replayed with the latency it",
        "measured on each frame); `monopic view FILE.rrd` opens a recording.",
        "",
    ]
    if not wrong:
        lines += ["None: no braking policy hit the pedestrian or braked without need.", ""]
    listed = []
    for row, o, what in wrong:
        how_ = (f"contact at {o.impact_speed:.2f} m/s" if what == CONTACT and o.impact_speed
                is not None else what)  # fmt: skip
        if what == WRONG_PERSON:
            how_ = o.braked_for_said() or what
        if what != CONTACT and o.brake_time is not None:
            how_ += f" (brake from {o.brake_time:.2f} s)"
        recording = None
        if recorded:
            path = Path(row.get("recording") or "")
            shown = _link(path.name, path, where.report) if path.name and path.is_file() else None
            recording = f"recording {shown or 'not kept'}"
        listed.append(
            Listed(
                id=row["id"],
                group=row["policy"],
                what=what,
                how=how_,
                values=source_said(row["source"]),
                command=where.command(row["id"], None),
                recording=recording,
            )
        )
    lines += listed_lines(listed, WENT_WRONG, Counter(row["policy"] for row in rows))
    return lines


def ncap_triage_lines(rows: Sequence[dict[str, Any]], where: Rerunning) -> list[str]:
    """The Euro NCAP grid's runs to look at: every run that hit the target (contact) and
    every near miss the car braked on (braked without need), per policy and test, each
    with its grid point and rerun command."""
    from sim.runs.closed_loop import CONTACT, NEEDLESS, WENT_WRONG, WRONG_PERSON
    from sim.runs.ncap_grid import NEAR_MISS, run_said
    from sim.world.warned_for import NOBODY, braked_wrong

    wrong = []
    for row in rows:
        o = row["outcome"]
        named = o.get("braked_for")
        if o["contact"]:
            wrong.append((row, CONTACT, -(o["relative_impact_speed"] or 0.0)))
        elif braked_wrong(named, o.get("braked_for_on_course")):
            wrong.append((row, WRONG_PERSON, o["brake_time"] or 0.0))
        elif row["role"] == NEAR_MISS and o["brake_time"] is not None:
            wrong.append((row, NEEDLESS, o["brake_time"]))
    wrong.sort(key=lambda w: (WENT_WRONG.index(w[1]), w[2]))
    lines = [
        "## Runs to look at",
        "",
        "The runs that hit the target (contact) and the car-scale near misses the car braked",
        f"on (braked without need), per policy and test, at most {PER_FAMILY} each, the worst "
        "first (contacts",
        "by relative impact speed), the rest counted. Each command runs its run again from the",
        "protocol and car files into a recording and checks that it gives the same outcome",
        "(run it from the folder the grid ran in: the rows name the files as the command was",
        "given them); `monopic view FILE.rrd` opens a recording.",
        "",
    ]
    if not wrong:
        lines += ["None: no run hit its target and no near miss braked.", ""]
    listed = []
    for row, what, _ in wrong:
        o = row["outcome"]
        if what == CONTACT:
            rel = o["relative_impact_speed"]
            said = f"contact at {3.6 * o['impact_speed']:.1f} km/h" if o["impact_speed"] else what
            said += f" ({3.6 * rel:.1f} km/h relative)" if rel is not None else ""
        elif what == WRONG_PERSON:
            track = o.get("braked_for_track")
            whom = o["braked_for"] if o["braked_for"] != NOBODY else "nobody (a phantom)"
            said = f"braked for {whom}" + (f" (track {track})" if track is not None else "")
            said += ", not on a collision course" if o["braked_for"] != NOBODY else ""
            said += f" (brake from {o['brake_time']:.2f} s)"
        else:
            said = f"{what} (brake from {o['brake_time']:.2f} s)"
        listed.append(
            Listed(
                id=row["id"],
                group=f"{row['policy']}, {row['test']}",
                what=what,
                how=said,
                values=run_said(row),
                command=where.command(row["id"], None),
            )
        )
    runs = Counter(f"{row['policy']}, {row['test']}" for row in rows)
    lines += listed_lines(listed, WENT_WRONG, runs)
    return lines
