"""Constant-velocity baseline: keep every component of the measured velocity.

The yardstick any direction classifier must beat: the case it reports is the rule
cascade's, but the future point uses the full velocity, not only the case's axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from monopic.cases import GROUND_DEAD_ZONE_MPS, case_from_ground_velocity
from monopic.features.record import Features
from monopic.predict.base import Mode, Prediction, with_ground_point
from monopic.predict.registry import no_model
from monopic.predict.rules import IMAGE_DEAD_ZONE_PX_S, image_rule_case


@dataclass(frozen=True)
class ConstantVelocityPredictor:
    mode: Mode = Mode.IMAGE
    name: str = "constant-velocity"

    def predict(self, features: Features, horizon: float) -> Prediction:
        if self.mode is Mode.IMAGE:
            vx = features.vx if math.isfinite(features.vx) else 0.0
            vy = features.vy if math.isfinite(features.vy) else 0.0
            case = image_rule_case(vx, vy, IMAGE_DEAD_ZONE_PX_S)
            (cu, cv), (fu, fv) = features.center, features.foot
            dx, dy = vx * horizon, vy * horizon
            return Prediction(case, horizon, (cu + dx, cv + dy), (fu + dx, fv + dy))
        g = features.ground
        if g is None:
            raise ValueError("ground mode needs the camera model (ground features)")
        vf, vl = g.velocity
        if not (math.isfinite(vf) and math.isfinite(vl)):
            vf = vl = 0.0
        case = case_from_ground_velocity(vf, vl, GROUND_DEAD_ZONE_MPS)
        future = (g.position[0] + vf * horizon, g.position[1] + vl * horizon)
        return with_ground_point(features, case, horizon, future)


def constant_velocity_predictor(mode: Mode, model: Path | None = None) -> ConstantVelocityPredictor:
    """The `constant-velocity` entry of the predictor registry."""
    no_model("constant-velocity", model)
    return ConstantVelocityPredictor(mode=mode)
