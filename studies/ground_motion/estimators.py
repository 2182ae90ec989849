"""Ground-motion estimators judged on a sweep's own foot points, without rendering again.

A sweep's results file keeps, for every frame, the foot point the pipeline found and the
robot's speed. This replays those foot points through a ground-motion estimator, then
through the real constant-velocity ground predictor and the real collision warning
(monopic's own code, as Pipeline.process calls it), and judges the warnings with the
sweep's own metrics (sim.analysis.metrics). So estimators can be compared on hundreds of
runs in seconds. Compared: finite differences, the estimator the Kalman track replaced
(positions in the odometry frame differenced over 4 frames, averaged over 4), and the
shipped Kalman track (monopic/features/ground_track.py), plus any Kalman settings given on
the command line.

Only constant-velocity/ground is replayed: its decision depends on nothing but the ground
track. The agreement column says how many frames' warnings the replay reproduces from the
file; the estimator that produced the file should agree on nearly all (foot points are
stored to 0.1 px).

    .venv/bin/python -m studies.ground_motion.estimators recordings/medium-s4.jsonl \
        [--acceleration 1.5 3] [--initial-speed 2] [--column-noise 0.3+0.01]
        [--plot errors.png]

Prints the table (and draws the plot); studies/ground_motion/README.md says where its
answers are kept.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from monopic.errors import UserError
from monopic.features.ground import GroundMotion, Odometry
from monopic.features.ground_track import GroundTrackConfig
from monopic.features.motion import VelocityEstimator
from monopic.frame import EgoState
from monopic.output import atomic_path
from sim.analysis.metrics import FrameCounts, group_by, summarise
from sim.runs.result import MAIN, RunResult
from sim.runs.results_file import read_results
from studies.ground_replay import Estimator, ground_errors, judge_warnings, replay

METHOD = "constant-velocity/ground"


@dataclass
class FiniteDifferences:
    """The estimator before the Kalman track: odometry-frame positions differenced, then
    averaged."""

    odometry: Odometry = field(default_factory=Odometry)
    velocity: VelocityEstimator = field(default_factory=lambda: VelocityEstimator(4, 4))

    def observe_ego(self, t: float, ego: EgoState) -> None:
        self.odometry.update(t, ego)

    def update(self, t, ego, foot, height):
        g = ego.camera.ground_point(np.array(foot, dtype=float))
        if not np.all(np.isfinite(g)):
            return None
        pos = (float(g[0]), float(g[1]))
        vx, vy = self.velocity.update(t, *self.odometry.to_fixed(pos))
        if not (math.isfinite(vx) and math.isfinite(vy)):
            return pos, (math.nan, math.nan)
        return pos, self.odometry.rotate_to_robot((vx, vy))

    def reset_track(self) -> None:
        self.velocity.reset()


@dataclass
class Judged:
    name: str
    agreement: float
    outcomes: list
    errors: np.ndarray

    def by_family(self) -> dict[str, tuple[int, int]]:
        """Per family: (runs warned, runs) — collision runs warned 1 s ahead, or near-miss
        runs warned at all. A near miss the track's lag causes shows in some families
        and not others (docs/intent/ground-tree.md)."""
        out: dict[str, tuple[int, int]] = {}
        for family, outs in group_by(self.outcomes, lambda o: o.family).items():
            sm = summarise(METHOD, outs)
            runs = sm.collision_runs + sm.near_miss_runs
            if runs:
                out[family] = (sm.warned_1s + sm.near_miss_warned, runs)
        return out

    def row(self) -> str:
        sm = summarise(METHOD, self.outcomes)
        f = sum((o.frames for o in self.outcomes), FrameCounts())
        near = [o for o in self.outcomes if o.near_miss]
        e = self.errors
        cells = [
            self.name,
            f"{100 * self.agreement:.1f} %",
            f"{sm.warned_1s}/{sm.collision_runs}",
            f"{sm.warned}/{sm.collision_runs}",
            f"{sum(o.warned for o in near)}/{len(near)}",
            str(f.fp),
            f"{f.tp / max(f.tp + f.fp, 1):.3f}",
            f"{f.tp / max(f.tp + f.fn, 1):.3f}",
            f"{np.percentile(e, 50):.2f} / {np.percentile(e, 90):.2f} / {np.percentile(e, 99):.1f}",
            f"{100 * np.mean(e > 10):.1f} %",
        ]
        return "| " + " | ".join(cells) + " |"


def judge(rows: list[RunResult], name: str, make: Callable[[], Estimator]) -> Judged:
    outcomes, errors = [], []
    agree = total = 0
    for row in rows:
        warn, ground = replay(row, make())
        main = row.pipelines[MAIN]
        logged_cols = main.decisions.get(METHOD)
        logged = logged_cols.warn if logged_cols else [None] * len(warn)
        agree += sum((a or 0) == (b or 0) for a, b in zip(warn, logged, strict=True))
        total += len(warn)
        outcomes.append(judge_warnings(row, warn, METHOD, logged_cols))
        errors.extend(ground_errors(row, ground))
    return Judged(name, agree / max(total, 1), outcomes, np.array(errors))


def plot(judged: list[Judged], path: Path, title: str) -> None:
    """Share of predictions within each error, one curve per estimator (log scale)."""
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.add_subplot()
    for j in judged:
        e = np.sort(j.errors)
        ax.plot(e, np.arange(1, len(e) + 1) / len(e), label=j.name)
    ax.set_xscale("log")
    ax.set_xlim(0.05, 200)
    ax.set_xlabel("error of the predicted ground point one horizon ahead (m)")
    ax.set_ylabel("share of predictions within")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(title, fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)


def load(path: Path) -> list[RunResult]:
    if not path.is_file():
        sys.exit(f"{path}: no such results file (write one with `monopic sweep`)")
    try:
        rows = list(read_results(path))
    except UserError as err:
        sys.exit(str(err))
    if not rows:
        sys.exit(f"{path}: no result lines")
    return rows


def column_noise(text: str) -> tuple[float | None, float]:
    """`--column-noise`'s PX+PER_HEIGHT, or 'row' for the shipped isotropic pixels."""
    if text == "row":
        return None, 0.0
    try:
        px, per_height = (float(x) for x in text.split("+"))
    except ValueError:
        raise SystemExit(
            f"--column-noise: {text!r} is not PX+PER_HEIGHT (e.g. 0.3+0.01) or 'row'"
        ) from None
    if not (px > 0 and per_height >= 0):
        raise SystemExit(f"--column-noise: {text!r}: PX must be > 0 and PER_HEIGHT >= 0")
    return px, per_height


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results", type=Path)
    ap.add_argument("--acceleration", type=float, nargs="+", default=[])
    ap.add_argument("--initial-speed", type=float, nargs="+", default=[])
    ap.add_argument("--pixel-noise-per-height", type=float, nargs="+", default=[])
    ap.add_argument(
        "--column-noise",
        metavar="PX+PER_HEIGHT",
        nargs="+",
        default=[],
        help="the foot column's own pixel noise, e.g. 0.3+0.01 (0.3 px plus 1 %% of the "
        "apparent height); 'row' keeps the column as noisy as the row (shipped)",
    )
    ap.add_argument("--plot", type=Path, help="PNG of the error distributions")
    args = ap.parse_args()
    rows = load(args.results)
    shipped = GroundTrackConfig()
    candidates: list[tuple[str, Callable[[], Estimator]]] = [
        ("finite differences (before the Kalman track)", FiniteDifferences),
        ("Kalman track (shipped)", GroundMotion),
    ]
    grid = itertools.product(
        args.acceleration or [shipped.acceleration],
        args.initial_speed or [shipped.initial_speed],
        args.pixel_noise_per_height or [shipped.pixel_noise_per_height],
        [column_noise(c) for c in args.column_noise] or [(None, 0.0)],
    )
    for a, s0, ph, (c0, ch) in grid:
        cfg = GroundTrackConfig(
            acceleration=a,
            initial_speed=s0,
            pixel_noise_per_height=ph,
            column_pixel_noise=c0,
            column_pixel_noise_per_height=ch,
        )
        if cfg != shipped:
            name = f"Kalman, acceleration {a:g}, initial speed {s0:g}, px/height {ph:g}"
            if c0 is not None:
                name += f", column {c0:g} px + {ch:g} x height"
            candidates.append((name, lambda cfg=cfg: GroundMotion(cfg)))
    lines = [
        f"{len(rows)} runs of `{args.results}` replayed for {METHOD} (foot points and robot "
        "speed from the file; the real predictor, warning and metrics). Recall@1s and "
        "'warned' count collision runs warned at least 1 s / any time before contact; "
        "frames judge each frame against contact within the horizon; the error is the "
        "predicted ground point against the true position one horizon later (m).",
        "",
        "| estimator | agreement with file | recall@1s | warned | near-miss warned "
        "| false-alarm frames | frame precision | frame recall | error p50 / p90 / p99 "
        "| error > 10 m |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    judged = []
    for name, make in candidates:
        judged.append(judge(rows, name, make))
        lines.append(judged[-1].row())
        print(lines[-1], file=sys.stderr)
    families = sorted({f for j in judged for f in j.by_family()})
    lines += [
        "",
        "Per family: collision runs warned 1 s ahead, or near-miss runs warned at all.",
        "",
        "| estimator | " + " | ".join(families) + " |",
        "| --- |" + " ---: |" * len(families),
    ]
    for j in judged:
        mine = j.by_family()
        cells = [f"{mine[f][0]}/{mine[f][1]}" if f in mine else "-" for f in families]
        lines.append(f"| {j.name} | " + " | ".join(cells) + " |")
    if args.plot:
        plot(judged, args.plot, f"{len(rows)} runs of {args.results.name}, {METHOD}")
        lines += ["", f"![error distributions]({args.plot})"]
    print("\n".join(lines))


if __name__ == "__main__":
    main()
