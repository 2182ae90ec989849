"""How walkers move, on the statistics real pedestrian tracks give: simulated beside real.

Tracks are positions on the ground plane at STEP-second steps, as the ETH/UCY benchmark
has them (text rows `frame person x y`, consecutive frames FRAME_STEP apart, 0.4 s). The
statistics, as measured in ../shared/data/eth-ucy-calibration/README.md:

- speed: |p[k+1] - p[k]| / STEP;
- |acceleration|: the change of that speed between consecutive steps / STEP;
- turn rate: the change of heading (direction of p[k+1] - p[k]) between steps / STEP;
- constant-velocity error at h (0.4, 0.8, 1.2 s): |p[k] + h (p[k] - p[k-1]) / STEP -
  p[k + h / STEP]|, the last step's velocity held;

each over steps of tracks without gaps, speed, acceleration and turn rate where the
walker walks (speed > WALKING on the steps involved), p50 and p90.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sim.scenario.track_file import read_rows as track_rows

STEP = 0.4  # s between positions
FRAME_STEP = 10  # ETH/UCY frame numbers between consecutive positions
WALKING = 0.5  # m/s
HORIZONS = (0.4, 0.8, 1.2)  # s, for the constant-velocity error
STATISTICS = (
    ("speed", "m/s"),
    ("abs_acceleration", "m/s2"),
    ("turn_rate", "deg/s"),
    *((f"cv_error_{h:.1f}s", "m") for h in HORIZONS),
)


@dataclass(frozen=True)
class TrackSet:
    """Named tracks: each an (n, 2) array of positions STEP seconds apart, no gaps."""

    name: str
    tracks: tuple[np.ndarray, ...]


@dataclass(frozen=True)
class Summary:
    """p50 and p90 of every statistic of a set of tracks."""

    name: str
    tracks: int
    steps: int
    p50: dict[str, float]
    p90: dict[str, float]
    values: dict[str, np.ndarray]


def read_rows(path: Path) -> np.ndarray:
    """An ETH/UCY text file's rows as they are: an (n, 4) array of frame, person, x, y
    (frame numbers FRAME_STEP apart per STEP seconds; ids and frames kept, for what needs
    who stood where at the same moment). The replay walker's reader checks them
    (sim.scenario.track_file.read_rows); gaps are the statistics' own to cut."""
    return track_rows(path)


def read_tracks(path: Path) -> TrackSet:
    """An ETH/UCY text file (`frame person x y` rows) split into gap-free tracks."""
    rows = read_rows(path)
    tracks = []
    for person in np.unique(rows[:, 1]):
        mine = rows[rows[:, 1] == person]
        mine = mine[np.argsort(mine[:, 0])]
        cut = np.flatnonzero(np.diff(mine[:, 0]) != FRAME_STEP) + 1
        for piece in np.split(mine, cut):
            if len(piece) >= 2:
                tracks.append(piece[:, 2:4].astype(float))
    return TrackSet(path.stem, tuple(tracks))


def tracks_text(tracks: Sequence[np.ndarray], first_id: int = 1) -> str:
    """Tracks in the same text format (frame numbers FRAME_STEP apart from 0, ids from
    `first_id`), one row per person per step."""
    lines = []
    for i, track in enumerate(tracks):
        for k, (x, y) in enumerate(track):
            lines.append(f"{k * FRAME_STEP:d}\t{first_id + i:d}\t{x:.3f}\t{y:.3f}")
    return "\n".join(lines) + ("\n" if lines else "")


