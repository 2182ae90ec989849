"""bench/simulator.py's night rows: the scenarios and the child's figures (no timing is
judged here: speed is measured by the benchmark itself)."""

from __future__ import annotations

from bench.simulator import WARM_STEPS, child_night, night_report, night_scenarios


def test_the_night_rows_run_the_same_point_by_day_at_night_and_without_the_blur() -> None:
    s = night_scenarios(10)
    assert set(s) == {"day", "night", "night_ideal", "night_one_draw"}
    assert all(sc.frames == 10 for sc in s.values())
    assert not s["day"].scene.lighting.night and s["night"].scene.lighting.night
    assert s["night"].robot.headlamps is not None and s["night"].scene.lamps
    assert s["night_ideal"].robot.camera.sensor is None
    assert s["night_one_draw"].robot.camera.sensor.max_subframes == 1
    assert s["day"].pedestrian == s["night"].pedestrian


def test_the_night_child_times_each_world_and_the_table_names_them() -> None:
    got = child_night(WARM_STEPS + 3, rounds=1)
    assert got["night"]["frames"] == got["day"]["frames"] == 2
    assert got["night"]["exposure_p50_ms"] > got["day"]["exposure_p50_ms"]
    assert got["night_one_draw"]["draws_max"] == 1 and got["night_ideal"]["exposure_p50_ms"] is None
    _, table = night_report(got, WARM_STEPS + 3)
    for name in ("day", "night", "night_ideal", "night_one_draw"):
        assert f"\n| {name} |" in table
