"""bench/simulator.py's people rows: the crowd, the child's figures and the table (no timing
is judged here: speed is measured by the benchmark itself)."""

from __future__ import annotations

import pytest

from bench import simulator
from bench.simulator import BYSTANDERS, PARTS, WARM_STEPS, child_people, crowd, people_report
from sim.world import world as world_module
from sim.world.entities import pedestrian as pedestrian_module


def test_the_crowd_grows_from_the_scripted_person_with_named_bystanders() -> None:
    one, five = crowd(1, 30), crowd(5, 30)
    assert one.bystanders == () and one.pedestrian == five.pedestrian
    assert [p.name for p in five.bystanders] == ["b1", "b2", "b3", "b4"]
    assert len(crowd(len(BYSTANDERS) + 1, 30).people) == len(BYSTANDERS) + 1
    with pytest.raises(ValueError, match="people must be 1 to"):
        crowd(len(BYSTANDERS) + 2, 30)


def test_no_two_bystanders_stand_or_walk_into_each_other() -> None:
    # A row (one y) keeps one heading and speed, so the gaps at the start hold all run long;
    # rows lie further apart than a person's footprint.
    for k, (x, y, heading, speed) in enumerate(BYSTANDERS):
        for x2, y2, heading2, speed2 in BYSTANDERS[k + 1 :]:
            if y == y2:
                assert (heading, speed) == (heading2, speed2)
                assert abs(x - x2) >= 2.0
            else:
                assert abs(y - y2) >= 0.8


def test_the_people_child_times_every_part_for_each_crowd_and_unwraps_after() -> None:
    render, truth = world_module.World.render, world_module.World._ground_truth
    seen, rays = pedestrian_module.visibility, pedestrian_module.occluded_landmarks
    out = child_people(WARM_STEPS + 2, (1, 2), rounds=1)
    for n in ("1", "2"):
        for light in ("sun", "overcast"):
            row = out[n][light]
            assert row["frames"] == 1
            assert row["in_frame_min"] == int(n)
            for part in ("step", *PARTS, "rest"):
                assert row[f"{part}_p50_ms"] >= 0.0
            assert row["truth_p50_ms"] >= row["visibility_p50_ms"]
    # The wrappers are gone once the child is done.
    assert world_module.World.render is render
    assert world_module.World._ground_truth is truth
    assert pedestrian_module.visibility is seen
    assert pedestrian_module.occluded_landmarks is rays

    results, table = people_report(out, WARM_STEPS + 2)
    assert [r["people"] for r in results["rows"]] == [1, 2]
    assert results["rows"][0]["vs_one_x"] == pytest.approx(1.0)
    assert "fps_10_over_1_x" not in results  # no 10-person row to read it from
    assert table.count("\n| 1 (1; ") == 1 and table.count("\n| 2 (2; ") == 1


def test_the_report_gives_the_ten_over_one_ratio_against_the_stretch_goal() -> None:
    def row(step: float, render: float) -> dict[str, float]:
        parts = {f"{p}_p50_ms": 1.0 for p in PARTS}
        return parts | {
            "step_p50_ms": step, "step_p95_ms": step, "render_p50_ms": render,
            "rest_p50_ms": 0.5, "frames": 10, "in_frame_min": 1, "seen_mean": 1.0,
        }  # fmt: skip

    people = {
        "1": {"sun": row(50.0, 40.0), "overcast": row(30.0, 20.0)},
        "10": {"sun": row(100.0, 70.0), "overcast": row(60.0, 30.0)},
        "rounds": 2,
        "maxrss_mb": 300.0,
    }
    results, table = people_report(people, 30)
    assert results["fps_10_over_1_x"] == pytest.approx(0.5)
    assert results["rows"][1]["shadow_pass_ms"] == pytest.approx(40.0)
    assert f"0.50 (stretch goal {simulator.PEOPLE_STRETCH_X:g}: not met)" in table


def test_the_bench_crowd_has_the_members_asked_for_beside_the_scripted_person() -> None:
    for n in simulator.CROWD_SIZES:
        s = simulator.crowd_scenario(n, 30)
        assert s.crowd is not None and s.crowd.count == n and len(s.people) == n + 1
        assert s.frames == 30


def test_the_crowd_table_gives_the_model_beside_the_rendered_frame() -> None:
    got = {
        "5": {"total_ms_per_frame": 1.0, "jupedsim_ms_per_frame": 0.5,
              "jupedsim_ms_per_iteration": 0.05, "world_step_p50_ms": 100.0,
              "seconds_worked": 9.0},
        "rounds": 3,
    }  # fmt: skip
    results, table = simulator.crowd_report(got, 60)
    assert results["crowd"]["5"]["world_step_p50_ms"] == 100.0
    assert "| 5 | 0.50 ms | 1.00 ms | 0.050 ms | 100 ms | 0.010 |" in table


def test_the_people_runs_report_gives_each_count_and_tracker_against_one_person() -> None:
    from bench.simulator import people_runs_report

    got = {
        "rounds": 2,
        "maxrss_mb": 900.0,
        "1/one": {"wall_s": [10.0, 12.0], "frames": 40},
        "1/everyone": {"wall_s": [14.0, 14.0], "frames": 40},
        "5/one": {"wall_s": [20.0, 22.0], "frames": 40},
        "5/everyone": {"wall_s": [40.0, 44.0], "frames": 40},
    }
    results, table = people_runs_report(got, 40)
    rows = {(r["people"], r["tracker"]): r for r in results["rows"]}
    assert rows[(1, "one")]["frame_ms"] == pytest.approx(275.0)  # median 11 s / 40 frames
    assert rows[(5, "everyone")]["vs_one_person_x"] == pytest.approx(42 / 14)
    assert rows[(5, "everyone")]["vs_one_tracker_x"] == pytest.approx(42 / 21)
    assert "| 5 | everyone | 42.0 | 1050.0 | 3.00x | 2.00x |" in table
