"""The sweep report: a Markdown file with PNG plots, and the headline table for the terminal.

Tables come from sim.analysis.metrics; plots from sim.analysis.plots. Every file is written under a
temporary name and renamed when complete, the Markdown last, so a report directory
never holds a half-written report.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from monopic.cases import Case
from monopic.output import write_text_atomically
from sim.analysis import plots
from sim.analysis.beside import beside_lines
from sim.analysis.markdown import num, pct, table
from sim.analysis.metrics import (
    ABLATION,
    FLICKER_S,
    LEAD_GOAL,
    MAIN,
    TIMELY_TTC,
    CaseSummary,
    SweepMetrics,
    WarningSummary,
    paired_by_family,
    split_method,
)
from sim.analysis.people import summarise_people
from sim.analysis.person_by_person import is_everyone
from sim.analysis.person_report import person_by_person_lines
from sim.analysis.triage import Rerunning, triage_lines
from sim.runs.result import RunResult


def said(cases: CaseSummary) -> str:
    """'7 toward (94 %)': the case a method answers most, with its share."""
    most = cases.most_predicted
    return "-" if most is None else f"{int(most[0])} {most[0].label} ({pct(most[1])})"


HEADLINE = (
    "method", "runs", "coll.", "recall [low]", f"rec@{LEAD_GOAL:g}s [low]",
    f"TTC>={TIMELY_TTC:g}s car", "+latency", "lead p50", "fr.recall", "precision", "FA rate",
    "near-miss warned", "case acc", "px err",
)  # fmt: skip


def _recall(s: WarningSummary, count: int, low: float) -> str:
    if not s.collision_runs:
        return "-"
    return f"{pct(count / s.collision_runs)} [{pct(low)}]"


def headline_rows(m: SweepMetrics, methods: Sequence[str] | None = None) -> list[list[str]]:
    rows = []
    for method in methods or m.methods:
        s = m.overall[method]
        car = m.by_scale[method].get("car")
        rows.append(
            [
                method,
                str(s.runs),
                str(s.collision_runs),
                _recall(s, s.warned, s.recall_low),
                _recall(s, s.warned_1s, s.recall_1s_low),
                pct(car.timely_share) if car else "-",
                pct(s.recall_latency),
                f"{num(s.lead_p50)} s" if s.leads else "-",
                pct(s.frames.recall),
                pct(s.frames.precision),
                pct(s.frames.false_alarm_rate),
                f"{s.near_miss_warned}/{s.near_miss_runs}" if s.near_miss_runs else "-",
                pct(m.cases[method].accuracy),
                num(m.positions[method].px_percentile(50), 0),
            ]
        )
    return rows


def headline(m: SweepMetrics) -> str:
    """The terminal table: every method of the main pipeline, then the ablation's."""
    return "\n".join(table(HEADLINE, headline_rows(m)))


def ran_on(m: SweepMetrics) -> str:
    return (
        f"{m.rows} runs in {len(m.families)} families, {m.seeds} seeds, frames "
        f"{', '.join(m.frame_sizes)}, on {', '.join(m.machines) or 'an unknown machine'}, "
        + (f"code {m.codes[0]}" if len(m.codes) == 1 else f"MIXED code {', '.join(m.codes)}")
    )


@dataclass(frozen=True)
class Report:
    markdown: Path
    plots: tuple[Path, ...]
    headline: str


def group_rows(
    groups: dict[str, dict[Any, WarningSummary]],
    methods: Sequence[str],
    label: Callable[[Any], str],
) -> list[list[str]]:
    """Per group (a walker model, a lighting preset...), per method: what a safety engineer
    asks first."""
    rows = []
    keys = sorted({g for method in methods for g in groups.get(method, {})})
    for key in keys:
        for method in methods:
            s = groups[method].get(key)
            if s is None:
                continue
            rows.append(
                [
                    label(key),
                    method,
                    str(s.runs),
                    _recall(s, s.warned_1s, s.recall_1s_low),
                    f"{num(s.lead_p50)} s" if s.leads else "-",
                    f"{s.near_miss_warned}/{s.near_miss_runs}" if s.near_miss_runs else "-",
                    f"{s.nuisance_per_hour:.0f} ({s.nuisance_onsets} in {s.clear_seconds:.0f} s)"
                    if s.clear_seconds
                    else "-",
                    f"{pct(s.flicker_share)} ({s.flickers}/{s.episodes})" if s.episodes else "-",
                ]
            )
    return rows


