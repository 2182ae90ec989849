"""Variant 1: collision warning. COLLISION IMMINENT when the prediction falls in the zone.

Risk levels as the authors coded them: green while the person's landmarks span under half
the frame height, yellow above, red when the predicted point is in the robot's zone.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np

from monopic.features.record import Features
from monopic.frame import EgoState
from monopic.predict.base import Mode, Prediction
from monopic.variants.zone import (
    RobotGeometry,
    default_image_zone,
    image_zone,
    meets_swept_footprint,
    point_in_polygon,
)


class Risk(StrEnum):
    GREEN = "green"
    YELLOW = "yellow"
    RED = "red"


@dataclass(frozen=True)
class Warning:
    collision: bool
    risk: Risk
    zone: np.ndarray  # image polygon of the robot's zone, pixels
    time_to_contact: float | None = None  # ground mode: predicted time of meeting, s


@dataclass(frozen=True)
class CollisionWarning:
    """Judges predictions against the zone the robot will occupy."""

    robot: RobotGeometry = RobotGeometry()
    zone_polygon: np.ndarray | None = None  # fixed image zone; overrides camera geometry

    def zone_for(self, image_size: tuple[int, int], ego: EgoState | None, horizon: float):
        if self.zone_polygon is not None:
            return np.asarray(self.zone_polygon, dtype=float)
        if ego is None:
            return default_image_zone(*image_size)
        return image_zone(ego.camera, self.robot, ego.speed, horizon)

    def assess(
        self,
        features: Features,
        prediction: Prediction,
        mode: Mode,
        image_size: tuple[int, int],
        ego: EgoState | None,
    ) -> Warning:
        zone = self.zone_for(image_size, ego, prediction.horizon)
        ttc = None
        if mode is Mode.GROUND:
            if features.ground is None or prediction.ground is None or ego is None:
                collision = False
            else:
                ttc = meets_swept_footprint(
                    features.ground.position,
                    prediction.ground,
                    self.robot,
                    ego.speed,
                    ego.yaw_rate,
                    prediction.horizon,
                )
                collision = ttc is not None
        else:
            collision = point_in_polygon(prediction.foot, zone)
        if collision:
            risk = Risk.RED
        elif features.apparent_height >= 0.5 * image_size[1]:
            risk = Risk.YELLOW
        else:
            risk = Risk.GREEN
        return Warning(collision, risk, zone, ttc)
