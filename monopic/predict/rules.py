"""The authors' reference predictor: a hand-written cascade over the dead-zoned velocity.

The authors' code (SR42-dev/pedestrian-intention-fuzzy-classifier, MIT) decides the
direction with if/else rules on the smoothed image velocity and a dead zone of 20 px/s,
then extrapolates linearly along the chosen direction. Their extrapolation passed phi in
degrees to cos(); we do not reproduce that bug: the future point is the current point
plus the measured velocity along the axes the case says are moving.

In ground mode the same rule runs on the pedestrian's own ground velocity in the robot's
frame, with the ground dead zone of the case vocabulary.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from monopic.cases import GROUND_DEAD_ZONE_MPS, Case, case_from_ground_velocity
from monopic.features.record import Features
from monopic.predict.base import Mode, Prediction, extrapolate_ground, extrapolate_image
from monopic.predict.registry import no_model

IMAGE_DEAD_ZONE_PX_S = 20.0


def image_rule_case(vx: float, vy: float, dead_zone: float = IMAGE_DEAD_ZONE_PX_S) -> Case:
    """The authors' cascade: each image axis moves when its speed clears the dead zone.

    Moving down the image is toward the (static) camera, up is away.
    """
    if not (math.isfinite(vx) and math.isfinite(vy)):
        return Case.STILL
    lateral = (vx > dead_zone) - (vx < -dead_zone)
    down = (vy > dead_zone) - (vy < -dead_zone)
    return Case.from_signs(lateral, -down)


@dataclass(frozen=True)
class RulePredictor:
    """The reference rule cascade, in image or ground mode."""

    mode: Mode = Mode.IMAGE
    image_dead_zone: float = IMAGE_DEAD_ZONE_PX_S
    ground_dead_zone: float = GROUND_DEAD_ZONE_MPS
    name: str = "rules"

    def predict(self, features: Features, horizon: float) -> Prediction:
        if self.mode is Mode.IMAGE:
            case = image_rule_case(features.vx, features.vy, self.image_dead_zone)
            return extrapolate_image(features, case, horizon)
        if features.ground is None:
            raise ValueError("ground mode needs the camera model (ground features)")
        vf, vl = features.ground.velocity
        case = (
            case_from_ground_velocity(vf, vl, self.ground_dead_zone)
            if math.isfinite(vf) and math.isfinite(vl)
            else Case.STILL
        )
        return extrapolate_ground(features, case, horizon)


def rule_predictor(mode: Mode, model: Path | None = None) -> RulePredictor:
    """The `rules` entry of the predictor registry."""
    no_model("rules", model)
    return RulePredictor(mode=mode)
