"""The gymnasium environment monopic/PedestrianCrossing-v0, registered by a string entry point.

Importing this package registers the environment with gymnasium and loads nothing else:
gymnasium imports `sim.envs.crossing` (MuJoCo, highway-env, pygame) on the first
`gymnasium.make`, as highway-env registers its own environments. gymnasium 1.x has no
plug-in discovery, so it must be imported; three ways, each tested in tests/sim/test_env.py:

    gym.make("sim.envs:monopic/PedestrianCrossing-v0")  # gymnasium imports sim.envs

    import gymnasium as gym, sim  # gymnasium first: `import sim` registers it then
    gym.make("monopic/PedestrianCrossing-v0")

    import sim.envs  # any time
    gym.make("monopic/PedestrianCrossing-v0")

The scenario is the config's "scenario": a sim.scenario.spec.Scenario or a scenario
file's path, e.g. `config={"scenario": "scenarios/families/small/cpna25.toml"}`
(sim.envs.crossing).
"""

from __future__ import annotations

import gymnasium

ENV_ID = "monopic/PedestrianCrossing-v0"
# The longest episode: 60 s, the longest run a scenario may last (scenario files and
# CasePlacement), at the default 15 Hz policy frequency. The environment truncates each
# episode at its own scenario's duration, so this TimeLimit never cuts one short; pass
# max_episode_steps to gymnasium.make for a shorter limit.
MAX_EPISODE_STEPS = 60 * 15


def register_envs() -> None:
    """Register the environment (again importing is harmless)."""
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(
            id=ENV_ID,
            entry_point="sim.envs.crossing:PedestrianCrossingEnv",
            max_episode_steps=MAX_EPISODE_STEPS,
        )


register_envs()
