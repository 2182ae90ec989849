"""The dry run's time estimate: per-frame cost by camera, people and tracker, learnt from
finished runs (sim.runs.estimate)."""

from __future__ import annotations

import pytest

from sim.runs.estimate import bench_frame_seconds, estimate_time
from sim.runs.run_spec import EVERYONE, ONE
from sim.scenario.spec import CameraSpec

CAMERA = CameraSpec()


def test_each_person_costs_and_more_with_the_people_tracker() -> None:
    one = [bench_frame_seconds(CAMERA, False, n, ONE) for n in (1, 5, 10)]
    everyone = [bench_frame_seconds(CAMERA, False, n, EVERYONE) for n in (1, 5, 10)]
    assert one[0] < one[1] < one[2]
    assert all(e > o for e, o in zip(everyone, one, strict=True))
    assert everyone[2] - everyone[0] > one[2] - one[0]  # landmarks per person, every frame


def test_finished_runs_scale_every_runs_own_benchmark_figure() -> None:
    small, big = bench_frame_seconds(CAMERA, False, 1), bench_frame_seconds(CAMERA, False, 10)
    # Two finished runs of one person took twice the benchmark's time on this machine.
    done = [(40, 2 * 40 * small, small), (60, 2 * 60 * small, small)]
    got = estimate_time([(100, small), (100, big)], done, workers=1, measured_where="here")
    assert got.frame_seconds == pytest.approx(2 * (small + big) / 2)
    assert got.seconds == pytest.approx(2 * 100 * (small + big))
    assert "x 2.00" in got.text() and "2 finished runs here" in got.text()


def test_lines_without_a_benchmark_figure_give_their_mean_as_before() -> None:
    got = estimate_time([(10, 0.1)], [(20, 4.0), (20, 2.0)], workers=1, measured_where="x")
    assert got.frame_seconds == pytest.approx(6.0 / 40)
