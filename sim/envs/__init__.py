"""The gymnasium environment monopic/PedestrianCrossing-v0, registered by a string entry point.

Importing this package registers the environment with gymnasium and loads nothing else:
gymnasium imports `sim.envs.crossing` (MuJoCo, highway-env, pygame) on the first
`gymnasium.make`, as highway-env registers its own environments. Without importing it,
`gymnasium.make("sim.envs:monopic/PedestrianCrossing-v0")` imports it for you.
"""

from __future__ import annotations

import gymnasium

ENV_ID = "monopic/PedestrianCrossing-v0"


def register_envs() -> None:
    """Register the environment (again importing is harmless)."""
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(id=ENV_ID, entry_point="sim.envs.crossing:PedestrianCrossingEnv")


register_envs()
