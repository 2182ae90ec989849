"""highway-env's top-down view of a World, drawn offscreen for the recordings."""

from __future__ import annotations

import os
from types import SimpleNamespace

import numpy as np

from sim.world.world import World


class TopDownCamera:
    """highway-env's bird's-eye view of a World's road, drawn offscreen.

    sim.envs.crossing.TopDownViewer wants an environment; it reads only the road, the ego vehicle,
    the config and the observation type, so a plain namespace carrying the World's own
    objects stands in for one.
    """

    def __init__(self, world: World) -> None:
        from sim.envs.crossing import PedestrianCrossingEnv, TopDownViewer

        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # pygame needs a driver
        self.world = world
        config = PedestrianCrossingEnv.default_config()
        # Zoom so the robot is about 30 px long: a 0.8 m robot at the car's 20 px/m was a
        # 16 px speck on an empty road.
        config["scaling"] = min(45.0, max(20.0, 30.0 / world.scenario.robot.length))
        self._host = SimpleNamespace(
            road=world.road, vehicle=world.robot, config=config, observation_type=None
        )
        self._viewer = TopDownViewer(self._host)  # type: ignore[arg-type]

    def render(self) -> np.ndarray:
        """RGB (H, W, 3) of the current state."""
        self._host.road, self._host.vehicle = self.world.road, self.world.robot
        self._viewer.display()
        return np.ascontiguousarray(self._viewer.get_image())

    def close(self) -> None:
        self._viewer.close()