GROUP_COLUMNS = (
    "method",
    "runs",
    f"recall@{LEAD_GOAL:g}s",
    "lead p50",
    "near misses warned",
    "nuisance warnings / h",
    "flicker",
)


def family_goal_rows(m: SweepMetrics, methods: Sequence[str]) -> list[list[str]]:
    """Per family: recall@1s and its lower bound (collision runs), near misses warned."""
    rows = []
    for family in m.families:
        cells = [family]
        for method in methods:
            s = m.by_family[method].get(family)
            if s is None:
                cells.append("-")
                continue
            parts = []
            if s.collision_runs:
                parts.append(f"{pct(s.recall_1s)} [{pct(s.recall_1s_low)}] n={s.collision_runs}")
            if s.near_miss_runs:
                parts.append(f"NM {s.near_miss_warned}/{s.near_miss_runs}")
            if not parts:
                parts.append(f"no collision ({s.other_warned}/{s.other_runs} warned)")
            cells.append("; ".join(parts))
        rows.append(cells)
    return rows


BASELINE = "constant-velocity/ground"
PAIRED = ("intent-tree/ground", "rules/ground")  # ground methods judged against BASELINE


def paired_lines(m: SweepMetrics) -> list[str]:
    """Each ground method beside constant velocity on the same runs, per family."""
    if BASELINE not in m.outcomes:
        return []
    lines = []
    for method in (x for x in PAIRED if x in m.outcomes):
        rows = []
        for family, p in paired_by_family(m, method, BASELINE).items():
            recall = nm = "-"
            if p.collision_runs:
                n = p.collision_runs
                recall = (
                    f"{p.warned_1s[0]}/{n} vs {p.warned_1s[1]}/{n}: "
                    f"{p.difference * 100:+.0f} [{p.low * 100:+.0f}, {p.high * 100:+.0f}]"
                )
            if p.near_miss_runs:
                nm = f"{p.near_miss_warned[0]} vs {p.near_miss_warned[1]} of {p.near_miss_runs}"
            rows.append([family, recall, nm])
        lines += [
            f"### {method} beside {BASELINE}",
            "",
            *table(
                [
                    "family",
                    f"recall@{LEAD_GOAL:g}s: difference, points [95 %]",
                    "near-miss runs warned",
                ],
                rows,
            ),
            "",
        ]
    if not lines:
        return []
    return [
        "## Paired beside constant velocity",
        "",
        f"The same rendered runs judged by each method: collision runs warned {LEAD_GOAL:g} s "
        "ahead by the method and by constant velocity, the difference in points with its 95 % "
        "interval for paired data (Newcombe 1998, method 10: it allows for both methods "
        "finding the same runs hard), and near-miss runs warned by each. With 16 runs a "
        "family the interval spans about +-12 points even when both warn the same runs.",
        "",
        *lines,
    ]


def ablation_rows(m: SweepMetrics) -> list[list[str]]:
    """Real pose vs the ground-truth crop, per predictor: what the pose stage costs."""
    rows = []
    for method in m.methods:
        pipeline, key = split_method(method)
        if pipeline != MAIN:
            continue
        crop = f"{ABLATION}:{key}"
        if crop not in m.overall:
            continue
        a, b = m.overall[method], m.overall[crop]
        rows.append(
            [
                key,
                pct(a.recall_1s),
                pct(b.recall_1s),
                pct(a.frames.recall),
                pct(b.frames.recall),
                pct(a.frames.false_alarm_rate),
                pct(b.frames.false_alarm_rate),
                pct(m.cases[method].accuracy),
                pct(m.cases[crop].accuracy),
            ]
        )
    return rows


