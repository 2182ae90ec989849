"""The gymnasium environment monopic/PedestrianCrossing-v0 on top of World.step."""

from __future__ import annotations

import subprocess
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from monopic.cases import Case
from monopic.errors import UserError
from sim.envs import ENV_ID
from sim.envs.crossing import PedestrianCrossingEnv
from sim.scenario.cases import CasePlacement, default_crossing
from sim.scenario.files import load
from sim.scenario.spec import CameraSpec, RoadLayout, Scenario
from tests.paths import ROOT

SMALL = CameraSpec(width=160, height=90)


def small(sc: Scenario) -> Scenario:
    return replace(
        sc,
        robot=replace(sc.robot, camera=SMALL),
        scene=replace(sc.scene, road=RoadLayout(buildings=False)),
    )


def make(render_mode: str = "rgb_array", **config: object) -> PedestrianCrossingEnv:
    config.setdefault("scenario", small(default_crossing()))
    env = gym.make(ENV_ID, config=config, render_mode=render_mode)
    return env.unwrapped  # type: ignore[return-value]


def test_passes_the_gymnasium_env_checker_without_a_warning() -> None:
    env = make()
    try:
        assert env.observation_space.shape == (90, 160, 3)
        assert env.action_space == gym.spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env)  # includes the render check of every declared mode
        assert [str(w.message) for w in caught] == []
    finally:
        env.close()


def test_the_normalised_action_maps_onto_the_robots_limits() -> None:
    env = make()
    try:
        env.reset(seed=0)
        robot = env.scenario.robot
        act = env.action_type
        brake, accelerate = robot.max_deceleration, robot.max_acceleration
        cases = [(-1.0, -brake), (-0.5, -brake / 2), (0.0, 0.0), (0.5, accelerate / 2),
                 (1.0, accelerate), (-3.0, -brake), (7.0, accelerate)]  # fmt: skip
        for action, expected in cases:
            assert act.to_acceleration(action) == pytest.approx(expected)
        _, _, _, _, info = env.step(np.array([-0.25], dtype=np.float32))
        assert info["action"] == -0.25
        assert info["acceleration"] == pytest.approx(-0.25 * robot.max_deceleration)
        assert info["speed"] == pytest.approx(robot.speed - 0.25 * robot.max_deceleration / 15)
        with pytest.raises(ValueError, match="the action must be finite"):
            env.step(np.array([np.nan], dtype=np.float32))
    finally:
        env.close()


def test_render_fps_is_the_step_rate_and_episodes_have_a_registered_limit() -> None:
    """gymnasium's RecordVideo plays at render_fps: highway-env's doubled rate played the
    episode at twice its speed."""
    from sim.envs import MAX_EPISODE_STEPS
    from sim.scenario.cases import PLACEMENT_FIELDS

    assert gym.spec(ENV_ID).max_episode_steps == MAX_EPISODE_STEPS
    assert PLACEMENT_FIELDS["duration"].metadata["high"] * 15 == MAX_EPISODE_STEPS
    for policy_frequency in (15, 5):
        wrapped = gym.make(
            ENV_ID,
            config={"scenario": small(default_crossing()), "policy_frequency": policy_frequency},
            render_mode="rgb_array",
        )
        try:
            assert wrapped.metadata["render_fps"] == policy_frequency
            wrapped.reset(seed=0)
            assert wrapped.metadata["render_fps"] == policy_frequency
            assert wrapped.spec.max_episode_steps == MAX_EPISODE_STEPS
        finally:
            wrapped.close()
    assert PedestrianCrossingEnv.metadata["render_fps"] == 15  # the class's own is untouched


def test_registered_under_its_id_as_a_highway_env() -> None:
    from highway_env.envs.common.abstract import AbstractEnv

    assert ENV_ID in gym.registry
    env = make()
    try:
        assert isinstance(env, AbstractEnv)
        assert env.vehicle is env.world.robot and env.road is env.world.road
        assert env.world.pedestrian in env.road.objects
    finally:
        env.close()


def rollout(seed: int, actions: list[float]) -> list[tuple]:
    env = make()
    try:
        obs, info = env.reset(seed=seed)
        out = [(obs, 0.0, False, False, info)]
        for a in actions:
            out.append(env.step(np.array([a], dtype=np.float32)))
    finally:
        env.close()
    return out


