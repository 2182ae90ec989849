"""A constant-velocity Kalman filter for the pedestrian's foot point on the ground.

Why not finite differences: one pixel of foot-point jitter is 0.5 m on the ground at 15 m
and 2 m at 30 m (the ground distance grows with the square of the range), so a velocity
differenced over a few frames reads tens of metres per second on a distant or freshly
found pedestrian, and a one-second extrapolation of it lands anywhere. Here each
measurement carries its own covariance, the camera's pixel noise carried through the
ground projection (long and thin along the line of sight, growing with range), the
velocity starts from a walking-speed prior instead of from the first difference, and a
measurement too far from the prediction to be the same person walking is not believed.

The filter works in a fixed frame (the robot's odometry frame), so a standing pedestrian
stays put while the robot moves.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Chi-square, 2 degrees of freedom, 99.9 %: beyond it a measurement is not this track.
GATE_CHI2 = 13.82


@dataclass(frozen=True)
class GroundTrackConfig:
    """Noise model. Defaults measured or physical, not tuned on sweep outcomes:

    - pixel noise: the foot point's robust spread against the true foot in the medium
      sweep was 1.3 px at 20-40 m (people about 20 px tall), 1.8 px at 10-20 m (40 px),
      2.5 px at 5-10 m (80 px), 6 px under 5 m (200 px and more): about 1 px plus 2.5 %
      of the apparent height;
    - acceleration: a walker starting, stopping or turning changes velocity by about
      1.5 m/s within a second;
    - initial speed: walking speed is 1-2 m/s, so a new track's velocity starts at 0 with
      a 2 m/s standard deviation in each direction;
    - column noise: by default the column is as noisy as the row (isotropic pixels). With
      the ground column taken from the hips the column is steadier than the row: its
      robust spread against the truth's ground point projected was 0.5 px at about 45 px
      tall, 1.0 px at 80, 1.4 px at 125 and 2.6 px at 200 on the development intent sweep
      (docs/intent/ground-tree.md), about 0.3 px plus 1 % of the apparent height.
      Setting `column_pixel_noise` gives the column its own model, so the track believes
      motion across the line of sight sooner than motion along it.
    """

    pixel_noise: float = 1.0  # px, plus `pixel_noise_per_height` x apparent height
    pixel_noise_per_height: float = 0.025
    column_pixel_noise: float | None = None  # px; None: the column as noisy as the row
    column_pixel_noise_per_height: float = 0.0
    acceleration: float = 1.5  # m/s^2, standard deviation of the white acceleration
    initial_speed: float = 2.0  # m/s, standard deviation of the velocity prior
    min_position_noise: float = 0.05  # m: the ground itself is not perfectly flat
    max_rejections: int = 3  # measurements in a row outside the gate before restarting

    def __post_init__(self) -> None:
        for name in ("pixel_noise", "acceleration", "initial_speed", "min_position_noise"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)}")
        if self.pixel_noise_per_height < 0:
            raise ValueError(
                f"pixel_noise_per_height must be >= 0, got {self.pixel_noise_per_height}"
            )
        if self.column_pixel_noise is not None and not self.column_pixel_noise > 0:
            raise ValueError(f"column_pixel_noise must be positive, got {self.column_pixel_noise}")
        if self.column_pixel_noise_per_height < 0:
            raise ValueError(
                "column_pixel_noise_per_height must be >= 0, got "
                f"{self.column_pixel_noise_per_height}"
            )


@dataclass
class GroundTrack:
    """State [x, y, vx, vy] in a fixed frame, metres and metres per second."""

    config: GroundTrackConfig = field(default_factory=GroundTrackConfig)
    x: np.ndarray | None = None
    P: np.ndarray | None = None
    t: float | None = None
    rejected: int = 0
    starts: int = 0  # times the track (re)started: a window fed from it restarts too

    def update(self, t: float, z: np.ndarray, R: np.ndarray) -> bool:
        """Fold in a position measurement `z` (2,) with covariance `R` (2, 2) taken at `t`.

        Returns False when the measurement was outside the gate and not used.
        """
        z = np.asarray(z, dtype=float)
        if self.x is None or self.P is None or self.t is None:
            self._start(t, z, R)
            return True
        if t <= self.t:
            raise ValueError(f"timestamps must increase: {t} after {self.t}")
        x, P = self._predicted(t - self.t)
        H = np.eye(2, 4)
        y = z - H @ x
        S = H @ P @ H.T + R
        if float(y @ np.linalg.solve(S, y)) > GATE_CHI2:
            self.rejected += 1
            if self.rejected >= self.config.max_rejections:
                self._start(t, z, R)  # it was not noise: someone else, or a jump
                return True
            self.x, self.P, self.t = x, P, t
            return False
        K = P @ H.T @ np.linalg.inv(S)
        self.x = x + K @ y
        I_KH = np.eye(4) - K @ H
        self.P = I_KH @ P @ I_KH.T + K @ R @ K.T  # Joseph form: stays symmetric
        self.t = t
        self.rejected = 0
        return True

    @property
    def position(self) -> np.ndarray:
        if self.x is None:
            raise ValueError("the track has no state yet")
        return self.x[:2].copy()

    @property
    def velocity(self) -> np.ndarray:
        if self.x is None:
            raise ValueError("the track has no state yet")
        return self.x[2:].copy()

    def reset(self) -> None:
        self.x, self.P, self.t, self.rejected = None, None, None, 0

    def _start(self, t: float, z: np.ndarray, R: np.ndarray) -> None:
        s2 = self.config.initial_speed**2
        self.x = np.array([z[0], z[1], 0.0, 0.0])
        self.P = np.zeros((4, 4))
        self.P[:2, :2] = R
        self.P[2:, 2:] = np.eye(2) * s2
        self.t = t
        self.rejected = 0
        self.starts += 1

    def _predicted(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        assert self.x is not None and self.P is not None
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        q = self.config.acceleration**2
        Q1 = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
        Q = np.zeros((4, 4))
        Q[np.ix_([0, 2], [0, 2])] = Q1
        Q[np.ix_([1, 3], [1, 3])] = Q1
        return F @ self.x, F @ self.P @ F.T + Q
