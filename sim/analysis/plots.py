"""PNG plots of sweep metrics (matplotlib's Agg canvas, no pyplot state).

Each figure carries a footer saying what it ran on (runs, seeds, frame size, machine),
and is written under a temporary name then renamed.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from monopic.cases import Case
from monopic.output import atomic_path
from sim.analysis.metrics import (
    LEAD_GOAL,
    MAIN,
    RADII,
    TIMELY_TTC,
    SweepMetrics,
    recall_by_range,
    split_method,
    wilson,
)
from sim.runs.result import RunResult

# One colour per predictor and mode (matplotlib's tab10), so the histograms and bars, which
# have no line style to tell image from ground mode, keep them apart too.
COLOURS = {
    "rules/image": "#1f77b4",
    "rules/ground": "#9467bd",
    "tree/image": "#ff7f0e",
    "tree/ground": "#8c564b",
    "constant-velocity/image": "#2ca02c",
    "constant-velocity/ground": "#d62728",
}
OTHER_COLOURS = ("#e377c2", "#17becf", "#bcbd22", "#7f7f7f")  # other predictors, by name
DPI = 110


def colour(key: str) -> str:
    """The fixed colour of a predictor key ("rules/image"); another predictor's is stable."""
    return COLOURS.get(key) or OTHER_COLOURS[zlib.crc32(key.encode()) % len(OTHER_COLOURS)]


def style(method: str) -> dict[str, object]:
    """Colour by predictor and mode, dashes for ground mode, thin dotted for the ablation."""
    pipeline, key = split_method(method)
    mode = key.partition("/")[2]
    out: dict[str, object] = {
        "color": colour(key),
        "linestyle": "--" if mode == "ground" else "-",
        "linewidth": 2.0,
        "label": method,
    }
    if pipeline != MAIN:
        out.update(linestyle=":", linewidth=1.4, alpha=0.8)
    return out


def _legend(ax: object, **kw: object) -> None:
    """A legend only when something is labelled (an empty one only warns)."""
    if ax.get_legend_handles_labels()[0]:  # type: ignore[attr-defined]
        ax.legend(**kw)  # type: ignore[attr-defined]


def _save(fig: Figure, path: Path, footer: str) -> Path:
    fig.text(0.01, 0.005, footer, fontsize=7, color="#555555", ha="left", va="bottom")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=DPI)
    return path