def test_deterministic_for_a_seed() -> None:
    actions = [0.2, 0.0, -0.125, -0.25, 0.3]
    a, b, c = rollout(7, actions), rollout(7, actions), rollout(8, actions)
    for (oa, ra, ta, ua, ia), (ob, rb, tb, ub, ib) in zip(a, b, strict=True):
        assert np.array_equal(oa, ob)
        assert (ra, ta, ua) == (rb, tb, ub)
        assert ia == ib
    # Another seed starts the gait elsewhere: other pixels, same path.
    assert not np.array_equal(a[0][0], c[0][0])
    assert a[-1][4]["truth"]["position_world"] == c[-1][4]["truth"]["position_world"]


def test_one_world_step_per_simulation_frame() -> None:
    env = make(policy_frequency=5)
    try:
        env.reset(seed=0)
        _, reward, _, _, info = env.step(np.array([0.0], dtype=np.float32))
        assert env.world.index == 3  # 15 Hz simulation, 5 Hz policy
        assert info["time"] == pytest.approx(3 / 15)
        assert reward == pytest.approx(0.1 * 2.0 * 3 / 15)  # progress reward per metre
    finally:
        env.close()


def test_contact_terminates_with_a_penalty_and_braking_avoids_it() -> None:
    sc = small(replace(default_crossing(), duration=3.5))  # contact at 2.7 s when not braking
    env = make(scenario=sc)
    try:
        env.reset(seed=0)
        terminated = truncated = False
        while not (terminated or truncated):
            _, reward, terminated, truncated, info = env.step(np.array([0.0], dtype=np.float32))
        assert terminated and info["crashed"] and info["truth"]["contact"]
        assert reward < -9.0
        env.reset(seed=0)
        terminated = truncated = False
        steps = 0
        while not (terminated or truncated):
            _, reward, terminated, truncated, info = env.step(np.array([-1.0], dtype=np.float32))
            steps += 1
        assert truncated and not terminated and not info["crashed"]
        assert steps == sc.frames
        assert info["robot"]["speed"] == 0.0
    finally:
        env.close()


def test_passing_the_pedestrian_terminates() -> None:
    sc = small(
        CasePlacement(Case.AWAY, distance=3.0, lateral_offset=3.0, robot_speed=4.0).scenario()
    )
    env = make(scenario=sc)
    try:
        env.reset(seed=0)
        terminated = False
        for _ in range(sc.frames):
            _, _, terminated, truncated, info = env.step(np.array([0.0], dtype=np.float32))
            if terminated or truncated:
                break
        assert terminated and info["pedestrian_passed"] and not info["crashed"]
    finally:
        env.close()


def test_rgb_array_is_the_camera_frame() -> None:
    env = make("rgb_array")
    try:
        obs, _ = env.reset(seed=0)
        image = env.render()
        assert image is not None and image.shape == (90, 160, 3) and image.dtype == np.uint8
        assert np.array_equal(image, obs)
        assert image.std() > 10  # a street, not a blank buffer
    finally:
        env.close()


