"""The pedestrian's motion as a polyline in time: where it is at any time, exactly.

A Track is vertices (t_k, p_k) joined by straight pieces at constant velocity, the last
piece going on for ever. The body (MuJoCo), highway-env's road object and the ground
truth all read the same Track, so the truth's case of the next second, its collisions and
times to contact use exactly the motion the body makes. Walkers (sim.scenario.walkers)
make Tracks; this module knows nothing of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.geometry.frames import Pose2D

H = 0.01  # s, the fine step of accelerations and of human walks


@dataclass(frozen=True)
class PathState:
    """The pedestrian on its path at one time (world frame)."""

    time: float
    position: np.ndarray  # (2,) world x, y
    yaw: float  # rad, CCW from east: where the person faces (and walks, when walking)
    velocity: np.ndarray  # (2,) world ground velocity, m/s
    footprint_yaw: float = math.nan  # rad: the square on the ground follows the walking line
    head_yaw: float = 0.0  # rad, the head turned from the shoulders (a human walker's cues)
    torso_yaw: float = 0.0  # rad, the shoulders turned from the walking direction

    def __post_init__(self) -> None:
        if math.isnan(self.footprint_yaw):
            object.__setattr__(self, "footprint_yaw", self.yaw)

    @property
    def speed(self) -> float:
        return float(math.hypot(self.velocity[0], self.velocity[1]))

    @property
    def pose(self) -> Pose2D:
        return Pose2D(float(self.position[0]), float(self.position[1]), self.yaw)


class Track:
    """Vertices at `times` (from 0, increasing), piece k from vertex k at `velocities[k]`.

    `yaws[k]` is the heading on piece k (the body's); `footprint_yaws[k]` the heading of
    the square the pedestrian occupies on the ground (the walking line's: a human walker's
    sway turns the body, not the ground it covers). The last piece has no end.
    """

    def __init__(self, times: np.ndarray, positions: np.ndarray, velocities: np.ndarray,
                 yaws: np.ndarray, footprint_yaws: np.ndarray | None = None,
                 phases: np.ndarray | None = None, head_yaws: np.ndarray | None = None,
                 torso_yaws: np.ndarray | None = None) -> None:  # fmt: skip
        self.times = np.asarray(times, dtype=float)
        self.positions = np.asarray(positions, dtype=float).reshape(-1, 2)
        self.velocities = np.asarray(velocities, dtype=float).reshape(-1, 2)
        self.yaws = np.asarray(yaws, dtype=float)
        self.footprint_yaws = self.yaws if footprint_yaws is None else np.asarray(footprint_yaws)
        # The stride phase (strides since some start, unwrapped) where the walk sets it;
        # None: the mannequin's gait keeps its own phase.
        self.phases = None if phases is None else np.asarray(phases, dtype=float)
        # Intent cues at the vertices (radians, interpolated between them); None: none.
        self.head_yaws = None if head_yaws is None else np.asarray(head_yaws, dtype=float)
        self.torso_yaws = None if torso_yaws is None else np.asarray(torso_yaws, dtype=float)
        n = len(self.times)
        arrays = (self.positions, self.velocities, self.yaws, self.footprint_yaws)
        optional = (self.phases, self.head_yaws, self.torso_yaws)
        sizes = {len(a) for a in arrays + tuple(a for a in optional if a is not None)}
        if not (n >= 1 and sizes == {n}):
            raise ValueError("a track needs as many positions, velocities and yaws as times")
        if self.times[0] != 0.0 or np.any(np.diff(self.times) <= 0):
            raise ValueError("track times must start at 0 and increase")

    @classmethod
    def from_vertices(cls, times: np.ndarray, positions: np.ndarray, yaws: np.ndarray,
                      end_velocity: np.ndarray, footprint_yaws: np.ndarray | None = None,
                      phases: np.ndarray | None = None, head_yaws: np.ndarray | None = None,
                      torso_yaws: np.ndarray | None = None) -> Track:  # fmt: skip
        """Pieces joining the vertices; the last one goes on at `end_velocity`."""
        times = np.asarray(times, dtype=float)
        positions = np.asarray(positions, dtype=float).reshape(-1, 2)
        velocities = np.empty_like(positions)
        if len(times) > 1:
            velocities[:-1] = np.diff(positions, axis=0) / np.diff(times)[:, None]
        velocities[-1] = end_velocity
        return cls(times, positions, velocities, np.asarray(yaws, dtype=float), footprint_yaws,
                   phases, head_yaws, torso_yaws)  # fmt: skip

    def _piece(self, t: float) -> int:
        if not (math.isfinite(t) and t >= 0):
            raise ValueError(f"path time must be >= 0, got {t}")
        return int(np.searchsorted(self.times, t, side="right")) - 1

    def state(self, t: float) -> PathState:
        """Where the pedestrian is at time t (s since the scenario start)."""
        k = self._piece(t)
        v = self.velocities[k]
        position = self.positions[k] + (t - self.times[k]) * v
        head = 0.0 if self.head_yaws is None else float(np.interp(t, self.times, self.head_yaws))
        torso = 0.0 if self.torso_yaws is None else float(np.interp(t, self.times, self.torso_yaws))
        return PathState(float(t), position, float(self.yaws[k]), v.copy(),
                         float(self.footprint_yaws[k]), head, torso)  # fmt: skip

    def positions_at(self, times: np.ndarray) -> np.ndarray:
        """(n, 2) positions at many times (>= 0) at once."""
        times = np.asarray(times, dtype=float)
        k = np.searchsorted(self.times, times, side="right") - 1
        return self.positions[k] + (times - self.times[k])[:, None] * self.velocities[k]

    def breakpoints_between(self, t0: float, t1: float) -> list[float]:
        """Times in (t0, t1) where the velocity may change."""
        lo = int(np.searchsorted(self.times, t0, side="right"))
        hi = int(np.searchsorted(self.times, t1, side="left"))
        return [float(t) for t in self.times[lo:hi]]

    def phase(self, t: float) -> float | None:
        """The stride phase in [0, 1) at time t, where the walk sets it."""
        if self.phases is None:
            return None
        return float(np.interp(t, self.times, self.phases)) % 1.0

    def translated(self, offset: np.ndarray) -> Track:
        return Track(self.times, self.positions + offset, self.velocities, self.yaws,
                     self.footprint_yaws, self.phases, self.head_yaws, self.torso_yaws)  # fmt: skip
