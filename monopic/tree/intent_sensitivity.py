"""How much the ground intent tree gains over constant velocity as each cue changes.

What it answers: the gain against each cue's lead time and probability, and whether the
gain from body features (phi, head yaw) vanishes when the walker shows no body cue.
Rendering is the expensive part, so the cue settings are rendered once into a
dataset (`scenarios/datasets/intent-sensitivity.toml`) and every predictor is replayed
on the same pipeline features: constant velocity, and each tree given (typically the
full tree and one grown `--without phi --without phi_rate --without head_yaw`).

The warning is the pipeline's ground warning (the swept footprint); runs are counted as
the sweep's metrics count them (monopic.tree.intent_training.count_runs). The replay
never renders and never runs a tree on anything but the recorded features.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from monopic.errors import UserError
from monopic.output import atomic_path, write_text_atomically
from monopic.tree.intent import IntentTreeModel
from monopic.tree.intent_training import (
    RunCount,
    RunRows,
    WarningCount,
    count_runs,
    count_warnings,
    predicted_point,
    warned_frames,
)

CUE_KEYS = (
    "pedestrian.behaviour.head_check_probability",
    "pedestrian.behaviour.head_check_lead",
    "pedestrian.behaviour.stop_lead",
    "pedestrian.behaviour.turn_lead",
)
BODY_CUES_OFF = {
    "pedestrian.behaviour.head_check_probability": 0.0,
    "pedestrian.behaviour.turn_lead": 0.0,
}  # no head checks, no head and shoulders leading turns: only slowing remains
CONSTANT_VELOCITY = "constant velocity"
MAX_VALUES = 12  # a key with more distinct values is drawn from a range, not swept


@dataclass(frozen=True)
class Replayed:
    """One predictor's points on every row of the runs, and whether each row warned."""

    name: str
    points: tuple[tuple[float, float], ...]
    warned: tuple[bool, ...]


def replay(
    name: str, model: IntentTreeModel | None, runs: Sequence[RunRows], horizon: float
) -> Replayed:
    """The predictor's point on each recorded row (None: constant velocity)."""
    rows = [row for r in runs for row in r.rows]
    points = [predicted_point(model, row.sample, horizon) for row in rows]
    return Replayed(name, tuple(points), tuple(warned_frames(points, rows, horizon)))


@dataclass(frozen=True)
class Cell:
    """One predictor on one group of runs."""

    runs: RunCount
    median_error_m: float
    frames: WarningCount

    @property
    def recall_1s(self) -> float:
        return (
            self.runs.warned_1s / self.runs.collision_runs if self.runs.collision_runs else math.nan
        )

    @property
    def near_miss_share(self) -> float:
        r = self.runs
        return r.near_miss_warned / r.near_miss_runs if r.near_miss_runs else math.nan


def judge_group(replayed: Replayed, runs: Sequence[RunRows], chosen: Sequence[bool]) -> Cell:
    """The cell of the runs flagged in `chosen` (same order as `runs`)."""
    warned: list[bool] = []
    errors: list[float] = []
    picked: list[RunRows] = []
    k = 0
    for run, keep in zip(runs, chosen, strict=True):
        n = len(run.rows)
        if keep:
            picked.append(run)
            warned += replayed.warned[k : k + n]
            for point, row in zip(replayed.points[k : k + n], run.rows, strict=True):
                fx, fy = row.sample.future
                errors.append(math.hypot(point[0] - fx, point[1] - fy))
        k += n
    rows = [row for run in picked for row in run.rows]
    return Cell(
        count_runs(warned, picked),
        float(np.median(errors)) if errors else math.nan,
        count_warnings(warned, rows),
    )


@dataclass(frozen=True)
class Sensitivity:
    """Cells per swept cue value and predictor, and the body-cues-off comparison."""

    predictors: tuple[str, ...]
    by_value: dict[str, dict[float, dict[str, Cell]]]  # key -> value -> predictor -> cell
    body_off: dict[str, Cell]  # predictor -> cell on the runs without body cues
    body_on: dict[str, Cell]  # the same on the runs with some body cue
    runs: int


