"""Two sweeps side by side: the same families and methods, one walker setting against another.

For comparing one walker setting with another: the medium sweep with `human` walkers
beside the `rail` one, or cue-bearing walkers beside cue-free ones; both are two results
files of the same families, settings and seeds. Each cell reads "this sweep / the
other", from the same metrics the report gives each sweep alone (sim.analysis.metrics),
so no figure is computed twice.
"""

from __future__ import annotations

from collections.abc import Sequence

from sim.analysis.markdown import table
from sim.analysis.metrics import LEAD_GOAL, SweepMetrics, WarningSummary, wilson

COLUMNS = (
    "runs", "collision runs", f"recall@{LEAD_GOAL:g}s [low]", "lead p50",
    "near misses warned", "nuisance warnings / h", "flicker",
)  # fmt: skip


def _cells(s: WarningSummary | None) -> list[str]:
    if s is None:
        return ["-"] * len(COLUMNS)
    recall = (
        f"{100 * s.recall_1s:.0f} % [{100 * wilson(s.warned_1s, s.collision_runs)[0]:.0f}]"
        if s.collision_runs
        else "-"
    )
    return [
        str(s.runs),
        str(s.collision_runs),
        recall,
        f"{s.lead_p50:.2f} s" if s.leads else "-",
        f"{s.near_miss_warned}/{s.near_miss_runs}" if s.near_miss_runs else "-",
        f"{s.nuisance_per_hour:.0f}" if s.clear_seconds else "-",
        f"{100 * s.flicker_share:.0f} %" if s.episodes else "-",
    ]


def _pair(a: WarningSummary | None, b: WarningSummary | None) -> list[str]:
    return [f"{x} / {y}" for x, y in zip(_cells(a), _cells(b), strict=True)]


def beside_rows(
    a: SweepMetrics, b: SweepMetrics, methods: Sequence[str], by_family: bool
) -> list[list[str]]:
    """Rows of (family,) method, then each column as 'a / b'; methods only one sweep ran
    are left out, families only one sweep holds show '-' on the other side."""
    shared = [m for m in methods if m in a.overall and m in b.overall]
    if not by_family:
        return [[m, *_pair(a.overall[m], b.overall[m])] for m in shared]
    families = list(a.families) + [f for f in b.families if f not in a.families]
    return [
        [f, m, *_pair(a.by_family[m].get(f), b.by_family[m].get(f))]
        for f in families
        for m in shared
    ]


def beside_lines(
    a: SweepMetrics, b: SweepMetrics, name_a: str, name_b: str, methods: Sequence[str]
) -> list[str]:
    """The report's section for `a` beside `b`: per method, then per family and method."""

    head = [f"{c} ({name_a} / {name_b})" if k == 0 else c for k, c in enumerate(COLUMNS)]
    return [
        f"## Beside {name_b}",
        "",
        f"Each cell: this sweep ({name_a}) / the other ({name_b}), from the same metrics as",
        "the tables above (recall@1s with its 95 % Wilson lower bound in brackets; nuisance",
        "warnings per hour of pedestrian time off any collision course; flicker: warnings",
        "back within a second of ending, as a share of warning episodes).",
        "",
        *table(["method", *head], beside_rows(a, b, methods, by_family=False)),
        "",
        "Per family:",
        "",
        *table(["family", "method", *head], beside_rows(a, b, methods, by_family=True)),
        "",
    ]
