"""The simulated world of the MonoPIC test bed (MuJoCo scene, mannequin, ground truth).

MuJoCo picks its OpenGL backend when it is first imported, so the headless default
(EGL) is set here, before any sim module imports mujoco. A MUJOCO_GL already in the
environment wins.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
import sim.env  # noqa: E402, F401  (registers monopic/PedestrianCrossing-v0)
