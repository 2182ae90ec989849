"""Where the pedestrian stands against the robot's swept path, in the robot's frame.

The robot drives forward along its x axis; its swept path is the straight band of its
own width centred on that axis (the physical width: the warning's safety margin is a
choice of the warning, not a fact about the pedestrian). Forward distance along the
path is the ground position's x and needs no feature of its own.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PathOffset:
    """The foot point's lateral place against the band."""

    offset: float  # m, signed distance from the centre line, + to the robot's left
    distance: float  # m, lateral distance to the band's nearer edge, 0 inside the band


def path_offset(position: tuple[float, float], robot_width: float) -> PathOffset:
    """Offset and distance of a ground point (forward, left) m from a band `robot_width` m wide."""
    if not robot_width > 0:
        raise ValueError(f"robot width must be positive metres, got {robot_width}")
    left = float(position[1])
    return PathOffset(left, max(0.0, abs(left) - robot_width / 2))
