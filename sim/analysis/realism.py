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
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from monopic.errors import UserError

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


def read_tracks(path: Path) -> TrackSet:
    """An ETH/UCY text file (`frame person x y` rows) split into gap-free tracks."""
    try:
        rows = np.loadtxt(path, ndmin=2)
    except (OSError, ValueError) as err:
        raise UserError(f"{path}: not a track file of `frame person x y` rows ({err})") from None
    if rows.shape[1] != 4:
        raise UserError(f"{path}: rows have {rows.shape[1]} columns, expected frame person x y")
    tracks = []
    for person in np.unique(rows[:, 1]):
        mine = rows[rows[:, 1] == person]
        mine = mine[np.argsort(mine[:, 0])]
        cut = np.flatnonzero(np.diff(mine[:, 0]) != FRAME_STEP) + 1
        for piece in np.split(mine, cut):
            if len(piece) >= 2:
                tracks.append(piece[:, 2:4].astype(float))
    return TrackSet(path.stem, tuple(tracks))


def write_tracks(path: Path, tracks: Sequence[np.ndarray], first_id: int = 1) -> None:
    """Tracks in the same text format (frame numbers FRAME_STEP apart from 0)."""
    lines = []
    for i, track in enumerate(tracks):
        for k, (x, y) in enumerate(track):
            lines.append(f"{k * FRAME_STEP:d}\t{first_id + i:d}\t{x:.3f}\t{y:.3f}")
    path.write_text("\n".join(lines) + ("\n" if lines else ""))


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
    values = [getattr(s, quantile)[stat] for s in real]
    return min(values) * (1 - widen), max(values) * (1 + widen)