def goal_lines(m: SweepMetrics) -> list[str]:
    """How far each main method is from the issue's goal over the NCAP-style families."""
    out = []
    for method in m.methods:
        if split_method(method)[0] != MAIN:
            continue
        case_families = {o.family for o in m.outcomes[method] if o.kind == "case"}
        fams = {f: s for f, s in m.by_family[method].items() if f not in case_families}
        collision = {f: s for f, s in fams.items() if s.collision_runs}
        near = {f: s for f, s in fams.items() if s.near_miss_runs}
        met = sum(s.recall_1s_low >= 0.95 for s in collision.values())
        worst = min(collision.items(), key=lambda kv: kv[1].recall_1s_low, default=None)
        nm_bad = sum(s.near_miss_warned_share > 0.05 for s in near.values())
        text = (
            f"- **{method}**: recall@1s lower bound >= 0.95 in {met} of {len(collision)} families"
        )
        if worst:
            text += f" (worst {worst[0]}: {pct(worst[1].recall_1s_low)})"
        text += f"; near-miss families warned above 5 %: {nm_bad} of {len(near)}"
        out.append(text + ".")
    return out


def runs(n: int) -> str:
    return f"{n} run" if n == 1 else f"{n} runs"


def sweeps_line(rows: Sequence[RunResult]) -> str:
    """Which sweep(s) the file's runs came from: a file written by two sweeps is named as
    such, so the counts below are not mistaken for one sweep's."""
    count = Counter(r.sweep or "unnamed" for r in rows)
    if len(count) == 1:
        ((name, n),) = count.items()
        return f"Sweep: `{name}`, {runs(n)}."
    names = ", ".join(f"`{name}` ({runs(n)})" for name, n in count.most_common())
    return f"Runs of {len(count)} sweeps, counted together below: {names}."