def test_top_down_view_is_drawn_under_the_dummy_video_driver(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """highway-env draws nothing under SDL_VIDEODRIVER=dummy; our viewer must still draw,
    with north up: a pedestrian on the robot's left (north) is above it in the view."""
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    sc = small(
        CasePlacement(Case.STILL, distance=6.0, lateral_offset=3.0, robot_speed=0.0).scenario()
    )
    env = make("top_down", scenario=sc)
    try:
        env.reset(seed=0)
        view = env.render()
        assert view is not None and view.shape == (300, 600, 3)
        assert view.max() > 0 and len(np.unique(view.reshape(-1, 3), axis=0)) >= 4
        r, g, b = (view[..., k].astype(int) for k in range(3))
        robot = np.argwhere((g > 180) & (r < 120) & (b < 60))  # ego green (lightened)
        pedestrian = np.argwhere((r == 200) & (g == 200) & (b == 0))  # road-object yellow
        assert len(robot) > 20 and len(pedestrian) > 20
        (r_row, r_col), (p_row, p_col) = robot.mean(axis=0), pedestrian.mean(axis=0)
        assert p_row < r_row - 40  # 3 m north at 20 px/m
        assert p_col > r_col + 80  # 6 m east (ahead)
    finally:
        env.close()


# A user's own scenario file: a case-5 crossing, small camera, no buildings.
MY_SCENARIO = """
name = "my-crossing"
kind = "collision"
scale = "small"
duration = 1.0
[robot]
speed = 1.5
[robot.camera]
width = 160
height = 90
[pedestrian]
speed = {speed}
[path]
kind = "case"
case = 5
distance = 3.0
[scene.road]
buildings = false
"""


def my_scenario(folder: Path, speed: float = 1.4) -> Path:
    path = folder / "my-crossing.toml"
    path.write_text(MY_SCENARIO.format(speed=speed))
    return path


@pytest.mark.parametrize("as_path", [str, Path], ids=["str", "Path"])
def test_a_scenario_file_path_in_the_config_runs_its_base_scenario(
    tmp_path: Path, as_path: type
) -> None:
    path = my_scenario(tmp_path)
    env = make(scenario=as_path(path))
    try:
        assert env.scenario == load(path).base and env.config["scenario"] == env.scenario
        obs, _ = env.reset(seed=0)
        assert obs.shape == (90, 160, 3)
        _, _, _, _, info = env.step(np.array([0.0], dtype=np.float32))
        assert info["speed"] == pytest.approx(1.5)  # the file's robot speed
        # Another file on reset, as highway-env's options={"config": ...} allows.
        other = tmp_path / "other.toml"
        other.write_text(path.read_text().replace("speed = 1.5", "speed = 0.5"))
        env.reset(seed=0, options={"config": {"scenario": other}})
        assert env.scenario == load(other).base and env.world.scenario == env.scenario
    finally:
        env.close()


def test_a_bad_scenario_in_the_config_is_one_clear_error(tmp_path: Path) -> None:
    missing = tmp_path / "missing.toml"
    bad = my_scenario(tmp_path, speed=-1.0)
    with pytest.raises(UserError) as expected:
        load(bad)  # what `monopic record` says of the same file
    assert str(expected.value).startswith(f"{bad}: pedestrian.speed = -1.0: ")
    spec = ROOT / "scenarios" / "sweeps" / "demo.toml"
    cases = [
        (str(missing), f"{missing}: no such scenario file"),
        (bad, str(expected.value)),
        (spec, f"{spec}: this is a sweep spec, not a scenario file (it lists scenario files "
         f"under [[include]]): run it with `monopic sweep {spec}`"),
        (3, 'config["scenario"] = 3: expected a sim.scenario.spec.Scenario or a scenario '
         "file's path (str or pathlib.Path)"),
    ]  # fmt: skip
    for value, message in cases:
        with pytest.raises(UserError) as info:
            gym.make(ENV_ID, config={"scenario": value})
        assert str(info.value) == message


MAKE_IN_A_FRESH_PYTHON = """
import sys
{imports}
env = gym.make({env_id!r}, config={{"scenario": sys.argv[1]}}, render_mode="rgb_array")
obs, _ = env.reset(seed=0)
print(obs.shape)
env.close()
"""


@pytest.mark.parametrize(
    ("imports", "env_id"),
    [
        ("import gymnasium as gym", f"sim.envs:{ENV_ID}"),  # gymnasium imports sim.envs
        ("import gymnasium as gym, sim", ENV_ID),  # `import sim` registers it
    ],
    ids=["module-prefix", "import-sim"],
)
def test_made_without_importing_sim_envs(imports: str, env_id: str, tmp_path: Path) -> None:
    # gymnasium 1.x has no plug-in discovery: without one of these, gymnasium answers
    # "Namespace monopic not found. Have you installed the proper package for monopic?"
    code = MAKE_IN_A_FRESH_PYTHON.format(imports=imports, env_id=env_id)
    result = subprocess.run(
        [sys.executable, "-c", code, str(my_scenario(tmp_path))],
        capture_output=True, text=True, cwd=tmp_path, timeout=300,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-1500:]
    assert result.stdout.strip() == "(90, 160, 3)"


def test_import_sim_before_gymnasium_registers_nothing() -> None:
    # The order the docs give matters: registering it here would mean importing gymnasium,
    # which `import sim` must not load.
    code = (
        "import sys, sim, gymnasium\n"
        "print('gymnasium' in sys.modules, 'monopic/PedestrianCrossing-v0' in gymnasium.registry)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.split() == ["True", "False"], result.stderr[-1500:]


def test_the_readme_example_runs_as_written() -> None:
    readme = (ROOT / "README.md").read_text()
    blocks = [b.split("```", 1)[0] for b in readme.split("```python\n")[1:]]
    # The simulated world's example, with a shipped scenario file (the README's own-file
    # section has one of its own, run by tests/test_walkthrough.py).
    (example,) = [b for b in blocks if 'config={"scenario": "scenarios/' in b]
    assert "sim.envs:monopic/PedestrianCrossing-v0" in example
    code = example + "\nprint(obs.shape == env.observation_space.shape)\nenv.close()\n"
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert result.stdout.strip() == "True", result.stderr[-1500:]
