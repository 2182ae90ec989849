"""How noisy is the pipeline's foot point, across the line of sight and along it?

The ground track (monopic.features.ground_track) believes each foot point as much as its
noise model says: 1 px plus 2.5 % of the apparent height, the same for the column and
the row, measured before the ground column came from the hips. Whether a
motion reading can lag the walker by 0.2 s or less depends on the real spread, which
this measures on a sweep's own results file, against the simulator's truth:

- pixels: the foot point's column and row against the truth's ground point projected
  into the run's camera, robust spread (1.4826 x MAD) by apparent height and robot scale;
- metres per second: the velocity of a line fitted to the measured ground points over the
  last 0.4 s (6 frames at 15 fps, about 0.2 s of lag) against the same fit to the truth's
  points, split across and along the line of sight, by range.

Both include the walker's own sway (the hips' column and the lowest foot's row move with
each step), which a track must take as noise too.

    .venv/bin/python -m studies.intent.foot_noise RESULTS.jsonl [MORE.jsonl ...] [--out noise.md]
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from monopic.errors import UserError
from monopic.output import write_text_atomically
from sim.runs.result import MAIN, RunResult
from sim.runs.results_file import read_results
from studies.ground_replay import camera

HEIGHT_BINS = (0, 30, 60, 100, 150, 250, 10_000)  # px of apparent height
RANGE_BINS = (0.0, 4.0, 6.0, 8.0, 10.0, 14.0, 30.0)  # m from the camera
FIT_WINDOW = 0.4  # s: the line fit's window
MIN_ROWS = 30  # a bin with fewer samples is left out


@dataclass(frozen=True)
class PixelSample:
    scale: str
    height: float  # px, apparent
    column: float  # px, measured - truth
    row: float


@dataclass(frozen=True)
class VelocitySample:
    scale: str
    range: float  # m
    across: float  # m/s, measured fit - truth fit
    along: float


def robust_spread(x: np.ndarray) -> float:
    """1.4826 x the median absolute deviation: the standard deviation of a normal."""
    return float(1.4826 * np.median(np.abs(x - np.median(x))))


def run_samples(row: RunResult) -> tuple[list[PixelSample], list[VelocitySample]]:
    """One run's foot points against its truth: pixel residuals, and the 0.4 s line fits'
    velocity residuals across and along the line of sight."""
    cam = camera(row)
    eye = cam.position[:2]
    main, tr = row.pipelines[MAIN], row.truth
    pixels: list[PixelSample] = []
    t_, meas, true = [], [], []
    for k, t in enumerate(tr.t):
        foot, fwd, lat = main.foot[k], tr.forward[k], tr.lateral[k]
        if not main.found[k] or foot is None or fwd is None or lat is None or t is None:
            continue
        height = main.height[k] or 0.0
        p = cam.project(np.array([[fwd, lat, 0.0]]))[0]
        pixels.append(PixelSample(row.scale, height, foot[0] - p[0], foot[1] - p[1]))
        g = cam.ground_point(np.array(foot[:2], dtype=float))
        if not np.all(np.isfinite(g)):
            continue
        t_.append(t)
        meas.append(g)
        true.append((fwd, lat))
    velocities: list[VelocitySample] = []
    if len(t_) < 6:
        return pixels, velocities
    # Both in the robot's frame: the robot's own motion moves both alike and cancels in
    # the difference of the two fits.
    ts, m, g_true = np.asarray(t_), np.asarray(meas), np.asarray(true)
    for i in range(len(ts)):
        sel = (ts > ts[i] - FIT_WINDOW - 1e-9) & (ts <= ts[i])
        if sel.sum() < 5:
            continue
        x = ts[sel] - ts[i]
        vm = np.polyfit(x, m[sel], 1)[0]
        vt = np.polyfit(x, g_true[sel], 1)[0]
        sight = g_true[i] - eye
        r = float(np.linalg.norm(sight))
        u = sight / max(r, 1e-6)
        n = np.array([-u[1], u[0]])
        d = vm - vt
        velocities.append(VelocitySample(row.scale, r, float(d @ n), float(d @ u)))
    return pixels, velocities


def table(
    title: str, keys: Sequence[str], bins: Sequence[float], unit: str, samples: list, key: str
) -> list[str]:
    """Robust spread of each residual in each bin, one row per bin and robot scale."""
    lines = [f"| robot | {title} | samples | " + " | ".join(keys) + " |",
             "| --- | --- | ---: |" + " ---: |" * len(keys)]  # fmt: skip
    for scale in sorted({s.scale for s in samples}):
        mine = [s for s in samples if s.scale == scale]
        at = np.array([getattr(s, key) for s in mine])
        for lo, hi in zip(bins[:-1], bins[1:], strict=True):
            inside = [s for s, a in zip(mine, at, strict=True) if lo <= a < hi]
            if len(inside) < MIN_ROWS:
                continue
            cells = [
                f"{robust_spread(np.array([getattr(s, k) for s in inside])):.3f}" for k in keys
            ]
            span = f"{lo:g}-{hi:g} {unit}" if hi < 1000 else f"{lo:g} {unit} and more"
            lines.append(f"| {scale} | {span} | {len(inside)} | " + " | ".join(cells) + " |")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results", type=Path, nargs="+", help="sweep results files (JSON lines)")
    ap.add_argument("--out", type=Path, help="also write the tables to this Markdown file")
    args = ap.parse_args(argv)
    pixels: list[PixelSample] = []
    velocities: list[VelocitySample] = []
    try:
        for path in args.results:
            if not path.is_file():
                raise UserError(f"{path}: no such results file (write one with `monopic sweep`)")
            for row in read_results(path):
                p, v = run_samples(row)
                pixels += p
                velocities += v
        if not pixels:
            raise UserError(f"{' '.join(map(str, args.results))}: no frame with a foot point")
    except UserError as err:
        print(err, file=sys.stderr)
        return 1
    names = " + ".join(f"`{p}`" for p in args.results)
    text = "\n".join([
        f"Foot points of {names} against the truth (studies/intent/foot_noise.py): robust spread "
        "(1.4826 x MAD).",
        "",
        "Pixels: the foot point against the truth's ground point projected into the camera.",
        "",
        *table("apparent height", ("column", "row"), HEIGHT_BINS, "px", pixels, "height"),
        "",
        f"Velocity (m/s): a line fit over the last {FIT_WINDOW:g} s of the measured ground "
        "points against the same fit to the truth's, across and along the line of sight.",
        "",
        *table("range", ("across", "along"), RANGE_BINS, "m", velocities, "range"),
    ]) + "\n"  # fmt: skip
    print(text)
    if args.out:
        write_text_atomically(args.out, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
