"""How a street's people stand and walk among each other: crowd statistics, real or simulated.

Input is what the ETH/UCY files hold, rows of (frame, person, x, y): frame numbers
FRAME_STEP apart per STEP (0.4 s), positions in metres on the ground plane. A recording
is one such array (a real scene, or one simulated run: sim.analysis.tracks.run_rows); a
set of recordings (a scene, a sweep's runs) gives one CrowdSummary. Numpy (matplotlib
for the plot, when drawn) and no simulator imports, so a real scene and a simulated
street are measured by the same code.

The statistics, each defined so that it is computed the same way for both:

- density (people/m2): per frame, the people in it over the area of the walked region;
  the median over frames (frames with nobody in them are not in the files, and a run
  always has its people, so both count frames with someone). The walked region of a
  recording is the union of the CELL x CELL squares that its people's positions, and the
  straight steps between consecutive positions, pass through (a square per person at
  the least: about the ground one person keeps to themselves). Its convex hull would
  count the building fronts and planters a real scene's people walk around; the cells
  count only where someone went. The region grows with the time watched until the
  walkable ground is covered: a real scene is one street watched for minutes, so the
  runs of a simulated spec (seconds each, the same street) are pooled into one region,
  while each run keeps its own frames, people and groups.
- distance to the nearest other person (m): over every person-frame with at least two
  people in the frame, p10 and p50.
- groups: two people walk together when, for at least TOGETHER seconds of consecutive
  steps, both walk (speed > WALKING), stand within NEAR of each other and their
  velocities differ by less than SAME_VELOCITY. That is the usual criterion of
  trajectory-based group detection, proximity and velocity similarity persisting over
  time (Ge, Collins and Ruback, "Vision-based analysis of small groups in pedestrian
  crowds", IEEE TPAMI 2012; the ETH scenes' group annotation, Pellegrini et al. 2009,
  marks people walking side by side at about a metre); the thresholds here are round
  values of that kind, not fitted. Velocities are forward differences of positions one
  step apart; two strangers crossing differ in velocity by about their speed, so the
  velocity (not the speed) test keeps them apart.
- group speed difference (m/s): |speed_a - speed_b| over the steps where a detected
  pair walks together, p50.
- speed spread (m/s): in each frame with at least two walking people, p90 - p10 of their
  speeds (with two: 0.8 of their difference, numpy's linear percentile); the median over
  frames. How unlike each other the people of one moment walk.
- group share: of the people who walk at all (one step faster than WALKING), the
  fraction in at least one group pair.

A statistic with nothing to measure (no two people ever in a frame, nobody walking) is
NaN, and is then never inside a span.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sim.analysis.realism import (
    FRAME_STEP,
    STEP,
    WALKING,
    Verdict,
    cdf_panel,
    verdict_rows,
    widened,
)

CELL = 1.0  # m, side of the squares of the walked region
NEAR = 1.5  # m, at most this far apart to walk together
SAME_VELOCITY = 0.5  # m/s, at most this unlike in velocity to walk together
TOGETHER = 2.0  # s of consecutive steps together to count as a group
MIN_STEPS = int(round(TOGETHER / STEP))  # 5 steps of 0.4 s

# key, label (with unit), what of its values the statistic is
CROWD_STATISTICS = (
    ("density", "density (people/m2)", "p50 over frames"),
    ("nn_p10", "nearest other person (m)", "p10"),
    ("nn_p50", "nearest other person (m)", "p50"),
    ("group_speed_difference", "speed difference in a group (m/s)", "p50"),
    ("speed_spread", "speed spread in a frame, p90 - p10 (m/s)", "p50 over frames"),
    ("group_share", "share of walkers in a group", "share"),
)


@dataclass(frozen=True)
class CrowdSummary:
    """One scene's (or one spec's runs') crowd statistics and what they were made of."""

    name: str
    recordings: int
    people: int  # people over all recordings (ids are per recording)
    frames: int  # frames with someone in them
    area: float  # m2, the walked region of all recordings together
    values: dict[str, float]  # every CROWD_STATISTICS key
    nearest: np.ndarray  # every person-frame's distance to the nearest other person
    densities: np.ndarray  # every frame's people / walked area


