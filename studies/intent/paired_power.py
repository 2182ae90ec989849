"""How many collision runs a judged family needs before the recall goal can be met at all.

The intent stage's per-family test (docs/intent/verdict.md) asks the paired 95 % interval
of the recall difference (the intent predictor minus constant velocity,
`sim.analysis.metrics.paired_difference`) to have its lower bound at -3 points or better.
With n collision runs and a warned share near constant velocity's, that bound stays below
-3 points at small n even when the predictor loses no run at all, so a judged draw too
small fails any predictor. This prints, for each warned share and number of runs lost
(warned 1 s ahead by constant velocity only, none gained), the lower bound at the given
family sizes and the smallest family size at which the bound reaches the goal.

    .venv/bin/python -m studies.intent.paired_power [--share 0.8 0.85 0.9 0.95] [--lost 0 1 2]
        [--runs 96 128 200] [--bound -3]
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from monopic.errors import UserError
from sim.analysis.metrics import paired_difference

MAX_RUNS = 5000  # beyond this a judged draw is no longer a sweep anyone runs


def lower_bound(runs: int, share: float, lost: int) -> float:
    """The paired interval's lower bound (points) for `runs` collision runs, constant
    velocity warning a `share` of them in time and the predictor the same runs but `lost`."""
    warned = round(share * runs)
    if not 0 <= lost <= warned <= runs:
        raise ValueError(f"{lost} lost of {warned} warned in {runs} runs")
    _, low, _ = paired_difference(warned - lost, 0, lost, runs - warned)
    return 100 * low


def runs_needed(share: float, lost: int, bound: float) -> int | None:
    """The smallest family size whose lower bound reaches `bound` (None past MAX_RUNS)."""
    for runs in range(max(lost, 1), MAX_RUNS + 1):
        if round(share * runs) >= lost and lower_bound(runs, share, lost) >= bound:
            return runs
    return None


def table(shares: Sequence[float], losts: Sequence[int], sizes: Sequence[int], bound: float) -> str:
    head = " | ".join(f"{n} runs" for n in sizes)
    lines = [
        f"| warned share | runs lost | {head} | runs needed for {bound:+g} |",
        "| ---: | ---: | " + "---: | " * len(sizes) + "---: |",
    ]
    for share in shares:
        for lost in losts:
            cells = " | ".join(f"{lower_bound(n, share, lost):+.2f}" for n in sizes)
            need = runs_needed(share, lost, bound)
            lines.append(
                f"| {share:.2f} | {lost} | {cells} | {need if need else f'> {MAX_RUNS}'} |"
            )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--share", type=float, nargs="+", default=[0.8, 0.85, 0.9, 0.95])
    ap.add_argument("--lost", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--runs", type=int, nargs="+", default=[96, 128, 200])
    ap.add_argument("--bound", type=float, default=-3.0, help="goal, points (default -3)")
    args = ap.parse_args(argv)
    try:
        for s in args.share:
            if not (math.isfinite(s) and 0 < s <= 1):
                raise UserError(f"--share: {s} is not a share in (0, 1]")
        for k in args.lost:
            if k < 0:
                raise UserError(f"--lost: {k} is not a number of runs >= 0")
        for n in args.runs:
            if n < 1 or any(k > round(s * n) for s in args.share for k in args.lost):
                raise UserError(f"--runs: {n} runs cannot lose {max(args.lost)} warned runs")
        if not (math.isfinite(args.bound) and args.bound < 0):
            raise UserError(f"--bound: {args.bound} is not a negative number of points")
    except UserError as err:
        print(f"paired_power: {err}", file=sys.stderr)
        return 2
    print(table(args.share, args.lost, args.runs, args.bound))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