def _heading_change(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = np.arctan2(b[:, 1], b[:, 0]) - np.arctan2(a[:, 1], a[:, 0])
    return np.abs((d + math.pi) % (2 * math.pi) - math.pi)


def statistics(tracks: Iterable[np.ndarray]) -> dict[str, np.ndarray]:
    """Every statistic's values over the steps of the tracks (see the module docstring)."""
    out: dict[str, list[np.ndarray]] = {name: [] for name, _ in STATISTICS}
    for p in tracks:
        if len(p) < 2:
            continue
        steps = np.diff(p, axis=0)
        speed = np.hypot(steps[:, 0], steps[:, 1]) / STEP
        walking = speed > WALKING
        out["speed"].append(speed[walking])
        if len(steps) >= 2:
            both = walking[:-1] & walking[1:]
            out["abs_acceleration"].append(np.abs(np.diff(speed))[both] / STEP)
            turn = np.degrees(_heading_change(steps[:-1], steps[1:])) / STEP
            out["turn_rate"].append(turn[both])
        for h in HORIZONS:
            n = int(round(h / STEP))
            if len(p) < n + 2:
                continue
            k = np.arange(1, len(p) - n)
            guess = p[k] + (h / STEP) * (p[k] - p[k - 1])
            out[f"cv_error_{h:.1f}s"].append(np.hypot(*(guess - p[k + n]).T))
    return {k: np.concatenate(v) if v else np.array([]) for k, v in out.items()}


def summarise(tracks: TrackSet) -> Summary:
    values = statistics(tracks.tracks)

    def q(v: np.ndarray, p: float) -> float:
        return float(np.percentile(v, p)) if len(v) else math.nan

    return Summary(
        tracks.name,
        len(tracks.tracks),
        int(sum(max(len(t) - 1, 0) for t in tracks.tracks)),
        {k: q(v, 50) for k, v in values.items()},
        {k: q(v, 90) for k, v in values.items()},
        values,
    )


def span(
    real: Sequence[Summary], stat: str, quantile: str, widen: float = 0.2
) -> tuple[float, float]:
    """The real scenes' range of one statistic's p50 or p90, widened by `widen` of each end
    (min * (1 - widen), max * (1 + widen))."""
    return widened([getattr(s, quantile)[stat] for s in real], widen)


def widened(values: Sequence[float], widen: float = 0.2) -> tuple[float, float]:
    """min * (1 - widen) to max * (1 + widen) of the values that are numbers (NaN: a scene
    with nothing to measure; all NaN gives a NaN span, which nothing is inside)."""
    known = [v for v in values if not math.isnan(v)]
    if not known:
        return math.nan, math.nan
    return min(known) * (1 - widen), max(known) * (1 + widen)


# -- the report -----------------------------------------------------------------------

LABELS = {
    "speed": "speed (m/s)",
    "abs_acceleration": "|acceleration| (m/s2)",
    "turn_rate": "turn rate (deg/s)",
    "cv_error_0.4s": "CV error 0.4 s (m)",
    "cv_error_0.8s": "CV error 0.8 s (m)",
    "cv_error_1.2s": "CV error 1.2 s (m)",
}


@dataclass(frozen=True)
class Verdict:
    stat: str
    quantile: str
    value: float
    low: float
    high: float

    @property
    def inside(self) -> bool:
        return self.low <= self.value <= self.high


def judge(real: Sequence[Summary], simulated: Summary, widen: float = 0.2) -> list[Verdict]:
    """Each statistic's p50 and p90 of `simulated` against the real scenes' widened span."""
    out = []
    for stat, _ in STATISTICS:
        for quantile in ("p50", "p90"):
            low, high = span(real, stat, quantile, widen)
            out.append(Verdict(stat, quantile, getattr(simulated, quantile)[stat], low, high))
    return out


def _g(value: float) -> str:
    """Three significant digits; rounding noise (a straight walk's 1e-15) as 0; none as -."""
    if math.isnan(value):
        return "-"
    return "0" if abs(value) < 1e-9 else f"{value:.3g}"


def verdict_rows(verdicts: Sequence[Verdict], labels: Mapping[str, str]) -> list[str]:
    """A verdict table's rows: statistic, quantile, value, span, inside."""
    return [
        f"| {labels[v.stat]} | {v.quantile} | {_g(v.value)} | {_g(v.low)} - {_g(v.high)} "
        f"| {'yes' if v.inside else 'no'} |"
        for v in verdicts
    ]


def report_text(real: Sequence[Summary], simulated: Sequence[Summary],
                judged: Sequence[str], command: str, plot: str) -> str:  # fmt: skip
    """The realism report (Markdown): a table of every set, the verdicts of each judged
    set, the plot."""
    head = ["set", "tracks", "steps"] + [f"{LABELS[s]} p50 / p90" for s, _ in STATISTICS]
    lines = [
        "# Realism: simulated walkers beside real ones",
        "",
        f"`{command}`",
        "",
        "Statistics of 0.4 s steps (sim/analysis/realism.py): speed, |acceleration| and "
        f"turn rate over steps where the walker walks (> {WALKING} m/s), and the error of "
        "holding the last step's velocity for 0.4, 0.8 and 1.2 s; p50 / p90. Real scenes "
        "are read from their files at run time; simulated tracks are each run's pedestrian "
        "over the run, exactly as rendered (`monopic tracks`).",
        "",
        "| " + " | ".join(head) + " |",
        "|" + " --- |" * len(head),
    ]
    for kind, sets in (("real", real), ("simulated", simulated)):
        for s in sets:
            cells = [f"{s.name} ({kind})", str(s.tracks), str(s.steps)]
            cells += [f"{_g(s.p50[k])} / {_g(s.p90[k])}" for k, _ in STATISTICS]
            lines.append("| " + " | ".join(cells) + " |")
    for chosen in (s for name in judged for s in simulated if s.name == name):
        verdicts = judge(real, chosen)
        inside = sum(v.inside for v in verdicts)
        lines += [
            "",
            f"## `{chosen.name}` against the real scenes' span",
            "",
            "The span of each statistic is the real scenes' min to max, widened by 20 % "
            "(min x 0.8 to max x 1.2).",
            "",
            f"{inside} of {len(verdicts)} inside.",
            "",
            "| statistic | quantile | simulated | span | inside |",
            "| --- | --- | ---: | --- | --- |",
        ]
        lines += verdict_rows(verdicts, LABELS)
    lines += ["", f"![distributions]({plot})", ""]
    return "\n".join(lines)


def walkers_text(real: Sequence[Summary], walkers: Sequence[Summary]) -> str:
    """The per-walker statistics of the crowds' people beside the real scenes' span."""
    lines = [
        "",
        "### The crowds' walkers, one by one",
        "",
        "Every person of each crowd spec's runs but the scripted one (whose walk is the "
        "family's script, judged with the walker specs above) on the per-walker statistics "
        "of 0.4 s steps, p50 / p90, and how many fall inside the real scenes' span (min x "
        "0.8 to max x 1.2).",
        "",
        "| set | tracks | " + " | ".join(LABELS[k] for k, _ in STATISTICS) + " | inside |",
        "|" + " --- |" * (len(STATISTICS) + 3),
    ]
    for w in walkers:
        verdicts = judge(real, w)
        cells = [f"{_g(w.p50[k])} / {_g(w.p90[k])}" for k, _ in STATISTICS]
        inside = f"{sum(v.inside for v in verdicts)} of {len(verdicts)}"
        lines.append(f"| {w.name} | {w.tracks} | " + " | ".join(cells) + f" | {inside} |")
    return "\n".join(lines) + "\n"


def cdf_panel(ax: Any, curves: Sequence[tuple[str, np.ndarray, str]], xlabel: str,
              ylabel: str, legend: bool) -> None:  # fmt: skip
    """One panel of cumulative shares: each (name, values, line style) a curve, the x axis
    from 0 to past the highest set's 98th percentile."""
    for name, values, style in curves:
        v = np.sort(values)
        if len(v):
            ax.plot(v, np.arange(1, len(v) + 1) / len(v), style, label=name, lw=1.4)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    high = max((np.percentile(v, 98) for _, v, _ in curves if len(v)), default=1.0)
    ax.set_xlim(0, high * 1.1 if high > 0 else 1.0)
    if legend:
        ax.legend(fontsize=7, loc="lower right")


def plot_distributions(real: Sequence[Summary], simulated: Sequence[Summary], path: Path,
                       title: str) -> None:  # fmt: skip
    """One panel per statistic: the share of steps within each value, every set a curve."""
    from matplotlib.figure import Figure

    from monopic.output import atomic_path

    fig = Figure(figsize=(13, 7.5), layout="constrained")
    for i, (stat, _) in enumerate(STATISTICS):
        ax = fig.add_subplot(2, 3, i + 1)
        curves = [(s.name, s.values[stat], style) for group, style in ((real, "-"),
                  (simulated, "--")) for s in group]  # fmt: skip
        cdf_panel(ax, curves, LABELS[stat], "share of steps within", legend=i == 0)
    fig.suptitle(title + " (solid: real scenes, dashed: simulated)", fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
