"""Gymnasium environment `monopic/PedestrianCrossing-v0`: brake for a pedestrian you see.

A highway-env AbstractEnv (its config dict, road, controlled vehicle and top-down
viewer) whose dynamics are exactly World.step: one world step per simulation frame.

- observation: the robot camera's RGB frame, uint8 (H, W, 3) at the scenario camera's size;
- action: shape (1,) in [-1, 1], the robot's longitudinal acceleration as a share of its
  limits: -1 brakes at RobotSpec.max_deceleration, +1 accelerates at max_acceleration,
  0 holds the speed (linear on each side; gymnasium's check_env wants a normalised,
  symmetric space); `info["acceleration"]` is the m/s^2 it became;
- reward: `progress_reward` per metre driven plus `contact_reward` on contact;
- terminated on contact or once the pedestrian is behind the robot; truncated at the
  scenario's duration (registered with max_episode_steps = sim.envs.MAX_EPISODE_STEPS, the
  longest run a scenario may last, so gymnasium's TimeLimit never cuts an episode first);
- info: the ground truth (GroundTruth.to_dict()) and the robot's own state; the typed
  records are on `env.unwrapped.world.last`.
- render modes: "rgb_array" returns the camera frame, "top_down" highway-env's bird's-eye
  view drawn offscreen.

The config key "scenario" holds a sim.scenario.spec.Scenario or a scenario file's path (a
str or pathlib.Path: its base scenario, the file without its sweep, as `monopic record FILE`
runs it); default sim.scenario.cases.default_crossing. A path is read when the env is
configured (made, or reset with options={"config": ...}), and env.config then holds its
Scenario; a missing or bad file is a monopic.errors.UserError naming the file and the field,
as the commands report it.
Each reset draws the world's seed (the gait phase) from the env's RNG, so a seeded reset is
deterministic. Simulation and policy frequency default to 15 Hz; `metadata["render_fps"]`
is the rate frames are rendered at, one per step (highway-env doubles it, which would
make a recorded video play at twice the speed).

Headless top-down view: pygame needs a video driver to start; with no display this module
selects SDL's "dummy" driver. highway-env's EnvViewer then disables drawing altogether
(it draws black frames under SDL_VIDEODRIVER=dummy), although drawing on an offscreen
pygame Surface needs no display: TopDownViewer re-enables it.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import gymnasium
import numpy as np
from gymnasium import spaces
from highway_env.envs.common.abstract import AbstractEnv
from highway_env.envs.common.action import ActionType
from highway_env.envs.common.graphics import EnvViewer
from highway_env.envs.common.observation import ObservationType

from monopic.errors import UserError
from sim.scenario.cases import default_crossing
from sim.scenario.files import load
from sim.scenario.spec import Scenario
from sim.world.ground_truth import pedestrian_passed
from sim.world.robot import Robot
from sim.world.world import World, WorldStep


def scenario_of(value: object) -> Scenario | None:
    """The config's "scenario" as a Scenario (None: the default crossing).

    A str or os.PathLike is a scenario file: its base scenario (sim.scenario.files.load,
    whose UserError names the file and the bad field).
    """
    if value is None or isinstance(value, Scenario):
        return value
    if isinstance(value, str | os.PathLike):
        return load(Path(value)).base
    raise UserError(
        f'config["scenario"] = {value!r}: expected a sim.scenario.spec.Scenario or a '
        "scenario file's path (str or pathlib.Path)"
    )


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
    """A normalised action in [-1, 1] mapped onto the robot's braking and acceleration limits.

    -1 is the robot's full brake (max_deceleration), +1 its full acceleration
    (max_acceleration), 0 coasting at constant speed; linear on each side, so an agent
    sees one symmetric space whatever robot the scenario has.
    """

    def __init__(self, env: AbstractEnv, **kwargs: object) -> None:
        super().__init__(env)
        robot = env.scenario.robot
        self.max_deceleration, self.max_acceleration = (
            robot.max_deceleration,
            robot.max_acceleration,
        )
        self.last_action = 0.0  # the normalised action, clipped to [-1, 1]
        self.acceleration = 0.0  # what it means, m/s^2

    def space(self) -> spaces.Space:
        return spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)

    @property
    def vehicle_class(self) -> type[Robot]:
        return Robot

    def to_acceleration(self, action: float) -> float:
        """m/s^2 for a normalised action (clipped to [-1, 1])."""
        a = float(np.clip(action, -1.0, 1.0))
        return a * (self.max_deceleration if a < 0 else self.max_acceleration)

    def act(self, action: np.ndarray | float) -> None:
        value = float(np.asarray(action, dtype=float).reshape(-1)[0])
        if not math.isfinite(value):
            raise ValueError(f"the action must be finite, got {value}")
        self.last_action = float(np.clip(value, -1.0, 1.0))
        self.acceleration = self.to_acceleration(value)


class TopDownViewer(EnvViewer):
    """highway-env's viewer, always drawing offscreen (even under the dummy video driver)."""

    def __init__(self, env: AbstractEnv) -> None:
        config = dict(env.config, offscreen_rendering=True)
        super().__init__(env, config)
        self.enabled = True


