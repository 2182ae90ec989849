"""The mannequin's landmark sites: where BlazePose's 33 points sit on the body.

The builder adds one site per landmark to the body part it belongs to, and the compiled
mannequin reads their world positions as the ground truth the pose tracker is scored
against; both find a site by the name `landmark_site` gives, so they cannot drift apart.
"""

from __future__ import annotations

from monopic.pose.skeleton import LANDMARK_NAMES

# BlazePose's 33 landmarks, indexed as MediaPipe numbers them; left/right are the
# person's own. One list for the whole project: the pipeline's.
BLAZEPOSE_NAMES = LANDMARK_NAMES
N_LANDMARKS = len(BLAZEPOSE_NAMES)

# Geom and site groups: the robot camera shows geom groups 0-2; sites are kept in a
# hidden group so the landmark markers never show up in a frame.
SITE_GROUP = 4


def landmark_site(prefix: str, index: int) -> str:
    """Name of the site marking BlazePose landmark `index` on the mannequin `prefix`."""
    return f"{prefix}lm{index:02d}"
