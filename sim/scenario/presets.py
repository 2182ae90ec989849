"""The simulator's defaults, each written once: what a scenario gets where it says nothing.

The dataclasses (sim.scenario.spec), the case placement (sim.scenario.cases), the scenario
file loader (sim.scenario.files), the shipped test clip (sim.dataset.clip) and the commands
(through the placement) read them; scenarios/README.md's key tables document them and
tests/sim/test_presets.py holds the two together. The two robot scales built on them
(robot, camera, road and horizon per scale) are sim.scenario.families.SMALL and CAR.
Plain values only: sim.scenario.spec stands on this module.
"""

from __future__ import annotations

from monopic.horizon import HORIZON_S as HORIZON_S  # the pipeline's, re-exported

# The run: its length, frame rate (the paper's data's) and, from monopic.horizon, the
# pipeline's warning horizon (the small scale's; the car's is its own).
DURATION_S = 4.0  # s
MAX_DURATION_S = 60.0  # s, the longest run a scenario may ask for
FPS = 15.0  # frames per second
FPS_RANGE = (1.0, 60.0)  # frames per second a scenario may ask for
MAX_HORIZON_S = 10.0  # s, the longest warning horizon a scenario may ask for

# The pedestrian: walking speed (about 5 km/h), the side of the square it occupies on the
# ground, and the statures a mannequin can have.
PEDESTRIAN_SPEED = 1.4  # m/s
MAX_PEDESTRIAN_SPEED = 10.0  # m/s
FOOTPRINT = 0.5  # m
HEIGHT_RANGE = (0.8, 2.2)  # m

# The small camera-carrying robot: speed and size.
ROBOT_SPEED = 2.0  # m/s
ROBOT_WIDTH = 0.6  # m
ROBOT_LENGTH = 0.8  # m

# Its forward camera, the project's default camera.
CAMERA_WIDTH = 768  # px
CAMERA_HEIGHT = 432  # px
CAMERA_FOV_DEG = 65.0  # vertical field of view, degrees
CAMERA_MOUNT_HEIGHT = 1.2  # m above the ground
CAMERA_PITCH_DEG = 5.0  # degrees, positive looks down
