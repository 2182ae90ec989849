"""The predictor interface: one frame's motion features in, a case and a future point out.

Every predictor (the authors' rule cascade, the ID3 tree, constant velocity) takes the
same `Features` and returns the same `Prediction`, so sweeps can run them side by side.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol

import numpy as np

from monopic.cases import Case
from monopic.features.record import Features, Point


class Mode(StrEnum):
    """Where motion is measured and predicted.

    IMAGE is the paper's method: image velocity, static-camera assumption. GROUND uses the
    foot point on the ground plane, compensates the robot's own motion and predicts in the
    robot's frame.
    """

    IMAGE = "image"
    GROUND = "ground"


@dataclass(frozen=True)
class Prediction:
    """Where the pedestrian will be `horizon` seconds after the features' timestamp."""

    case: Case
    horizon: float
    center: Point  # predicted centre on the image, px
    foot: Point  # predicted foot point on the image, px
    ground: Point | None = None  # predicted foot point, robot's current frame, m
    # What the pedestrian will do within the horizon, for predictors that say (the intent
    # tree: keep going, stop, turn away, start crossing); None for the others.
    intent: str | None = None


class Predictor(Protocol):
    """Anything that turns features into a prediction."""

    name: str
    mode: Mode

    def predict(self, features: Features, horizon: float) -> Prediction:
        """Predict `horizon` seconds ahead; must not keep hidden state between frames."""
        ...


def extrapolate_image(features: Features, case: Case, horizon: float) -> Prediction:
    """Future point = current point + measured image velocity along the case's axes.

    An axis the case says is not moving contributes nothing; the image axes follow the
    static-camera reading of the case (right = +u, away = up the image = -v).
    """
    dx = features.vx * horizon if case.lateral != 0 else 0.0
    dy = features.vy * horizon if case.depth != 0 else 0.0
    return Prediction(
        case=case,
        horizon=horizon,
        center=(features.center[0] + dx, features.center[1] + dy),
        foot=(features.foot[0] + dx, features.foot[1] + dy),
    )


def extrapolate_ground(features: Features, case: Case, horizon: float) -> Prediction:
    """Future ground point = foot point + own ground velocity along the case's axes.

    The image points are that ground point seen by the robot's current camera, with the
    centre kept above the foot at the apparent height the new distance gives.
    """
    g = features.ground
    if g is None:
        raise ValueError("ground extrapolation needs ground features (a camera model)")
    (x, y), (vf, vl) = g.position, g.velocity
    future = (
        x + (vf * horizon if case.depth != 0 else 0.0),
        y + (vl * horizon if case.lateral != 0 else 0.0),
    )
    return with_ground_point(features, case, horizon, future)


def with_ground_point(features: Features, case: Case, horizon: float, future: Point) -> Prediction:
    """A prediction whose image points are drawn from a predicted ground point."""
    g = features.ground
    if g is None:
        raise ValueError("a ground prediction needs ground features (a camera model)")
    foot = g.camera.project(np.array([future[0], future[1], 0.0]))
    scale = max(g.position[0], 1e-3) / max(future[0], 1e-3)
    cu, cv = features.center
    fu, fv = features.foot
    if not np.all(np.isfinite(foot)):  # behind the camera: keep the current image points
        return Prediction(case, horizon, features.center, features.foot, future)
    center = (float(foot[0]) + (cu - fu) * scale, float(foot[1]) + (cv - fv) * scale)
    return Prediction(case, horizon, center, (float(foot[0]), float(foot[1])), future)
