"""Gymnasium environment `monopic/PedestrianCrossing-v0`: brake for a pedestrian you see.

A highway-env AbstractEnv (its config dict, road, controlled vehicle and top-down
viewer) whose dynamics are exactly World.step: one world step per simulation frame.

- observation: the robot camera's RGB frame, uint8 (H, W, 3) at the scenario camera's size;
- action: the robot's longitudinal acceleration in m/s^2, shape (1,), bounded by the
  robot's braking and acceleration limits;
- reward: `progress_reward` per metre driven plus `contact_reward` on contact;
- terminated on contact or once the pedestrian is behind the robot; truncated at the
  scenario's duration;
- info: the ground truth (GroundTruth.to_dict()) and the robot's own state; the typed
  records are on `env.unwrapped.world.last`.
- render modes: "rgb_array" returns the camera frame, "top_down" highway-env's bird's-eye
  view drawn offscreen.

The config key "scenario" holds a sim.scenario.spec.Scenario (default:
sim.scenario.cases.default_crossing).
Each reset draws the world's seed (the gait phase) from the env's RNG, so a seeded reset is
deterministic. Simulation and policy frequency default to 15 Hz.

Headless top-down view: pygame needs a video driver to start; with no display this module
selects SDL's "dummy" driver. highway-env's EnvViewer then disables drawing altogether
(it draws black frames under SDL_VIDEODRIVER=dummy), although drawing on an offscreen
pygame Surface needs no display: TopDownViewer re-enables it.
"""

from __future__ import annotations

import math
import os

import gymnasium
import numpy as np
from gymnasium import spaces
from highway_env.envs.common.abstract import AbstractEnv
from highway_env.envs.common.action import ActionType
from highway_env.envs.common.graphics import EnvViewer
from highway_env.envs.common.observation import ObservationType

from sim.scenario.cases import default_crossing
from sim.scenario.spec import Scenario
from sim.world.ground_truth import pedestrian_passed
from sim.world.robot import Robot
from sim.world.world import World, WorldStep


class CameraObservation(ObservationType):
    """The robot camera's frame."""

    def space(self) -> spaces.Space:
        cam = self.env.scenario.robot.camera
        return spaces.Box(0, 255, shape=(cam.height, cam.width, 3), dtype=np.uint8)

    def observe(self) -> np.ndarray:
        step = self.env.world_step
        assert step.frame is not None
        return step.frame.image.copy()


class AccelerationAction(ActionType):
    """Longitudinal acceleration in m/s^2, within the robot's limits."""

    def __init__(self, env: AbstractEnv, **kwargs: object) -> None:
        super().__init__(env)
        robot = env.scenario.robot
        self.low, self.high = -robot.max_deceleration, robot.max_acceleration
        self.last_action = 0.0

    def space(self) -> spaces.Space:
        return spaces.Box(self.low, self.high, shape=(1,), dtype=np.float32)

    @property
    def vehicle_class(self) -> type[Robot]:
        return Robot

    def act(self, action: np.ndarray | float) -> None:
        value = float(np.asarray(action, dtype=float).reshape(-1)[0])
        if not math.isfinite(value):
            raise ValueError(f"acceleration must be finite, got {value}")
        self.last_action = float(np.clip(value, self.low, self.high))


class TopDownViewer(EnvViewer):
    """highway-env's viewer, always drawing offscreen (even under the dummy video driver)."""

    def __init__(self, env: AbstractEnv) -> None:
        config = dict(env.config, offscreen_rendering=True)
        super().__init__(env, config)
        self.enabled = True


