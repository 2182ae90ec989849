"""What the pipeline receives per frame: pixels, a timestamp, and the robot's own state.

Nothing here describes the pedestrian: the pipeline must find them in the pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monopic.camera import CameraModel


@dataclass(frozen=True)
class EgoState:
    """What a real robot knows about itself when the frame was taken."""

    camera: CameraModel
    speed: float  # m/s along its heading
    yaw_rate: float = 0.0  # rad/s, positive turning left


@dataclass(frozen=True)
class Frame:
    """One camera frame: RGB uint8 image (H, W, 3), capture time in seconds."""

    image: np.ndarray
    timestamp: float
    ego: EgoState | None = None
    index: int = 0

    def __post_init__(self) -> None:
        img = self.image
        if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
            raise ValueError(f"frame image must be HxWx3 uint8, got {img.shape} {img.dtype}")