def write_report(
    m: SweepMetrics,
    rows: Sequence[RunResult],
    results: Path,
    out_dir: Path,
    beside: tuple[str, SweepMetrics] | None = None,
) -> Report:
    """Write report.md and its plots into out_dir (created); returns what was written.
    `beside` (a name and another sweep's metrics) adds that sweep's figures cell by cell."""
    out_dir.mkdir(parents=True, exist_ok=True)
    footer = ran_on(m)
    main_methods = [x for x in m.methods if split_method(x)[0] == MAIN]
    written = plots.write_all(m, rows, out_dir, footer, main_methods)
    lines = [
        f"# Sweep report: {results.name}",
        "",
        f"Ran on: {footer}. Results: `{results}`.",
        "",
        sweeps_line(rows),
        "",
        "Collision warning per run and per frame. Recall counts collision runs warned before",
        f"contact (95 % Wilson lower bound in brackets); recall@{LEAD_GOAL:g}s only warnings at",
        f"least {LEAD_GOAL:g} s before contact; TTC>={TIMELY_TTC:g}s is the share of car-scale",
        "collision runs warned that early (Euro NCAP's timely warning); recall+latency applies",
        "the measured per-frame latency on a real-time single-core pipeline. Frame metrics",
        "judge each frame against contact within the horizon. `gtcrop:` rows are the ablation:",
        "the same predictors fed the ground-truth crop instead of the pose found in the pixels.",
        "",
        *table(HEADLINE, headline_rows(m)),
        "",
        "## The goal: per family",
        "",
        f"Goal: recall@{LEAD_GOAL:g}s lower bound >= 95 % per family and <= 5 % of near-miss runs",
        "warned. Cells: recall@1s [95 % lower bound] n=collision runs; NM warned/near-miss runs.",
        "",
        *table(["family", *main_methods], family_goal_rows(m, main_methods)),
        "",
        *goal_lines(m),
        "",
        *paired_lines(m),
        *triage_lines(m, rows, Rerunning.of(results, out_dir)),
        "## By pedestrian behaviour and intent cues",
        "",
        "Walker model (`rail`: the Euro NCAP target; `human`: sim/scenario/walkers/human.py) and",
        "whether it showed intent cues (head checks, head and shoulders leading turns, slowing",
        "before a stop). Nuisance warnings: warning onsets while no contact is ahead at all, per",
        "hour of such time with the pedestrian in view. Flicker: warnings that come back within",
        f"{FLICKER_S:g} s of ending, as a share of warning episodes.",
        "",
        *table(
            ["walker", *GROUP_COLUMNS],
            group_rows(m.by_behaviour, main_methods, lambda g: f"{g[0]}, {g[1]}"),
        ),
        "",
        "## By lighting",
        "",
        "The lighting preset of each run (sim/scenario/lighting.py; a file that moves the sun",
        "keeps its preset's name). Columns as above.",
        "",
        *table(["lighting", *GROUP_COLUMNS], group_rows(m.by_lighting, main_methods, str)),
        "",
        *people_lines(rows, main_methods),
        *person_by_person_lines(rows, main_methods),
        "## Ablation: real pose vs ground-truth crop",
        "",
        "The gap between the columns is what the pose stage costs; what remains with the true",
        "crop is the decision stage (features, case, prediction, zone).",
        "",
        *table(
            [
                "predictor",
                "recall@1s",
                "gtcrop",
                "frame recall",
                "gtcrop",
                "false alarms",
                "gtcrop",
                "case acc.",
                "gtcrop",
            ],
            ablation_rows(m),
        ),  # fmt: skip
        "",
        f"## Recall@{LEAD_GOAL:g}s by robot speed and by case",
        "",
        f"Collision runs warned at least {LEAD_GOAL:g} s before contact (warned/collision runs).",
        "",
        *table(
            ["robot speed (m/s)", *main_methods],
            [
                [f"{speed:g}"] + [_cell(m.by_speed[x].get(speed)) for x in main_methods]
                for speed in sorted(m.by_speed[main_methods[0]])
            ],
        ),
        "",
        *table(
            ["case", *main_methods],
            [
                [f"{case} {Case(case).label}"]
                + [_cell(m.by_case[x].get(case)) for x in main_methods]
                for case in sorted(m.by_case[main_methods[0]])
            ],
        ),
        "",
        "![recall by robot speed](recall_by_speed.png)",
        "",
        "![recall by distance](recall_by_distance.png)",
        "",
        "## Lead time",
        "",
        "![lead time](lead_time.png)",
        "",
        "## Cases, facing angle, positions",
        "",
        "Case accuracy against the ground-truth case of the next second of motion; confusion",
        "matrices are row-normalised (rows: true case). 'Most often said' is the case a",
        "method answers most and its share of its decisions: a method that gives one answer",
        "whatever the truth scores low accuracy however well it places the point.",
        "",
        "![confusion](confusion.png)",
        "",
        *table(
            [
                "method",
                "decided frames",
                "case acc.",
                "most often said",
                "px err p50",
                "px err p90",
                "m err p50",
                "m err p90",
            ],
            [
                [
                    x,
                    str(m.cases[x].frames),
                    pct(m.cases[x].accuracy),
                    said(m.cases[x]),
                    num(m.positions[x].px_percentile(50), 0),
                    num(m.positions[x].px_percentile(90), 0),
                    num(m.positions[x].m_percentile(50)),
                    num(m.positions[x].m_percentile(90)),
                ]
                for x in m.methods
            ],
        ),  # fmt: skip
        "",
        *_intent_table(m),
        "Position error at the real horizon: the predicted foot point against the true foot",
        "point one horizon later (pixels), and the predicted ground point against the true",
        "future position in the robot's frame (metres, ground mode only).",
        "",
        "![accuracy against error radius](accuracy_vs_radius.png)",
        "",
        *table(
            ["pipeline", "frames", "phi MAE (deg)", "correlation"],
            [[p, str(s.frames), num(s.mae, 1), num(s.correlation)] for p, s in m.phi.items()],
        ),
        "",
        "![phi](phi.png)",
        "",
        "## Pose found",
        "",
        "Share of frames with a pose among frames where at least half the landmarks are in",
        "view and unoccluded.",
        "",
        *_found_tables(m),
        "![pose found](found_share.png)",
        "",
        "## Latency per stage (ms)",
        "",
        *table(
            ["pipeline", "stage", "p50", "p95"],
            [
                [p, stage, num(s.p50[stage], 1), num(s.p95[stage], 1)]
                for p, s in m.latency.items()
                for stage in s.p50
            ],
        ),
        "",
    ]
    if beside is not None:
        lines += beside_lines(m, beside[1], results.stem, beside[0], main_methods)
    markdown = out_dir / "report.md"
    write_text_atomically(markdown, "\n".join(lines))
    return Report(markdown, tuple(written), headline(m))


