"""Who gets the landmark model first when it cannot run on everyone: the landmark budget.

The robot's path in the image is the column band below the camera's centre: a person
matters more the nearer they stand to it (lower in the frame: closer to the robot; nearer
the centre column: closer to its path) and the faster they close on it (moving toward
the centre column, or growing as they come nearer). The score adds the image fractions
that say so, each person's predicted `HORIZON` ahead, so a person walking fast toward the
path outranks one standing beside it. `turn` adds STALE_PER_SECOND for each second since
a person's last landmarks, the whole urgency scale a second, so everyone gets a turn:
within about a second even the least urgent person.
"""

from __future__ import annotations

from monopic.horizon import HORIZON_S
from monopic.people.box import Box

HORIZON = HORIZON_S  # s ahead, as the pipeline's prediction
STALE_PER_SECOND = 2.0


def urgency(box: Box, velocity: tuple[float, float], width: int, height: int) -> float:
    """About 0 (far off the path, top of the frame) to 2 (on the path, at the robot)."""
    x0, y0, x1, y1 = box
    centre = (x0 + x1) / 2
    lateral = abs(centre - width / 2) / (width / 2)
    toward = -velocity[0] if centre > width / 2 else velocity[0]  # px/s toward the centre
    lateral_ahead = max(lateral - HORIZON * toward / (width / 2), 0.0)
    nearness = min(max(y1 / height, 0.0), 1.0)  # feet low in the frame: near the robot
    # Coming nearer shows as the feet sinking down the frame (the centre's vertical
    # velocity stands in for the feet's).
    nearness_ahead = min(nearness + HORIZON * max(velocity[1], 0.0) / height, 1.0)
    return (1.0 - min(lateral_ahead, 1.0)) + nearness_ahead


def turn(urgency_now: float, stale: float) -> float:
    """A person's claim on the landmark model: urgency, plus the seconds since their last
    landmarks (`stale`; never run: as if a second ago)."""
    return urgency_now + STALE_PER_SECOND * min(stale, 1.0)
