"""The MonoPIC test bed: a simulated world, runs through the real pipeline, their analysis.

MuJoCo picks its OpenGL backend when it is first imported, so the headless default
(EGL) is set here, before any sim module imports mujoco. A MUJOCO_GL already in the
environment wins.

gymnasium (1.x) finds an environment only once the module registering it is imported,
and `import sim` loads no gymnasium (tests/test_layers.py: the light modules stay light).
So the environment is registered here when gymnasium is already loaded: `import gymnasium
as gym, sim` is enough before `gym.make("monopic/PedestrianCrossing-v0")`, gymnasium
first. Imported the other way round (sim, or any sim module, first), nothing is
registered: use `gym.make("sim.envs:monopic/PedestrianCrossing-v0")`, which imports
sim.envs whatever was imported before (sim.envs documents both).
"""

import os
import sys

os.environ.setdefault("MUJOCO_GL", "egl")

if "gymnasium" in sys.modules:
    import sim.envs  # noqa: F401 - registers the environment, loads nothing heavy
