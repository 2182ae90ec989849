"""The crowd: JuPedSim moves its people together; each person is a PedestrianBody.

The crowd has no body of its own. When a run starts it works out every member's walk for
the whole run at once (sim.scenario.crowd_motion: the model needs everyone together, and
the truth needs each walk ahead of time, as every walker's), making way for the scripted
person and the bystanders, and hands each member's PedestrianBody its walk. It is listed
before the people, so its walks are given before they reset.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
from highway_env.road.road import Road

from sim.scenario.motion import people_tracks
from sim.scenario.spec import Scenario
from sim.world.entities.base import Entity
from sim.world.entities.pedestrian import PedestrianBody


class CrowdDirector(Entity):
    """Hands the crowd's members their walks at each reset (`members`: their bodies, in
    the crowd's order)."""

    name = "crowd"
    kind = "crowd"

    def __init__(self, scenario: Scenario, members: Sequence[PedestrianBody], t_end: float):
        self.scenario = scenario
        self.members = list(members)
        self.t_end = t_end

    def build(self, spec: mujoco.MjSpec) -> None:
        """Nothing to draw: the members are bodies of their own."""

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        tracks = people_tracks(self.scenario, seed, self.t_end)
        for body in self.members:
            body.follow(tracks[body.name])