def people_lines(rows: Sequence[RunResult], methods: Sequence[str]) -> list[str]:
    """Runs with several people: each warning set against the person it was for
    (sim/analysis/people.py), per family; nothing when every run has one person. Lines of
    the people tracker are judged person by person instead (person_by_person_lines)."""
    crowded = [r for r in rows if r.people and not is_everyone(r)]
    if not crowded:
        return []
    body = []
    for family in sorted({r.family for r in crowded}):
        mine = [r for r in crowded if r.family == family]
        for method in methods:
            s = summarise_people(mine, method)
            body.append([
                family, method, str(s.runs),
                f"{s.warned_1s}/{s.threat_runs}" if s.threat_runs else "-",
                f"{s.near_misses_warned}/{s.near_misses}" if s.near_misses else "-",
                f"{pct(s.wrong_share)} ({s.wrong_person}/{s.for_threat + s.wrong_person})"
                if s.for_threat + s.wrong_person else "-",
                str(s.runs_wrong_person), str(s.unattributed),
            ])  # fmt: skip
    return [
        "## Several people: whose warning",
        "",
        f"{runs(len(crowded))} with several people. Each warned frame is set against the person",
        "the pipeline looked at (the person whose box holds its foot point; sim/analysis/",
        "people.py): a warning for someone not on a collision course within the horizon is",
        f"one for the wrong person. Recall@{LEAD_GOAL:g}s here is of anyone's first threat.",
        "",
        *table(
            [
                "family",
                "method",
                "runs",
                f"warned {LEAD_GOAL:g} s ahead",
                "near misses warned",
                "wrong-person warnings",
                "runs with one",
                "unattributed frames",
            ],
            body,
        ),  # fmt: skip
        "",
    ]


def _cell(s: WarningSummary | None) -> str:
    if s is None or not s.collision_runs:
        return "-"
    return f"{pct(s.recall_1s)} ({s.warned_1s}/{s.collision_runs})"


def _found_tables(m: SweepMetrics) -> list[str]:
    out: list[str] = []
    for pipeline, shares in m.found.items():
        for share in shares:
            edges = share.edges
            labels = [
                f"{edges[i]:g}-{edges[i + 1]:g}" if edges[i + 1] < 1e8 else f">={edges[i]:g}"
                for i in range(len(edges) - 1)
            ]
            out += table(
                [f"{pipeline}: {share.label}", *labels],
                [["found", *(pct(v) for v in share.shares())], ["frames", *map(str, share.seen)]],
            )
            out.append("")
    return out


def _intent_table(m: SweepMetrics) -> list[str]:
    """Intent and case accuracy of predictors stating an intent, on all frames and in the
    1.5 s before each change of the true intent, beside the current-velocity baseline."""
    if not m.intents:
        return []
    rows = []
    for x, s in m.intents.items():
        rows.append(
            [
                x,
                str(s.intent.frames),
                pct(s.intent.accuracy),
                pct(s.intent.before_accuracy),
                pct(s.case.accuracy),
                pct(s.case.before_accuracy),
                pct(s.baseline_case.accuracy),
                pct(s.baseline_case.before_accuracy),
                str(s.intent.before_frames),
                pct(s.differing_share),
                f"{num(s.error_m)} / {num(s.cv_error_m)}",
            ]
        )
    return [
        "Intent (predictors that state one): accuracy on the frames they decided, and on "
        "those in the 1.5 s before a change of the true intent; the baseline answers the "
        "case of the true velocity now on the same frames. 'differs': the share of frames "
        "where its ground point is more than 5 cm from constant velocity's, and the median "
        "error (m) of each on those frames (it / constant velocity).",
        "",
        *table(
            [
                "method",
                "frames",
                "intent acc.",
                "before change",
                "case acc.",
                "before change",
                "baseline case acc.",
                "before change",
                "frames before",
                "differs",
                "m err there",
            ],
            rows,
        ),  # fmt: skip
        "",
    ]