def sensitivity(
    runs: Sequence[RunRows],
    trees: Mapping[str, IntentTreeModel],
    keys: Sequence[str] = CUE_KEYS,
) -> Sensitivity:
    """Every predictor replayed on the runs; cells per value of each key."""
    horizons = {r.horizon for r in runs if r.rows}
    if len(horizons) != 1:
        raise UserError(f"the datasets' runs have different horizons {sorted(horizons)}")
    horizon = horizons.pop()
    for name, model in trees.items():
        if not math.isclose(model.horizon, horizon):
            raise UserError(
                f"--tree {name}: trained at a {model.horizon:g} s horizon, the data's is "
                f"{horizon:g} s"
            )
    replayed = [replay(CONSTANT_VELOCITY, None, runs, horizon)]
    replayed += [replay(name, model, runs, horizon) for name, model in trees.items()]
    by_value: dict[str, dict[float, dict[str, Cell]]] = {}
    for key in keys:
        values = sorted({v for r in runs if (v := r.number(key)) is not None})
        if not values:
            raise UserError(f"--by {key}: no run of the data sets it (see the runs' parameters)")
        if len(values) > MAX_VALUES:
            raise UserError(
                f"--by {key}: the runs take {len(values)} values of it (drawn from a range?); "
                f"give a key swept over at most {MAX_VALUES} values, e.g. the cue keys of "
                "scenarios/datasets/intent-sensitivity.toml"
            )
        by_value[key] = {
            value: {
                p.name: judge_group(p, runs, [r.number(key) == value for r in runs])
                for p in replayed
            }
            for value in values
        }
    off = [all(r.number(k) == v for k, v in BODY_CUES_OFF.items()) for r in runs]
    on = [not x for x in off]
    return Sensitivity(
        tuple(p.name for p in replayed),
        by_value,
        {p.name: judge_group(p, runs, off) for p in replayed},
        {p.name: judge_group(p, runs, on) for p in replayed},
        len(runs),
    )


def _fmt(cell: Cell) -> str:
    r = cell.runs
    parts = []
    if r.collision_runs:
        parts.append(f"{r.warned_1s}/{r.collision_runs}")
    if r.near_miss_runs:
        parts.append(f"NM {r.near_miss_warned}/{r.near_miss_runs}")
    parts.append(f"{cell.median_error_m:.2f} m")
    f = cell.frames
    parts.append(f"false {f.false_alarms}/{f.frames - f.collisions}")
    return ", ".join(parts)


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    return [
        "| " + " | ".join(header) + " |",
        "|" + "|".join("---" for _ in header) + "|",
        *("| " + " | ".join(row) + " |" for row in rows),
    ]


def report_lines(s: Sensitivity, sources: Sequence[str]) -> list[str]:
    """The Markdown report: per cue value, then body cues off against on."""
    lines = [
        "# Cue sensitivity of the ground intent tree",
        "",
        f"Replayed on {s.runs} runs of {', '.join(sources)} (`monopic tree sensitivity`). "
        "Cells: collision runs warned 1 s ahead / collision runs, near-miss runs warned "
        "(NM) / near-miss runs, the median error of the predicted point a horizon "
        "ahead, and frames warned with no contact ahead within the horizon (false) / such "
        "frames.",
        "",
        "![gain against each cue](sensitivity.png)",
        "",
    ]
    for key, values in s.by_value.items():
        lines += [f"## {key}", ""]
        lines += _table(
            ["value", *s.predictors],
            [[f"{v:g}", *(_fmt(cells[p]) for p in s.predictors)] for v, cells in values.items()],
        )
        lines.append("")
    lines += [
        "## Body cues off",
        "",
        "Runs without head checks and without head and shoulders leading turns (only the "
        "slowing before a stop remains) beside the runs with some body cue. A tree that "
        "reads body features may gain on the second group only; on the first, its gain over "
        "the same tree grown without them should vanish.",
        "",
    ]
    lines += _table(
        ["runs", *s.predictors],
        [
            ["body cues off", *(_fmt(s.body_off[p]) for p in s.predictors)],
            ["some body cue", *(_fmt(s.body_on[p]) for p in s.predictors)],
        ],
    )
    lines.append("")
    return lines


def plot(s: Sensitivity, path: Path) -> None:
    """One column per cue: near-miss runs warned, recall@1s and median error per value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(s.by_value)
    fig, axes = plt.subplots(3, len(keys), figsize=(4 * len(keys), 8.5), squeeze=False)
    rows: tuple[tuple[str, Any], ...] = (
        ("near-miss runs warned", lambda c: c.near_miss_share),
        ("recall@1s", lambda c: c.recall_1s),
        ("median error (m)", lambda c: c.median_error_m),
    )
    for col, key in enumerate(keys):
        values = list(s.by_value[key])
        for row, (label, get) in enumerate(rows):
            ax = axes[row][col]
            for p in s.predictors:
                ax.plot(values, [get(s.by_value[key][v][p]) for v in values], marker="o", label=p)
            ax.set_xticks(values)
            if row == 2:
                ax.set_xlabel(key.rsplit(".", 1)[-1])
            if col == 0:
                ax.set_ylabel(label)
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(f"Ground intent tree against constant velocity, {s.runs} replayed runs")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90)
    plt.close(fig)


def write(s: Sensitivity, out_dir: Path, sources: Sequence[str]) -> Path:
    """report.md and sensitivity.png into out_dir; the Markdown last (whole or not at all)."""
    plot(s, out_dir / "sensitivity.png")
    markdown = out_dir / "report.md"
    write_text_atomically(markdown, "\n".join(report_lines(s, sources)))
    return markdown