@dataclass(frozen=True)
class Steps:
    """Each row that has a next position one step later: its frame, person, position and
    velocity over that step (m/s)."""

    frame: np.ndarray
    person: np.ndarray
    position: np.ndarray  # (n, 2)
    velocity: np.ndarray  # (n, 2)

    @property
    def speed(self) -> np.ndarray:
        return np.hypot(self.velocity[:, 0], self.velocity[:, 1])


def _check(rows: np.ndarray) -> np.ndarray:
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    frame_person = np.rint(rows[:, :2]).astype(np.int64)
    if len(np.unique(frame_person, axis=0)) != len(rows):
        raise ValueError("a person appears twice in one frame")
    return rows


def _frames(rows: np.ndarray) -> np.ndarray:
    return np.rint(rows[:, 0]).astype(np.int64)


def steps(rows: np.ndarray) -> Steps:
    """Forward differences of each person's positions one frame step apart (a gap in a
    person's track gives no step)."""
    rows = _check(rows)
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    r = rows[order]
    frames = _frames(r)
    same = (r[1:, 1] == r[:-1, 1]) & (frames[1:] - frames[:-1] == FRAME_STEP)
    k = np.flatnonzero(same)
    return Steps(frames[k], r[k, 1], r[k, 2:4], (r[k + 1, 2:4] - r[k, 2:4]) / STEP)


def walked_area(rows: np.ndarray) -> float:
    """m2: the CELL squares the people's positions and their steps pass through."""
    return float(len(walked_cells(rows)) * CELL * CELL)


def walked_cells(rows: np.ndarray) -> np.ndarray:
    """(k, 2) integer indices of the CELL squares the people's positions and their steps
    pass through."""
    rows = _check(rows)
    s = steps(rows)
    points = [rows[:, 2:4]]
    if len(s.frame):
        # Points along every step no more than a quarter cell apart, so a fast walker's
        # step leaves no square it crossed uncounted.
        ends = s.position + s.velocity * STEP
        n = int(np.ceil(np.max(np.hypot(*(ends - s.position).T)) / (CELL / 4))) + 1
        for f in np.linspace(0.0, 1.0, max(n, 2)):
            points.append(s.position + f * (ends - s.position))
    return np.unique(np.floor(np.concatenate(points) / CELL).astype(np.int64), axis=0)


def frame_counts(rows: np.ndarray) -> np.ndarray:
    """The number of people in each frame that has anyone."""
    return np.unique(_frames(_check(rows)), return_counts=True)[1]