class PedestrianCrossingEnv(AbstractEnv):
    """See the module docstring."""

    metadata = {"render_modes": ["rgb_array", "top_down"], "render_fps": 15}

    def __init__(self, config: dict | None = None, render_mode: str | None = None) -> None:
        self.world: World | None = None
        self._progress = 0.0
        super().__init__(config, render_mode)

    @classmethod
    def default_config(cls) -> dict:
        config = super().default_config()
        config.update(
            {
                "scenario": None,  # a Scenario; None: sim.scenario.cases.default_crossing()
                "observation": {"type": "camera"},
                "action": {"type": "acceleration"},
                "simulation_frequency": 15,
                "policy_frequency": 15,
                "progress_reward": 0.1,  # per metre driven
                "contact_reward": -10.0,
                "screen_width": 600,
                "screen_height": 300,
                "scaling": 20.0,  # top-down view, px per metre
                "centering_position": [0.3, 0.5],
            }
        )
        return config

    @property
    def scenario(self) -> Scenario:
        scenario = self.config["scenario"]
        return default_crossing() if scenario is None else scenario

    @property
    def world_step(self) -> WorldStep:
        if self.world is None or self.world.last is None:
            raise RuntimeError("the environment has not been reset")
        return self.world.last

    def define_spaces(self) -> None:
        self.observation_type = CameraObservation(self)
        self.action_type = AccelerationAction(self)
        self.observation_space = self.observation_type.space()
        self.action_space = self.action_type.space()

    def _reset(self) -> None:
        scenario = self.scenario
        sim_freq = self.config["simulation_frequency"]
        if sim_freq % self.config["policy_frequency"] != 0:
            raise ValueError("simulation_frequency must be a multiple of policy_frequency")
        if self.world is None or self.world.scenario != scenario:
            if self.world is not None:
                self.world.close()
            self.world = World(scenario, render=True)
        self.world.reset(seed=int(self.np_random.integers(2**31 - 1)))
        self.road = self.world.road
        self.vehicle = self.world.robot
        self._progress = 0.0

    def _simulate(self, action: np.ndarray | None = None) -> None:
        """Whole World.steps at the simulation frequency with the action held."""
        assert self.world is not None and self.world.robot is not None
        if action is not None:
            self.action_type.act(action)
        frames = int(self.config["simulation_frequency"] // self.config["policy_frequency"])
        start = self.world.robot.world_pose
        for frame in range(frames):
            self.world.step(1.0 / self.config["simulation_frequency"], self.action_type.last_action)
            self.steps += 1
            if frame < frames - 1:
                self._automatic_rendering()
        end = self.world.robot.world_pose
        self._progress = math.hypot(end.x - start.x, end.y - start.y)
        self.enable_auto_render = False

    def _rewards(self, action: object) -> dict[str, float]:
        return {"progress": self._progress, "contact": float(self.world_step.truth.contact)}

    def _reward(self, action: object) -> float:
        r = self._rewards(action)
        return float(
            self.config["progress_reward"] * r["progress"]
            + self.config["contact_reward"] * r["contact"]
        )

    def _pedestrian_passed(self) -> bool:
        scenario = self.scenario
        return pedestrian_passed(
            self.world_step.truth, scenario.robot.length, scenario.pedestrian.footprint
        )

    def _is_terminated(self) -> bool:
        return bool(self.world_step.truth.contact or self._pedestrian_passed())

    def _is_truncated(self) -> bool:
        """At the scenario's duration, counted in frames (Scenario.frames) like World.run."""
        return bool(self.world_step.index >= self.scenario.frames)

    def _info(self, obs: np.ndarray, action: object = None) -> dict:
        step = self.world_step
        return {
            "time": step.time,
            "speed": step.ego.speed,
            "crashed": step.truth.contact,
            "action": float(self.action_type.last_action),
            "rewards": self._rewards(action),
            "pedestrian_passed": self._pedestrian_passed(),
            "truth": step.truth.to_dict(),
            "robot": step.truth.robot.to_dict(),
        }

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gymnasium.logger.warn(
                f"render() without a render mode; make the env with render_mode in "
                f"{self.metadata['render_modes']}"
            )
            return None
        if self.render_mode == "top_down":
            return self.render_top_down()
        return self.observation_type.observe()

    def render_top_down(self) -> np.ndarray:
        """highway-env's bird's-eye view of the road, robot and pedestrian, RGB (H, W, 3)."""
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
        if self.viewer is None:
            self.viewer = TopDownViewer(self)
        self.viewer.display()
        return self.viewer.get_image()

    def close(self) -> None:
        super().close()
        if self.world is not None:
            self.world.close()
            self.world = None