class PedestrianCrossingEnv(AbstractEnv):
    """A robot drives along a street while a pedestrian crosses or walks; brake or not.

    Observation: the robot camera's RGB frame (H, W, 3) uint8, what the pipeline sees.
    Action: one number in [-1, 1], the longitudinal acceleration as a share of the
    robot's limits (-1: full brake, 0: hold speed, +1: full acceleration).
    Reward: `progress_reward` per metre driven, `contact_reward` on contact.
    Episode: terminated on contact or once the pedestrian is behind the robot, truncated
    at the scenario's duration; info holds the ground truth and the robot's state.
    Config: "scenario" (a sim.scenario.spec.Scenario or a scenario file's path; default
    sim.scenario.cases.default_crossing), the frequencies (15 Hz) and highway-env's
    viewer keys. Render modes: "rgb_array" (the camera frame), "top_down" (highway-env's
    bird's-eye view), at `metadata["render_fps"]` = the policy frequency.
    Each step is whole World.steps, the dynamics sweeps and the closed loop use.
    """

    metadata = {"render_modes": ["rgb_array", "top_down"], "render_fps": 15}

    def __init__(self, config: dict | None = None, render_mode: str | None = None) -> None:
        self.world: World | None = None
        self._progress = 0.0
        super().__init__(config, render_mode)
        self.update_metadata()

    def update_metadata(self, video_real_time_ratio: int = 2) -> None:
        """render_fps = the rate frames are rendered at: one per step (policy frequency), or
        one per simulation frame while highway-env's own video wrapper records them.

        highway-env multiplies it by `video_real_time_ratio` (a video would play at twice
        the speed) and writes it into the class's dict; here it is the true rate, and the
        instance's own (ratio ignored)."""
        steps = "simulation_frequency" if self._record_video_wrapper else "policy_frequency"
        self.metadata = {**type(self).metadata, "render_fps": self.config[steps]}

    def configure(self, config: dict | None) -> None:
        """highway-env's configure, with "scenario" read at once (a path becomes the
        file's Scenario): a bad value fails here, saying why, rather than somewhere inside
        highway-env when the scenario is first used."""
        super().configure(config)
        self.config["scenario"] = scenario_of(self.config["scenario"])

    @classmethod
    def default_config(cls) -> dict:
        config = super().default_config()
        config.update(
            {
                "scenario": None,  # None: sim.scenario.cases.default_crossing() (scenario_of)
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
            self.world.step(
                1.0 / self.config["simulation_frequency"], self.action_type.acceleration
            )
            self.steps += 1
            if frame < frames - 1:
                self._automatic_rendering()
        end = self.world.robot.world_pose
        self._progress = math.hypot(end.x - start.x, end.y - start.y)
        self.enable_auto_render = False

    def _rewards(self, action: object) -> dict[str, float]:
        return {
            "progress": self._progress,
            "contact": float(self.world_step.truth.pedestrian.contact),
        }

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
        return bool(self.world_step.truth.pedestrian.contact or self._pedestrian_passed())

    def _is_truncated(self) -> bool:
        """At the scenario's duration, counted in frames (Scenario.frames) like World.run."""
        return bool(self.world_step.index >= self.scenario.frames)

    def _info(self, obs: np.ndarray, action: object = None) -> dict:
        step = self.world_step
        return {
            "time": step.time,
            "speed": step.ego.speed,
            "crashed": step.truth.pedestrian.contact,
            "action": float(self.action_type.last_action),  # normalised, [-1, 1]
            "acceleration": float(self.action_type.acceleration),  # m/s^2
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