def accuracy_vs_radius(m: SweepMetrics, path: Path, footer: str) -> Path:
    fig = Figure(figsize=(8, 5), layout="constrained")
    ax = fig.add_subplot()
    for method in m.methods:
        acc = m.positions[method].accuracy_within(RADII)
        if np.all(np.isnan(acc)):
            continue
        ax.plot(RADII, 100 * acc, **style(method))
    ax.set_xlabel("error radius at the horizon (px)")
    ax.set_ylabel("predictions within the radius (%)")
    ax.set_title("Accuracy against error radius (foot point at the real horizon)")
    ax.set_ylim(0, 100)
    ax.set_xlim(0, RADII[-1])
    ax.grid(alpha=0.3)
    _legend(ax, fontsize=7, ncol=2, loc="lower right")
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def confusion(m: SweepMetrics, path: Path, footer: str, methods: Sequence[str]) -> Path:
    cols = 3
    rows = math.ceil(len(methods) / cols)
    fig = Figure(figsize=(4.4 * cols, 4.2 * rows + 0.4), layout="constrained")
    labels = [str(c.value) for c in Case]
    for i, method in enumerate(methods):
        ax = fig.add_subplot(rows, cols, i + 1)
        counts = m.cases[method].confusion
        totals = counts.sum(axis=1, keepdims=True)
        norm = np.divide(counts, totals, out=np.zeros(counts.shape), where=totals > 0)
        ax.imshow(norm, vmin=0, vmax=1, cmap="Blues")
        for r in range(9):
            for c in range(9):
                if counts[r, c]:
                    ax.text(
                        c, r, str(counts[r, c]), ha="center", va="center", fontsize=6,
                        color="white" if norm[r, c] > 0.6 else "black",
                    )  # fmt: skip
        ax.set_xticks(range(9), labels)
        ax.set_yticks(range(9), labels)
        ax.set_xlabel("predicted case")
        ax.set_ylabel("true case")
        ax.set_title(f"{method}: {100 * m.cases[method].accuracy:.0f} % of "
                     f"{m.cases[method].frames} frames", fontsize=9)  # fmt: skip
    fig.suptitle(
        "Case confusion (rows normalised; numbers are frame counts)\n"
        "1/2 oblique right/left away, 3/4 oblique right/left toward, "
        "5/6 perpendicular right/left, 7 toward, 8 away, 9 still",
        fontsize=10,
    )
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def lead_time(m: SweepMetrics, path: Path, footer: str, methods: Sequence[str]) -> Path:
    """Top: a histogram per method; bottom: share of collision runs warned at least x s ahead."""
    fig = Figure(figsize=(3.0 * len(methods), 7.5), layout="constrained")
    grid = fig.add_gridspec(2, len(methods), height_ratios=(1, 1.3))
    leads = [m.overall[x].leads for x in methods]
    top = max((max(v) for v in leads if v), default=3.0)
    bins = np.arange(0.0, top + 0.25, 0.25)
    first = None
    for i, (method, values) in enumerate(zip(methods, leads, strict=True)):
        ax = fig.add_subplot(grid[0, i], sharey=first)
        first = first or ax
        s = m.overall[method]
        ax.hist(values, bins=bins, color=style(method)["color"], alpha=0.8)
        for x in (LEAD_GOAL, TIMELY_TTC):
            ax.axvline(x, color="#444444", linewidth=1, linestyle=":")
        ax.set_title(f"{method}\n{s.warned}/{s.collision_runs} warned", fontsize=9)
        ax.set_xlabel("lead time (s)", fontsize=8)
        if i == 0:
            ax.set_ylabel("collision runs")
        ax.grid(alpha=0.3)
    ax = fig.add_subplot(grid[1, :])
    xs = np.linspace(0.0, max(top, TIMELY_TTC) + 0.25, 200)
    for method in methods:
        s = m.overall[method]
        if not s.collision_runs:
            continue
        values = np.asarray(s.leads)
        ax.plot(xs, [100 * (values >= x).sum() / s.collision_runs for x in xs], **style(method))
    for x, text in ((LEAD_GOAL, f"{LEAD_GOAL:g} s goal"), (TIMELY_TTC, f"{TIMELY_TTC:g} s NCAP")):
        ax.axvline(x, color="#444444", linewidth=1, linestyle=":")
        ax.text(x, 3, f" {text}", fontsize=8)
    ax.set_xlabel("lead time x: contact - first warning (s)")
    ax.set_ylabel("collision runs warned at least x ahead (%)")
    ax.set_ylim(0, 102)
    ax.grid(alpha=0.3)
    _legend(ax, fontsize=8, loc="upper right")
    fig.suptitle("Lead time of the first warning before contact")
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def recall_by_distance(
    m: SweepMetrics, rows: Sequence[RunResult], path: Path, footer: str, methods: Sequence[str]
) -> Path:
    fig = Figure(figsize=(8, 5), layout="constrained")
    ax = fig.add_subplot()
    counts = None
    for method in methods:
        edges, pos, hit = recall_by_range(rows, method)
        centres = [i for i, n in enumerate(pos) if n]
        ax.plot(centres, [100 * hit[i] / pos[i] for i in centres], marker="o", **style(method))
        counts = pos
    labels = [
        f"{edges[i]:g}-{edges[i + 1]:g}" if edges[i + 1] < 1e8 else f">{edges[i]:g}"
        for i in range(len(edges) - 1)
    ]
    if counts is not None:
        labels = [f"{lab}\nn={n}" for lab, n in zip(labels, counts, strict=True)]
    ax.set_xticks(range(len(labels)), labels, fontsize=8)
    ax.set_xlabel("true distance to the pedestrian (m); n = frames with contact within the horizon")
    ax.set_ylabel("frame recall (%)")
    ax.set_ylim(-2, 102)
    ax.set_title("Frame recall by distance (frames with contact ahead within the horizon)")
    ax.grid(alpha=0.3)
    _legend(ax, fontsize=7)
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def recall_by_speed(m: SweepMetrics, path: Path, footer: str, methods: Sequence[str]) -> Path:
    """Recall with the goal's lead (warned >= 1 s before contact) by robot speed, per scale."""
    scales = sorted({o.scale for o in m.outcomes[methods[0]] if o.collision_run})
    fig = Figure(figsize=(6.5 * max(len(scales), 1), 5.4), layout="constrained")
    width = 0.8 / len(methods)
    for j, scale in enumerate(scales):
        ax = fig.add_subplot(1, len(scales), j + 1)
        speeds = sorted(
            {round(o.robot_speed, 2) for o in m.outcomes[methods[0]]
             if o.scale == scale and o.collision_run}
        )  # fmt: skip
        counts = []
        for i, method in enumerate(methods):
            xs, ys, lo, hi = [], [], [], []
            for k, speed in enumerate(speeds):
                runs = [
                    o for o in m.outcomes[method]
                    if o.scale == scale and round(o.robot_speed, 2) == speed and o.collision_run
                ]  # fmt: skip
                warned = sum(o.lead is not None and o.lead >= LEAD_GOAL for o in runs)
                low, high = wilson(warned, len(runs))
                p = warned / len(runs)
                xs.append(k + (i - (len(methods) - 1) / 2) * width)
                ys.append(100 * p)
                lo.append(max(0.0, 100 * (p - low)))
                hi.append(max(0.0, 100 * (high - p)))
                if i == 0:
                    counts.append(len(runs))
            st = style(method)
            ground = "ground" in method
            ax.bar(
                xs, ys, width=width, color=st["color"], alpha=0.45 if ground else 0.85,
                hatch="//" if ground else None, label=method,
            )  # fmt: skip
            ax.errorbar(xs, ys, yerr=[lo, hi], fmt="none", ecolor="#333333", capsize=2, lw=0.8)
        ticks = [f"{s:g}\nn={n}" for s, n in zip(speeds, counts, strict=True)]
        ax.set_xticks(range(len(speeds)), ticks)
        ax.set_xlabel("robot speed (m/s); n = collision runs")
        ax.set_ylabel(f"collision runs warned >= {LEAD_GOAL:g} s before contact (%)")
        ax.set_ylim(0, 128)  # room for the legend above the bars
        ax.set_yticks(range(0, 101, 20))
        ax.set_title(f"{scale} scale", fontsize=10)
        ax.grid(alpha=0.3, axis="y")
        _legend(ax, fontsize=8, ncol=3, loc="upper center")
    fig.suptitle(
        f"Recall at {LEAD_GOAL:g} s lead by robot speed (95 % Wilson interval)", fontsize=11
    )
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def phi(m: SweepMetrics, path: Path, footer: str) -> Path:
    fig = Figure(figsize=(5.2 * len(m.phi), 5), layout="constrained")
    for i, (pipeline, s) in enumerate(m.phi.items()):
        ax = fig.add_subplot(1, len(m.phi), i + 1)
        if s.pairs:
            arr = np.array(s.pairs)
            ax.scatter(arr[:, 0], arr[:, 1], s=3, alpha=0.3)
        ax.plot([-180, 180], [-180, 180], color="#444444", linewidth=1, linestyle=":")
        ax.set_xlim(-190, 190)
        ax.set_ylim(-190, 190)
        ax.set_xlabel("true phi (deg)")
        ax.set_ylabel("measured phi (deg, smoothed)")
        ax.set_title(f"{pipeline}: MAE {s.mae:.0f} deg over {s.frames} frames", fontsize=10)
        ax.grid(alpha=0.3)
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def found_share(m: SweepMetrics, path: Path, footer: str) -> Path:
    fig = Figure(figsize=(11, 4.5), layout="constrained")
    for j in range(2):
        ax = fig.add_subplot(1, 2, j + 1)
        for pipeline, shares in m.found.items():
            share = shares[j]
            edges = share.edges
            labels = [
                f"{edges[i]:g}-{edges[i + 1]:g}" if edges[i + 1] < 1e8 else f">{edges[i]:g}"
                for i in range(len(edges) - 1)
            ]
            values = [100 * v if not math.isnan(v) else np.nan for v in share.shares()]
            ax.plot(range(len(labels)), values, marker="o", label=pipeline)
            if pipeline == MAIN:
                ticks = [f"{lab}\nn={n}" for lab, n in zip(labels, share.seen, strict=True)]
                ax.set_xticks(range(len(labels)), ticks, fontsize=8)
        ax.set_xlabel(shares[j].label)
        ax.set_ylabel("frames with a pose (%)")
        ax.set_ylim(-2, 102)
        ax.grid(alpha=0.3)
        _legend(ax, fontsize=8)
    fig.suptitle("Pose found (frames with at least half the landmarks in view)")
    fig.get_layout_engine().set(rect=(0, 0.03, 1, 0.97))
    return _save(fig, path, footer)


def write_all(
    m: SweepMetrics, rows: Sequence[RunResult], out_dir: Path, footer: str, methods: Sequence[str]
) -> list[Path]:
    """Every plot of the report; returns the paths written."""
    return [
        accuracy_vs_radius(m, out_dir / "accuracy_vs_radius.png", footer),
        confusion(m, out_dir / "confusion.png", footer, methods),
        lead_time(m, out_dir / "lead_time.png", footer, methods),
        recall_by_distance(m, rows, out_dir / "recall_by_distance.png", footer, methods),
        recall_by_speed(m, out_dir / "recall_by_speed.png", footer, methods),
        phi(m, out_dir / "phi.png", footer),
        found_share(m, out_dir / "found_share.png", footer),
    ]
