"""A camera that sees like a camera (sim.sensor, sim.world.shutter): noise that matches the
sensor's figures, blur that matches the motion, the ideal camera untouched, bad figures
refused in one line."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
from highway_env.road.road import Road

from sim.scenario.files import load
from sim.scenario.ncap import load_car
from sim.scenario.spec import CameraSpec, PedestrianSpec, RoadLayout, RobotSpec, Scenario, SceneSpec
from sim.scenario.toml_table import FieldError
from sim.sensor.exposure import ExposureState
from sim.sensor.photometry import electrons_per_second
from sim.sensor.readout import linear_light, srgb_decode
from sim.sensor.sensor import Sensor
from sim.sensor.spec import IMX273, SensorSpecError, preset
from sim.world.entities.base import Entity, Moment, Sight
from sim.world.world import World

ROOT = Path(__file__).resolve().parents[2]
STILL = Scenario(
    name="still",
    pedestrian=PedestrianSpec(x=8.0, y=4.0, heading_deg=-90.0, speed=0.0),
    robot=RobotSpec(speed=0.0, camera=CameraSpec(320, 180)),
    scene=SceneSpec(road=RoadLayout(buildings=False)),
    duration=0.4,
)


def with_sensor(scenario: Scenario, sensor: object, lux: float | None = None) -> Scenario:
    robot = replace(scenario.robot, camera=replace(scenario.robot.camera, sensor=sensor))
    scene = scenario.scene
    if lux is not None:
        scene = replace(scene, lighting=replace(scene.lighting, illuminance_lux=lux))
    return replace(scenario, robot=robot, scene=scene)


# -- the ideal camera ---------------------------------------------------------------


def test_the_ideal_camera_gives_the_renderers_frames_as_they_are() -> None:
    assert CameraSpec().sensor is None and preset("ideal") is None
    with World(STILL) as world:
        step = world.reset()
        assert step.frame is not None and step.truth.camera is None
        assert np.array_equal(step.frame.image, world.render())
        assert "camera" not in step.truth.to_dict()


def test_a_real_camera_keeps_the_run_ids_of_the_scenario_apart() -> None:
    from sim.scenario.spec import scenario_text

    assert "sensor" not in scenario_text(STILL)
    assert "imx273" in scenario_text(with_sensor(STILL, IMX273))


# -- noise --------------------------------------------------------------------------


def flat_patch(image: np.ndarray) -> tuple[np.ndarray, int]:
    """The pixels (a mask over H x W x 3) of the render's most common 8-bit value: a flat
    patch, where every pixel has the same light."""
    values, counts = np.unique(image, return_counts=True)
    value = int(values[np.argmax(counts)])
    return image == value, value


def predicted_sigma(spec: object, light: float, rate: float, t: float, gain: float) -> float:
    """The output's noise (8-bit steps) from the sensor's figures alone: shot noise on the
    mean electrons and read noise, times the gain and the digitiser's scale, through the
    slope of the sRGB curve at the mean, plus the 8-bit rounding."""
    mean_e = light * rate * t
    sigma_e = math.sqrt(mean_e + spec.read_noise_e**2)  # type: ignore[attr-defined]
    scale = gain / spec.full_well_e  # type: ignore[attr-defined]
    y, sigma_y = mean_e * scale, sigma_e * scale
    slope = 1.055 / 2.4 * y ** (1 / 2.4 - 1)  # d(sRGB)/dy above the linear toe
    return math.sqrt((255.0 * slope * sigma_y) ** 2 + 1 / 12)


@pytest.mark.parametrize("gain", [1.0, 4.0, 16.0])
def test_noise_off_a_flat_patch_matches_the_sensors_figures(gain: float) -> None:
    with World(STILL) as world:
        world.reset()
        render = world.render()
    patch, value = flat_patch(render)
    light = float(srgb_decode(np.array(value / 255.0)))
    assert patch.sum() > 2000 and light > 0.05
    lux = STILL.scene.lighting.illuminance_lux
    rate = electrons_per_second(IMX273, lux)
    t = 0.1 * IMX273.full_well_e / (gain * light * rate)  # the patch at 10 % of full scale
    spec = replace(IMX273, exposure_ms=max(1000.0 * t, IMX273.min_exposure_ms), gain=gain)
    t = spec.exposure_ms / 1000.0
    sensor = Sensor(spec, lux, STILL.dt, seed=3)
    image, state = sensor.read(linear_light(render), ExposureState(t, gain))
    measured = float(image[patch].astype(float).std())
    expected = predicted_sigma(spec, light, rate, t, gain)
    assert expected > 1.0  # noise well above the 8-bit step at every gain
    assert measured == pytest.approx(expected, rel=0.08)
    assert state.gain == gain


def test_noise_grows_with_gain_at_the_same_brightness() -> None:
    light = np.full((64, 64, 3), 0.2, np.float32)
    lux = 1000.0
    rate = electrons_per_second(IMX273, lux)
    spread, means = [], []
    for gain in (1.0, 4.0, 16.0):
        t = 0.15 * IMX273.full_well_e / (gain * 0.2 * rate)
        spec = replace(IMX273, exposure_ms=1000.0 * t, gain=gain)
        image, _ = Sensor(spec, lux, 1 / 15, seed=1).read(light, ExposureState(t, gain))
        spread.append(image.astype(float).std())
        means.append(image.astype(float).mean())
    assert max(means) - min(means) < 2  # the same brightness whatever the gain ...
    assert spread[0] < spread[1] < spread[2]  # ... noisier the more of it is gain


# -- blur ---------------------------------------------------------------------------

BAR_SPEED = 6.0  # m/s, sideways
BAR_AHEAD = 6.0  # m in front of the camera


class SlidingBar(Entity):
    """A tall magenta bar sliding sideways across the road ahead at BAR_SPEED."""

    name = "bar"

    def __init__(self) -> None:
        self.y = 1.2

    def build(self, spec: mujoco.MjSpec) -> None:
        body = spec.worldbody.add_body(name=self.name, mocap=True)
        body.add_geom(
            name=self.prefix + "box", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 0.3, 0.8],
            rgba=[1.0, 0.0, 1.0, 1.0], contype=0, conaffinity=0,
        )  # fmt: skip

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._mocap = int(model.body(self.name).mocapid[0])
        self._body = int(model.body(self.name).id)

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        self.y = 1.2

    def before_step(self, dt: float) -> None:
        self.y -= BAR_SPEED * dt

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        data.mocap_pos[self._mocap] = (moment.robot.x + BAR_AHEAD, self.y, 0.8)

    def truth(self, model: mujoco.MjModel, data: mujoco.MjData, sight: Sight) -> np.ndarray:
        centre = data.xpos[self._body].copy()
        return sight.camera.project(sight.robot.pose.to_local(centre))


def bar_edges(image: np.ndarray, row: int, column: float) -> float:
    """The smear of the bar along one row, within 60 px of its centre: (width above 10 % of
    the contrast - width above 90 %) / 1.6, which for a bar blurred over B pixels (a
    trapezoid) is B."""
    lo, hi = max(0, int(column) - 60), int(column) + 60
    red = image[row, lo:hi, 0].astype(float) - image[row, lo:hi, 1].astype(float)  # magenta
    low, high = np.median(red), red.max()
    span = high - low
    return (np.sum(red > low + 0.1 * span) - np.sum(red > low + 0.9 * span)) / 1.6


def test_a_bar_moving_at_a_known_speed_smears_by_the_expected_pixels() -> None:
    exposure_ms = 25.0
    spec = replace(IMX273, exposure_ms=exposure_ms, gain=1.0, noise=False, tone="linear",
                   max_subframes=16)  # fmt: skip
    cam = CameraSpec(640, 360)
    scenario = replace(STILL, robot=replace(STILL.robot, camera=cam))
    sharp_spec = replace(spec, motion_blur=False)
    smears = {}
    for name, s in (("blurred", spec), ("sharp", sharp_spec)):
        with World(with_sensor(scenario, s, lux=150.0), extra=(SlidingBar(),)) as world:
            first = world.reset()
            step = world.step()
            assert step.frame is not None and step.truth.camera is not None
            u0 = first.truth.bodies["bar"]
            u1, v1 = step.truth.bodies["bar"]
            smears[name] = bar_edges(step.frame.image, int(round(v1)), u1)
            moved = float(np.hypot(*(np.asarray((u1, v1)) - np.asarray(u0))))
            draws = step.truth.camera.subframes
    expected = moved * (exposure_ms / 1000.0) / scenario.dt
    assert expected > 5.0
    assert smears["blurred"] == pytest.approx(expected, abs=1.5)
    assert smears["sharp"] < 1.5
    assert draws == 1  # the sharp camera drew once


# -- auto-exposure ------------------------------------------------------------------


def test_auto_exposure_meets_its_target_and_follows_a_change_with_a_lag() -> None:
    spec = replace(IMX273, ae_time_constant_s=0.2)
    sensor = Sensor(spec, 32000.0, 1 / 15, seed=0)
    bright = np.full((40, 40, 3), 0.5, np.float32)
    sensor.meter(bright)
    _, state = sensor.read(bright, sensor.settings())
    assert state.signal == pytest.approx(spec.ae_target, rel=0.05)
    dark = bright / 8  # the light falls three stops
    signals = []
    for _ in range(30):
        _, state = sensor.read(dark, sensor.settings())
        signals.append(state.signal)
    assert signals[0] < 0.5 * spec.ae_target  # not at once ...
    assert signals[-1] == pytest.approx(spec.ae_target, rel=0.05)  # ... but within 2 s
    assert all(b >= a - 1e-3 for a, b in zip(signals, signals[1:], strict=False))


def test_exposure_is_spent_on_time_before_gain() -> None:
    sensor = Sensor(IMX273, 5.0, 1 / 15, seed=0)  # five lux: dusk
    sensor.meter(np.full((40, 40, 3), 0.2, np.float32))
    state = sensor.settings()
    assert state.exposure_s == pytest.approx(IMX273.max_exposure_ms / 1000.0)
    assert state.gain > 1.0


# -- bad input: one line each -------------------------------------------------------


def scenario_file(tmp_path: Path, camera: str, fps: float | None = None) -> Path:
    text = (ROOT / "scenarios/cases/case1_oblique_right_away.toml").read_text()
    if fps is not None:
        assert "\nfps = 15\n" in text
        text = text.replace("\nfps = 15\n", f"\nfps = {fps}\n")
    path = tmp_path / "s.toml"
    path.write_text(text + "\n[robot.camera]\n" + camera + "\n")
    return path


@pytest.mark.parametrize(
    ("camera", "fps", "field", "says"),
    [
        ('preset = "nikon"', None, "robot.camera.preset", "must be one of ideal, imx273"),
        ('preset = "imx273"\nexposure_ms = 25.0', 60.0, "robot.camera.exposure_ms",
         "longer than the frame interval"),
        ('preset = "imx273"\nread_noise_e = -1.0', None, "robot.camera.read_noise_e", ">= 0"),
        ("exposure_ms = 5.0", None, "robot.camera.exposure_ms", "ideal camera has no sensor"),
        ('preset = "imx273"\ngain = 4.0', None, "robot.camera.gain", "needs a fixed exposure"),
    ],
)  # fmt: skip
def test_bad_camera_figures_are_refused_naming_the_field(
    tmp_path: Path, camera: str, fps: float | None, field: str, says: str
) -> None:
    path = scenario_file(tmp_path, camera, fps)
    with pytest.raises(FieldError) as err:
        load(path).scenario({}, name="s")
    message = str(err.value)
    assert field in message and says in message and "\n" not in message
    assert str(path) in message


def test_a_camera_slower_than_the_scenario_is_refused() -> None:
    with pytest.raises(SensorSpecError, match="fps = 300.0: the imx273 camera runs at most 226"):
        IMX273.check_frame_rate(1 / 300)


def test_a_negative_noise_figure_is_refused_in_code_too() -> None:
    with pytest.raises(SensorSpecError, match="read_noise_e = -2.0: must be >= 0"):
        replace(IMX273, read_noise_e=-2.0)


def test_the_car_file_names_its_camera_and_bad_names_are_refused(tmp_path: Path) -> None:
    car = load_car(ROOT / "scenarios/ncap/car.toml")
    assert car.sensor is IMX273 or car.sensor == IMX273
    bad = tmp_path / "car.toml"
    text = (ROOT / "scenarios/ncap/car.toml").read_text().replace('preset = "imx273"',
                                                                 'preset = "gopro"')  # fmt: skip
    bad.write_text(text)
    with pytest.raises(FieldError, match="camera.preset = 'gopro': must be one of ideal, imx273"):
        load_car(bad)


# -- the camera's state in results and recordings -------------------------------------


@pytest.mark.slow
def test_a_real_cameras_exposure_is_in_the_result_line_and_the_recording(tmp_path: Path) -> None:
    from monopic.cases import Case
    from sim.runs.record import record_run
    from sim.runs.result import RunResult
    from sim.runs.run_spec import RunSpec
    from sim.runs.runner import run
    from sim.scenario.cases import CasePlacement
    from tests.sim.test_sim_recording import blueprint_views, values

    base = CasePlacement(Case(5), duration=0.6, seed=2).scenario()
    real = with_sensor(base, IMX273)
    result = run(RunSpec(id="real", scenario=real, stop_at_contact=False))
    assert result.exposure is not None
    exposure = result.exposure
    assert len(exposure.exposure_ms) == result.frames == len(exposure.gain)
    assert all(0 < ms <= IMX273.max_exposure_ms for ms in exposure.exposure_ms)
    again = RunResult.from_json(result.to_json())
    assert again.exposure == result.exposure
    ideal = run(RunSpec(id="ideal", scenario=base, stop_at_contact=False))
    assert ideal.exposure is None and "exposure" not in ideal.to_json()

    rrd = tmp_path / "real.rrd"
    record_run(real, rrd, stop_at_contact=False)
    logged = values(rrd, "/sensor/exposure_ms")
    assert len(logged) == result.frames
    assert logged == pytest.approx(exposure.exposure_ms, abs=1e-3)
    views = blueprint_views(rrd)
    assert views["camera: exposure (ms), gain, sub-frame draws"]["origin"] == "sensor"


def test_compression_changes_the_frame_a_little() -> None:
    light = np.tile(np.linspace(0.02, 0.6, 96, dtype=np.float32)[None, :, None], (64, 1, 3))
    spec = replace(IMX273, exposure_ms=0.2, gain=1.0, noise=False)
    sharp, _ = Sensor(spec, 32000.0, 1 / 15, seed=0).read(light, ExposureState(2e-4, 1.0))
    jpeg, _ = Sensor(replace(spec, jpeg_quality=30), 32000.0, 1 / 15, seed=0).read(
        light, ExposureState(2e-4, 1.0)
    )
    diff = np.abs(sharp.astype(int) - jpeg.astype(int))
    assert diff.max() > 0 and diff.mean() < 3
