"""From an authors' log to per-row features, labels and targets.

Per row: our own velocity from the raw centre and time columns, never their smoothed
speed columns (VelocityEstimator by default; with `velocity_window` the least-squares
slope over the trailing window of that many seconds, which the horizon judge uses),
phi from their angleOfApproach column (their logs lack the z needed to recompute it),
the foot point centreY + height/2 and the apparent height occupiedHeights * 432. The
label of row i is the case of the next `horizon` seconds of motion, from the
static-camera image labelling (`case_from_image_track`) of the track over
[t_i, t_i + horizon], its end interpolated from the log's own timestamps; the target is
the centre's displacement over the same interval. Rows whose t_i + horizon lies beyond the
log's last timestamp have neither. Rows less than `warm_up` seconds after the first one
are warm-up: their velocities are still settling, so they are neither trained on nor
scored.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monopic.cases import Case, case_from_image_track
from monopic.features.motion import VelocityEstimator
from monopic.features.record import Features
from monopic.horizon import HORIZON_S
from monopic.predict.base import Mode
from monopic.replay.logs import AuthorsLog
from monopic.tree.model import TrainingSample, feature_values

WARM_UP_S = 0.5


@dataclass(frozen=True)
class PreparedLog:
    """A log with everything the replay and the training need, row by row."""

    log: AuthorsLog
    horizon: float
    warm_up: float
    features: tuple[Features, ...]
    labels: tuple[Case | None, ...]
    future_center: np.ndarray  # (n, 2) centre at t + horizon, NaN where unknown
    velocity_window: float | None = None  # seconds; None: VelocityEstimator's 4 frames

    @property
    def warm(self) -> np.ndarray:
        """True for warm-up rows."""
        return self.log.time - self.log.time[0] < self.warm_up

    @property
    def has_future(self) -> np.ndarray:
        return np.isfinite(self.future_center[:, 0])

    @property
    def scored(self) -> np.ndarray:
        """Rows judged at the horizon (and usable for training)."""
        return ~self.warm & self.has_future

    def training_samples(self) -> list[TrainingSample]:
        """Scored rows with finite features, as image-mode training samples."""
        out: list[TrainingSample] = []
        for i in np.flatnonzero(self.scored):
            f = self.features[i]
            label = self.labels[i]
            values = feature_values(f, Mode.IMAGE)
            if label is None or not all(np.isfinite(v) for v in values.values()):
                continue
            h = f.apparent_height
            d = self.future_center[i] - np.asarray(f.center)
            k = self.horizon / h
            out.append(
                TrainingSample(
                    values,
                    label,
                    (float(d[0] / h), float(d[1] / h)),
                    velocity_displacement=(f.vx * k, f.vy * k),
                )
            )
        return out

    @property
    def velocity_note(self) -> str:
        """How the rows' vx, vy were measured (for a model's provenance)."""
        if self.velocity_window is None:
            return "monopic.features.motion.VelocityEstimator(window=4, average=4)"
        return (
            "least-squares slope of the centre over the trailing "
            f"{self.velocity_window:g} s (monopic.replay.dataset.window_velocities)"
        )


def recompute_velocities(log: AuthorsLog) -> np.ndarray:
    """(n, 2) centre velocity in px/s by our estimator, NaN for the first row."""
    est = VelocityEstimator()
    return np.array(
        [
            est.update(float(t), float(x), float(y))
            for t, x, y in zip(log.time, log.center_x, log.center_y, strict=True)
        ]
    )


def window_velocities(log: AuthorsLog, window: float) -> np.ndarray:
    """(n, 2) centre velocity in px/s: least-squares slope over the rows in [t - window, t].

    The row before is always included, so a gap in the log longer than the window still
    gives a two-point velocity; the first row has none (NaN).
    """
    if not window > 0:
        raise ValueError(f"velocity window must be positive, got {window}")
    t, x, y = log.time, log.center_x, log.center_y
    out = np.full((len(log), 2), np.nan)
    for i in range(1, len(log)):
        lo = min(int(np.searchsorted(t, t[i] - window, side="left")), i - 1)
        ts = t[lo : i + 1] - t[lo : i + 1].mean()
        denom = float(np.dot(ts, ts))
        out[i, 0] = np.dot(ts, x[lo : i + 1] - x[lo : i + 1].mean()) / denom
        out[i, 1] = np.dot(ts, y[lo : i + 1] - y[lo : i + 1].mean()) / denom
    return out


def prepare(
    log: AuthorsLog,
    horizon: float = HORIZON_S,
    warm_up: float = WARM_UP_S,
    velocity_window: float | None = None,
) -> PreparedLog:
    """Features, next-horizon labels and future centres for every row of `log`."""
    if not horizon > 0:
        raise ValueError(f"horizon must be positive, got {horizon}")
    t = log.time
    h = log.apparent_height
    foot_v = log.center_y + h / 2
    if velocity_window is None:
        vel = recompute_velocities(log)
    else:
        vel = window_velocities(log, velocity_window)
    features = tuple(
        Features(
            timestamp=float(t[i]),
            center=(float(log.center_x[i]), float(log.center_y[i])),
            foot=(float(log.center_x[i]), float(foot_v[i])),
            apparent_height=float(h[i]),
            phi=float(log.phi[i]),
            vx=float(vel[i, 0]),
            vy=float(vel[i, 1]),
        )
        for i in range(len(log))
    )
    future = np.full((len(log), 2), np.nan)
    labels: list[Case | None] = []
    for i in range(len(log)):
        t_end = t[i] + horizon
        if t_end > t[-1]:
            labels.append(None)
            continue
        inside = (t > t[i]) & (t < t_end)
        ts = np.concatenate([[t[i]], t[inside], [t_end]])
        u = np.interp(ts, t, log.center_x)
        labels.append(case_from_image_track(ts, u, np.interp(ts, t, foot_v), np.interp(ts, t, h)))
        future[i] = (u[-1], np.interp(t_end, t, log.center_y))
    return PreparedLog(log, horizon, warm_up, features, tuple(labels), future, velocity_window)
