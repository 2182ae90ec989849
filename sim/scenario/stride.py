"""How long a step is at a walking speed, for a body of a given height.

Dynamic similarity: bodies of different size walking at the same Froude number take
the same shape of stride, so step length scales with stature and grows with the square
root of the size-normalised speed. An adult (1.8 m) at a comfortable 1.4 m/s takes about
1.8 steps per second. The mannequin's gait (sim.world.gait) and the human walker's
stride-level motion (sim.scenario.walkers.human) both use it, so legs and body move together.
"""

from __future__ import annotations

import math

ADULT_HEIGHT = 1.8  # m, the body size the reference gait is given for
REF_SPEED = 1.4  # m/s, comfortable adult walking speed
REF_CADENCE = 1.8  # steps/s at REF_SPEED for an adult of ADULT_HEIGHT
IDLE_SPEED = 0.05  # m/s: below this the person stands


def step_length(
    speed: float,
    height: float = ADULT_HEIGHT,
    ref_speed: float = REF_SPEED,
    ref_cadence: float = REF_CADENCE,
) -> float:
    """Step length (m) at `speed`; 0 when standing."""
    if speed <= IDLE_SPEED:
        return 0.0
    size = height / ADULT_HEIGHT
    comfortable = ref_speed * math.sqrt(size)  # the same Froude number
    return ref_speed / ref_cadence * size * math.sqrt(speed / comfortable)