def nearest_distances(rows: np.ndarray) -> np.ndarray:
    """Every person-frame's distance to the nearest other person of the frame (frames
    with at least two people)."""
    rows = _check(rows)
    frames = _frames(rows)
    order = np.argsort(frames, kind="stable")
    bounds = np.flatnonzero(np.diff(frames[order])) + 1
    out = []
    for idx in np.split(order, bounds):
        if len(idx) < 2:
            continue
        p = rows[idx, 2:4]
        d = np.hypot(*(p[:, None, :] - p[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(d, np.inf)
        out.append(d.min(axis=1))
    return np.concatenate(out) if out else np.array([])


@dataclass(frozen=True)
class GroupPair:
    """Two people (ids) walking together over the steps from `frames[0]` to `frames[-1]`,
    and their speed difference at each of those steps."""

    a: float
    b: float
    frames: np.ndarray
    speed_difference: np.ndarray


def group_pairs(rows: np.ndarray) -> list[GroupPair]:
    """Every stretch of at least MIN_STEPS consecutive steps over which two people walk
    together (see the module docstring)."""
    s = steps(rows)
    speed = s.speed
    order = np.argsort(s.frame, kind="stable")
    bounds = np.flatnonzero(np.diff(s.frame[order])) + 1
    together: dict[tuple[float, float], list[tuple[int, float]]] = {}
    for idx in np.split(order, bounds):
        idx = idx[speed[idx] > WALKING]
        if len(idx) < 2:
            continue
        i, j = np.triu_indices(len(idx), k=1)
        a, b = idx[i], idx[j]
        near = np.hypot(*(s.position[a] - s.position[b]).T) < NEAR
        alike = np.hypot(*(s.velocity[a] - s.velocity[b]).T) < SAME_VELOCITY
        for x, y in zip(a[near & alike], b[near & alike], strict=True):
            key = (min(s.person[x], s.person[y]), max(s.person[x], s.person[y]))
            together.setdefault(key, []).append((int(s.frame[x]), abs(speed[x] - speed[y])))
    out = []
    for (pa, pb), found in together.items():
        found.sort()
        frames = np.array([f for f, _ in found])
        diff = np.array([d for _, d in found])
        cut = np.flatnonzero(np.diff(frames) != FRAME_STEP) + 1
        for f, d in zip(np.split(frames, cut), np.split(diff, cut), strict=True):
            if len(f) >= MIN_STEPS:
                out.append(GroupPair(pa, pb, f, d))
    return out


def speed_spreads(rows: np.ndarray) -> np.ndarray:
    """Per frame with at least two walking people: p90 - p10 of their speeds."""
    s = steps(rows)
    speed = s.speed
    walking = speed > WALKING
    frames, speed = s.frame[walking], speed[walking]
    out = []
    for f in np.unique(frames):
        v = speed[frames == f]
        if len(v) >= 2:
            out.append(float(np.percentile(v, 90) - np.percentile(v, 10)))
    return np.array(out)


def _q(values: np.ndarray, p: float) -> float:
    return float(np.percentile(values, p)) if len(values) else math.nan


def crowd_summary(name: str, recordings: Sequence[np.ndarray]) -> CrowdSummary:
    """The crowd statistics of recordings of one street: each person, frame and group
    belongs to its recording, and the walked region is the union of all of theirs (one
    street watched several times, as a real scene is one street watched for minutes)."""
    counts, nearest, differences, spreads, cells = [], [], [], [], []
    people = walkers = grouped = 0
    recordings = [r for r in (_check(r) for r in recordings) if len(r)]
    for rows in recordings:
        cells.append(walked_cells(rows))
        counts.append(frame_counts(rows))
        nearest.append(nearest_distances(rows))
        pairs = group_pairs(rows)
        differences += [p.speed_difference for p in pairs]
        spreads.append(speed_spreads(rows))
        people += len(np.unique(rows[:, 1]))
        s = steps(rows)
        walkers += len(np.unique(s.person[s.speed > WALKING]))
        grouped += len({p.a for p in pairs} | {p.b for p in pairs})

    def joined(parts: list[np.ndarray]) -> np.ndarray:
        return np.concatenate(parts) if parts else np.array([])

    area = len(np.unique(np.concatenate(cells), axis=0)) * CELL * CELL if cells else math.nan
    d = joined(counts) / area
    nn, diff, spread = joined(nearest), joined(differences), joined(spreads)
    values = {
        "density": _q(d, 50),
        "nn_p10": _q(nn, 10),
        "nn_p50": _q(nn, 50),
        "group_speed_difference": _q(diff, 50),
        "speed_spread": _q(spread, 50),
        "group_share": grouped / walkers if walkers else math.nan,
    }
    return CrowdSummary(name, len(recordings), people, len(d), float(area), values, nn, d)


def crowd_span(real: Sequence[CrowdSummary], stat: str, widen: float = 0.2) -> tuple[float, float]:
    """The real scenes' range of one crowd statistic, widened as realism.span widens."""
    return widened([s.values[stat] for s in real], widen)


def judge_crowd(real: Sequence[CrowdSummary], simulated: CrowdSummary, widen: float = 0.2
                ) -> list[Verdict]:  # fmt: skip
    """Each crowd statistic of `simulated` against the real scenes' widened span."""
    out = []
    for stat, _, quantile in CROWD_STATISTICS:
        low, high = crowd_span(real, stat, widen)
        out.append(Verdict(stat, quantile, simulated.values[stat], low, high))
    return out


# -- the report -----------------------------------------------------------------------


def _g(value: float) -> str:
    return "-" if math.isnan(value) else f"{value:.3g}"


def crowd_report_text(real: Sequence[CrowdSummary], simulated: Sequence[CrowdSummary],
                      plot: str, widen: float = 0.2) -> str:  # fmt: skip
    """The crowd section of the realism report (Markdown): the real scenes' densities to
    build crowds to, every set's statistics, each simulated set's verdicts, the plot."""
    lines = [
        "## Crowds: people among each other, at matched density",
        "",
        "Per frame of 0.4 s (sim/analysis/crowd_stats.py): density = people in the frame "
        f"/ the walked region (the {CELL:g} m squares anyone's positions and steps pass "
        "through, all runs of a spec together, as one street watched as long as a real "
        "scene), median over frames; the distance from each person to the nearest "
        "other, over person-frames with two people or more; a group is two people walking "
        f"(> {WALKING} m/s) within {NEAR} m whose velocities differ by less than "
        f"{SAME_VELOCITY} m/s for {TOGETHER:g} s or more (proximity and velocity over "
        "time, as Ge, Collins and Ruback 2012 detect groups); the speed difference within "
        "groups; the spread of walking speeds in a frame (p90 - p10, median over frames); "
        "the share of walkers in a group. A simulated spec is every run's people, each run "
        "measured on its own and pooled.",
        "",
        "### The real scenes' density, to build crowds to",
        "",
        "| scene | people | frames | walked region (m2) | density p10 / p50 / p90 over "
        "frames (people/m2) | people in a frame p50 |",
        "| --- | ---: | ---: | ---: | --- | ---: |",
    ]
    for s in real:
        q = [_g(_q(s.densities, p)) for p in (10, 50, 90)]
        lines.append(
            f"| {s.name} | {s.people} | {s.frames} | {_g(s.area)} | {' / '.join(q)} "
            f"| {_g(_q(s.densities * s.area, 50))} |"
        )
    head = ["set", "people", "frames", "walked region (m2)"]
    head += [f"{label} {quantile}" for _, label, quantile in CROWD_STATISTICS]
    lines += ["", "### Every set", "", "| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for kind, sets in (("real", real), ("simulated", simulated)):
        for s in sets:
            cells = [f"{s.name} ({kind})", str(s.people), str(s.frames), _g(s.area)]
            cells += [_g(s.values[k]) for k, _, _ in CROWD_STATISTICS]
            lines.append("| " + " | ".join(cells) + " |")
    for s in simulated:
        verdicts = judge_crowd(real, s, widen)
        inside = sum(v.inside for v in verdicts)
        lines += [
            "",
            f"### `{s.name}` against the real scenes' span",
            "",
            f"Density {_g(s.values['density'])} people/m2 beside the scenes' "
            + ", ".join(f"{r.name} {_g(r.values['density'])}" for r in real)
            + f". Each span is the real scenes' min to max widened by {widen:.0%} "
            f"(min x {1 - widen:g} to max x {1 + widen:g}). {inside} of {len(verdicts)} inside.",
            "",
            "| statistic | of | simulated | span | inside |",
            "| --- | --- | ---: | --- | --- |",
        ]
        labels = {k: label for k, label, _ in CROWD_STATISTICS}
        lines += verdict_rows(verdicts, labels)
    lines += ["", f"![crowds]({plot})", ""]
    return "\n".join(lines)


def plot_crowds(real: Sequence[CrowdSummary], simulated: Sequence[CrowdSummary], path: Path,
                title: str) -> None:  # fmt: skip
    """Two panels, as realism.plot_distributions draws them: the share of person-frames
    within each distance of the nearest other person, and of frames within each density."""
    from matplotlib.figure import Figure

    from monopic.output import atomic_path

    fig = Figure(figsize=(10, 4.2), layout="constrained")
    panels = (
        ("nearest", "nearest other person (m)", "share of person-frames within"),
        ("densities", "density (people/m2)", "share of frames within"),
    )
    for i, (attr, xlabel, ylabel) in enumerate(panels):
        ax = fig.add_subplot(1, 2, i + 1)
        curves = [(s.name, getattr(s, attr), style) for group, style in ((real, "-"),
                  (simulated, "--")) for s in group]  # fmt: skip
        cdf_panel(ax, curves, xlabel, ylabel, legend=i == 0)
    fig.suptitle(title + " (solid: real scenes, dashed: simulated)", fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
