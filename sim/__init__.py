"""The MonoPIC test bed: a simulated world, runs through the real pipeline, their analysis.

MuJoCo picks its OpenGL backend when it is first imported, so the headless default
(EGL) is set here, before any sim module imports mujoco. A MUJOCO_GL already in the
environment wins.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
