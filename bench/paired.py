"""Is one side's landmark error really lower than the other's, or within the noise?

Both pipelines see the same frames, so the comparison is paired: every resample takes the
same frames for both sides. Errors on neighbouring frames of one walk are not independent
(the same pose, the same crop), so the resampling unit is a block of consecutive frames of
one sequence, not a frame or a landmark: resampling landmarks would call 0.1 px
"significant" on a 60-frame clip. The statistic is the difference of the medians over
landmark instances, the number the error table shows, or of the means
(`paired_mean_difference`: the bound on what an int8 model may cost).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

BLOCK_FRAMES = 8  # about half a second at 15 fps: roughly one step of the gait
RESAMPLES = 2000


@dataclass(frozen=True)
class PairedDifference:
    """median(a) - median(b) with its bootstrap interval; negative means a is lower."""

    difference: float
    low: float
    high: float
    level: float

    @property
    def verdict(self) -> str:
        if self.low > 0:
            return "worse"
        if self.high < 0:
            return "better"
        return "equal"


def blocks(sequence: np.ndarray, block: int = BLOCK_FRAMES) -> list[np.ndarray]:
    """Positions 0..n-1 cut into runs of at most `block` consecutive frames of one sequence."""
    out: list[np.ndarray] = []
    start = 0
    n = len(sequence)
    for i in range(1, n + 1):
        if i == n or sequence[i] != sequence[start] or i - start == block:
            out.append(np.arange(start, i))
            start = i
    return out


def paired_median_difference(
    a: list[np.ndarray],
    b: list[np.ndarray],
    sequence: np.ndarray,
    *,
    level: float = 0.95,
    resamples: int = RESAMPLES,
    seed: int = 0,
) -> PairedDifference:
    """Block-bootstrap interval of median(a) - median(b).

    `a[k]` and `b[k]` hold the two sides' landmark errors on frame k (the same landmarks
    on both sides, so the arrays have equal length); `sequence[k]` is frame k's sequence,
    frames in time order.
    """
    return _paired(a, b, sequence, np.median, level, resamples, seed)


def paired_mean_difference(
    a: list[np.ndarray],
    b: list[np.ndarray],
    sequence: np.ndarray,
    *,
    level: float = 0.95,
    resamples: int = RESAMPLES,
    seed: int = 0,
) -> PairedDifference:
    """Block-bootstrap interval of mean(a) - mean(b), pooled over landmark instances."""
    return _paired(a, b, sequence, np.mean, level, resamples, seed)


def _paired(
    a: list[np.ndarray],
    b: list[np.ndarray],
    sequence: np.ndarray,
    stat: Callable[[np.ndarray], float],
    level: float,
    resamples: int,
    seed: int,
) -> PairedDifference:
    if not (len(a) == len(b) == len(sequence)) or not len(a):
        raise ValueError(f"need one error array per frame on both sides: {len(a)}, {len(b)}")
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        if len(x) != len(y):
            raise ValueError(f"frame {k}: {len(x)} errors on one side, {len(y)} on the other")
    cut = blocks(np.asarray(sequence))
    rng = np.random.default_rng(seed)
    stats = np.empty(resamples)
    for r in range(resamples):
        chosen = rng.integers(0, len(cut), size=len(cut))
        frames = np.concatenate([cut[c] for c in chosen])
        stats[r] = _stat_of(a, frames, stat) - _stat_of(b, frames, stat)
    every = np.arange(len(a))
    tail = 100 * (1 - level) / 2
    return PairedDifference(
        difference=_stat_of(a, every, stat) - _stat_of(b, every, stat),
        low=float(np.nanpercentile(stats, tail)),
        high=float(np.nanpercentile(stats, 100 - tail)),
        level=level,
    )


def _stat_of(
    errors: list[np.ndarray], frames: np.ndarray, stat: Callable[[np.ndarray], float]
) -> float:
    pooled = np.concatenate([errors[k] for k in frames])
    return float(stat(pooled)) if pooled.size else float("nan")
