"""bench/simulator.py's camera rows: the parts chosen, the scenarios, the child's figures and
the table (no timing is judged here: speed is measured by the benchmark itself)."""

from __future__ import annotations

import argparse
from typing import Any

import pytest

from bench import simulator
from bench.simulator import WARM_STEPS, camera_report, child_camera
from sim.sensor.sensor import Sensor
from sim.world import shutter as shutter_module
from sim.world import world as world_module
from sim.world.scene import Scene


def only(**chosen: bool) -> argparse.Namespace:
    flags = {f"{part}_only": chosen.get(part, False) for part in simulator.ONLY}
    return argparse.Namespace(**flags)


def test_the_only_options_choose_their_parts_and_none_runs_them_all() -> None:
    assert simulator.chosen_parts(only(camera=True)) == {"camera"}
    assert simulator.chosen_parts(only(camera=True, people=True)) == {"camera", "people"}
    everything = simulator.chosen_parts(only())
    assert everything == {"main", "people_runs", "crowd", "people", "camera", "night"}


def test_the_blur_rows_drive_the_car_fast_under_clouds_with_a_fixed_long_exposure() -> None:
    s = simulator.fast_scenario(30, simulator.blur_sensor(4))
    assert s.robot.speed == simulator.FAST_SPEED and s.robot.width == 1.8
    assert s.frames == 30 and s.scene.lighting.illuminance_lux == 1000.0
    sensor = s.robot.camera.sensor
    assert sensor.exposure_ms == simulator.BLUR_EXPOSURE_MS and sensor.gain == 1.0
    assert sensor.max_subframes == 4 and simulator.blur_sensor().max_subframes == 12
    # The person crosses 15 m beyond where the car is when they pass: it never gets there.
    anchor = s.pedestrian.anchor
    assert anchor.x - s.robot.speed * anchor.time == pytest.approx(15.0)
    assert simulator.fast_scenario(30).robot.camera.sensor is None


def test_the_camera_child_times_both_cameras_the_blur_and_the_readout_and_unwraps_after() -> None:
    before = (world_module.World.render, world_module.World._ground_truth,
              shutter_module.linear_light, Sensor.read, Scene.image_motion)  # fmt: skip
    got = child_camera(WARM_STEPS + 2, rounds=1, draws=(1, 2), repeats=2)
    after = (world_module.World.render, world_module.World._ground_truth,
             shutter_module.linear_light, Sensor.read, Scene.image_motion)  # fmt: skip
    assert after == before
    for light in ("sun", "overcast"):
        ideal, real = got[light]["ideal"], got[light]["real"]
        assert ideal["frames"] == real["frames"] == 1
        assert ideal["exposure_p50_ms"] is None and ideal["readout_p50_ms"] == 0.0
        assert real["exposure_p50_ms"] > 0 and real["readout_p50_ms"] > 0
        assert real["step_p50_ms"] >= real["render_p50_ms"] + real["readout_p50_ms"]
    # The clouds' 1,000 lux against the sun's 32,000: a longer exposure.
    assert got["overcast"]["real"]["exposure_p50_ms"] > got["sun"]["real"]["exposure_p50_ms"]
    blur = got["blur"]
    assert blur["1"]["draws_max"] == 1 and blur["2"]["draws_max"] == 2
    # 30 ms at 50 km/h smears the near ground over tens of pixels: more draws than 2.
    assert blur["auto"]["draws_min"] > 2 and blur["auto"]["blur_p50_px"] > 2.0
    assert got["readout"]["shape"] == [432, 768, 3] and got["readout"]["read_p50_ms"] > 0
    assert got["segmentation"]["masks_p50_ms"] > 0

    results, table = camera_report(got, WARM_STEPS + 2)
    assert [p["lighting"] for p in results["pairs"]] == ["sun", "overcast"]
    assert [r["camera"] for r in results["blur"]["rows"]] == ["ideal", "1", "2", "auto"]
    assert "per_draw_ms" in results["blur"]
    assert table.count("\n| 30 ms, at most ") == 2


def summary(step: float, render: float, readout: float = 0.0, draws: int = 1) -> dict[str, Any]:
    real = readout > 0
    return {
        "frames": 27, "step_p50_ms": step, "step_p95_ms": step + 5.0, "render_p50_ms": render,
        "truth_p50_ms": 4.0, "linear_p50_ms": 2.0 * real, "readout_p50_ms": readout,
        "motion_p50_ms": 0.5 * real, "draws_mean": float(draws), "draws_min": draws,
        "draws_max": draws, "exposure_p50_ms": 0.2 if real else None,
        "gain_p50": 1.0 if real else None, "blur_p50_px": 30.0 if real else None,
    }  # fmt: skip


def test_the_report_judges_each_lighting_against_the_goal_and_fits_the_cost_of_a_draw() -> None:
    got = {
        "rounds": 2,
        "lux": {"sun": 32000.0, "overcast": 1000.0},
        "sun": {"ideal": summary(40.0, 30.0), "real": summary(56.0, 30.0, 20.0),
                "paired_ratio_p50_x": 1.39},
        "overcast": {"ideal": summary(20.0, 15.0), "real": summary(40.0, 15.0, 20.0),
                     "paired_ratio_p50_x": 2.1},
        "blur": {"ideal": summary(20.0, 15.0), "1": summary(40.0, 15.0, 20.0, 1),
                 "2": summary(55.0, 30.0, 20.0, 2), "4": summary(85.0, 60.0, 20.0, 4),
                 "auto": summary(205.0, 180.0, 20.0, 12)},
        "blur_exposure_ms": 30.0,
        "blur_speed_mps": 13.9,
        "readout": {"shape": [432, 768, 3], "repeats": 40, "exposure_ms": 0.2, "gain": 1.0,
                    "read_p50_ms": 20.0, "read_p95_ms": 22.0, "linear_light_p50_ms": 1.5,
                    "linear_light_p95_ms": 1.6},
        "segmentation": {"masks_p50_ms": 14.0, "masks_p95_ms": 15.0, "depth_read_p50_ms": 1.0,
                         "depth_read_p95_ms": 1.1, "render_again_p50_ms": 30.0,
                         "render_again_p95_ms": 31.0},
        "maxrss_mb": 500.0,
    }  # fmt: skip
    results, table = camera_report(got, 30)
    sun, cloud = results["pairs"]
    assert sun["real_over_ideal_x"] == pytest.approx(1.4)
    assert cloud["real_over_ideal_x"] == pytest.approx(2.0)
    assert "sun 1.40x (met); overcast 2.00x (not met)" in table
    assert results["blur"]["per_draw_ms"] == pytest.approx(15.0)
    assert results["blur"]["render_per_draw_ms"] == pytest.approx(15.0)
    assert results["segmentation"]["floor_over_render_x"] == pytest.approx(0.5)
    assert "| 30 ms, the preset's cap | 12.00 (12-12) | 205.0 ms " in table
    assert "| sun, 32,000 lux | 0.20 ms, x1.0, 1-1 | 40.0 ms |" in table
