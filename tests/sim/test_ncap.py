"""The Euro NCAP grid: protocol figures vs the calculator, the AEB, the nose dip, the scoring."""

from __future__ import annotations

import json
import math

import numpy as np
import openpyxl
import pytest

from monopic.cli.main import main
from sim.analysis import ncap_score
from sim.analysis.ncap_score import Cell, band_colour, score
from sim.runs.aeb import AebParams, JerkLimitedBrake
from sim.scenario.ncap import KMH, Draw, draw_for, grid, load_car, load_protocol, scenario_for
from sim.scenario.path import pedestrian_path
from sim.scenario.spec import BodyPitch
from sim.world.world import World

PROTOCOL = load_protocol()
CAR = load_car()


def template_matrices():
    """The calculator's own template (generated from its package data) and matrix layout."""
    from importlib.resources import files

    from euroncap_rating_2026.crash_avoidance import data_model

    wb = openpyxl.load_workbook(str(files("data").joinpath("ca_template.xlsx")))
    return ncap_score._matrices(wb[ncap_score.PRED_SHEET]), wb[ncap_score.PRED_SHEET], data_model


def test_protocol_figures_are_the_calculators():
    matrices, ws, data_model = template_matrices()
    for test in PROTOCOL.tests.values():
        m = matrices[test.load_case]
        assert tuple(m["impacts"]) == test.impact_locations, test.key
        rows = [ws.cell(r, 1).value for r in m["rows"]]
        ours = [f"{v:g} km/h" for row in test.rows for v in row.speeds_kmh]
        assert rows == ours, test.key
        speeds = {ws.cell(r, m["header"]["Target speed"]).value for r in m["rows"]}
        assert speeds == {f"{test.target_speed_kmh:g} km/h"}, test.key
        extended = set(data_model.EXTENDED_RANGE_CELLS[test.load_case])
        k = 0
        for row in test.rows:
            for _ in row.speeds_kmh:
                standard = {
                    test.impact_locations[j]
                    for j in range(len(test.impact_locations))
                    if (k, j) not in extended
                }
                assert standard == set(row.standard), (test.key, row.function)
                k += 1


def test_colour_bands_come_from_the_calculator():
    assert band_colour("CPNA day", "AEB", 40, 0.0) == "Green"
    assert band_colour("CPNA day", "AEB", 40, 5.0) == "Orange"
    assert band_colour("CPNA day", "AEB", 20, 5.0) == "Red"
    assert band_colour("CPLA day", "FCW", 70, 1.7) == "Green"
    assert band_colour("CPLA day", "FCW", 70, 1.69) == "Red"


def test_brake_builds_up_after_latency_and_delay_with_limited_jerk():
    p = AebParams(brake_delay=0.15, jerk=25.0, deceleration=9.0)
    dt = 1 / 15
    brake = JerkLimitedBrake(dt, p)
    brake.observe(1.0, False, 0.05)
    assert brake.action(1.0) == 0.0
    brake.observe(2.0, True, 0.05)
    assert brake.warning_time == pytest.approx(2.05)
    assert brake.deceleration_at(2.19) == 0.0
    assert brake.deceleration_at(2.3) == pytest.approx(25.0 * 0.1)
    assert brake.deceleration_at(3.0) == 9.0
    # The steps' mean decelerations lose exactly the continuous profile's speed.
    lost = -sum(brake.action(t) * dt for t in np.arange(2.0, 4.0, dt))
    ramp = 9.0 / 25.0
    t_end = 2.0 + len(np.arange(2.0, 4.0, dt)) * dt
    expected = 0.5 * 9.0 * ramp + 9.0 * (t_end - 2.2 - ramp)
    assert lost == pytest.approx(expected, rel=1e-9)
    assert all(-brake.action(t) <= 9.0 + 1e-12 for t in np.arange(2.0, 4.0, dt))
    assert -brake.action(2.2) < 25.0 * dt  # no step jumps to full braking


def test_draws_stay_inside_the_tolerances_and_repeat():
    tol = PROTOCOL.tolerances
    draws = [draw_for(tol, "cpna/AEB/40kmh/50", k) for k in range(50)]
    assert draws[3] == draw_for(tol, "cpna/AEB/40kmh/50", 3)
    assert all(tol.vut_speed_kmh[0] <= d.vut_speed_kmh <= tol.vut_speed_kmh[1] for d in draws)
    assert all(abs(d.impact_point) <= tol.impact_point for d in draws)
    assert len({d.vut_speed_kmh for d in draws}) == 50


@pytest.mark.parametrize("point", grid(PROTOCOL, list(PROTOCOL.tests), quick=True), ids=str)
def test_unbraked_the_front_meets_the_target_at_the_impact_point(point):
    s = scenario_for(PROTOCOL, CAR, point, Draw.nominal())
    t = PROTOCOL.timing.impact_time
    assert s.robot.speed == pytest.approx(point.speed_kmh * KMH)
    ped = pedestrian_path(s.pedestrian, s.duration).state(t).position
    front = s.robot.speed * t + s.robot.length / 2 + s.pedestrian.footprint / 2
    assert ped[0] == pytest.approx(front, abs=1e-6)
    test = PROTOCOL.tests[point.test]
    if test.kind == "crossing":  # measured from the edge it enters by
        inward = ped[1] + 0.9 if test.side == "near" else 0.9 - ped[1]
    else:
        inward = ped[1] + 0.9
    assert inward / s.robot.width == pytest.approx(point.impact, abs=1e-6)
    # steady state: the crossing target walks at its speed well before the impact
    speed = pedestrian_path(s.pedestrian, s.duration).state(t - 0.5).speed
    assert speed == pytest.approx(test.target_speed_kmh * KMH, rel=1e-6)


def test_the_camera_dips_when_braking_but_the_pipeline_keeps_its_camera():
    s = scenario_for(PROTOCOL, CAR, grid(PROTOCOL, ["cpna"])[0], Draw.nominal())
    assert s.robot.pitch == BodyPitch(gain=0.2, frequency=1.2, damping=0.5)
    with World(s, render=False) as world:
        world.reset()
        for _ in range(30):  # 2 s of full braking (the car stands after ~0.3 s at 10 km/h)
            step = world.step(action=-9.0)
            if step.truth.robot.speed == 0:
                break
        assert world.pitch > math.radians(0.5)
        assert step.ego.camera == world.camera  # the pipeline's: nominal
        true = world.true_camera
        assert true.pitch == pytest.approx(world.camera.pitch + world.pitch)
        px = step.truth.body.landmarks_px
        assert np.allclose(px, true.project(step.truth.body.landmarks_robot), equal_nan=True)
        assert not np.allclose(px, world.camera.project(step.truth.body.landmarks_robot))
        for _ in range(60):  # standing: the body settles back
            world.step(action=0.0)
        assert abs(world.pitch) < math.radians(0.05)


def _cells(avoided: bool) -> list[Cell]:
    cells = []
    for pt in grid(PROTOCOL, list(PROTOCOL.tests)):
        case = PROTOCOL.tests[pt.test].load_case
        if avoided:
            v = 3.0 if pt.function == "FCW" else 0.0
        else:  # every impact at full (relative) speed; no warning at all
            v = 0.0 if pt.function == "FCW" else pt.speed_kmh - (5.0 if pt.test == "cpla" else 0)
        cells.append(Cell(case, pt.function, pt.speed_kmh, pt.impact,
                          band_colour(case, pt.function, pt.speed_kmh, v), v))  # fmt: skip
    return cells


@pytest.mark.slow
def test_the_calculator_scores_hand_made_cases(tmp_path):
    from euroncap_rating_2026.crash_avoidance import data_model

    claimed = {"CPNA", "CPFA", "CPNCO", "CPLA"}
    best = score(tmp_path / "avoided", _cells(True), claimed)
    for name, lc in best.load_cases.items():  # the day half of every standard range
        assert lc.standard == pytest.approx(data_model.TOTAL_SCORES[f"{name} day"]["Standard"])
        assert lc.extended == 0 and lc.robustness == 0  # not run, not claimed
    assert best.pedestrian_score == pytest.approx(3.0)
    assert best.verification and all(v["Colour"] == "Green" for v in best.verification)
    worst = score(tmp_path / "hit", _cells(False), claimed)
    assert worst.pedestrian_score == 0 and worst.ped_cyc_score == 0
    assert (tmp_path / "hit" / "ca_preprocessed_template.xlsx").exists()


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--tests", "cpna,cpta"], "--tests: unknown test 'cpta'"),
        (["--speeds", "90"], "--speeds 90: not a test speed of the protocol's grid"),
        (["--speeds", "25"], "--speeds 25: not a test speed"),
        (["--policies", "oracle"], "--policies: 'oracle' is not PREDICTOR/MODE"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys, argv, expected):
    out = tmp_path / "out"
    assert main(["ncap", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err
    assert not out.exists()


def test_a_missing_calculator_is_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(ncap_score, "calculator_version", lambda: None)
    out = tmp_path / "out"
    assert main(["ncap", "--quick", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "needs the Euro NCAP rating calculator" in err
    assert "[ncap]" in err and not out.exists()


@pytest.mark.slow
def test_ncap_command_runs_scores_and_resumes(tmp_path, capsys):
    out = tmp_path / "ncap"
    argv = ["ncap", "--tests", "cpna", "--quick", "--speeds", "20", "--seeds", "1",
            "--policies", "rules/ground", "--no-near-misses", "--workers", "2",
            "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    rows = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert len(rows) == 2 and {r["role"] for r in rows} == {"grid", "verify"}
    assert all(r["speed_kmh"] == 20 and r["impact"] == 0.5 for r in rows)
    report = (out / "report.md").read_text()
    assert "euroncap-rating-2026 5.4.9" in report and "matrix-rules-ground.png" in report
    assert (out / "matrix-rules-ground.png").stat().st_size > 10_000
    assert list((out / "calculator" / "rules-ground").glob("ca_*_report.xlsx"))
    capsys.readouterr()
    assert main(argv) == 0  # resumes: nothing to run again
    assert "2 of 2 runs already there" in capsys.readouterr().err


def test_a_results_file_of_a_newer_schema_or_being_written_is_refused_in_one_line(tmp_path):
    """The grid's results file gets the sweep's checks: a newer schema (this code would
    misread it) is refused unless --restart sets it aside; one another grid is appending to
    is refused before anything is set aside."""
    import json

    from monopic.errors import UserError
    from sim.runs.code_version import code_version
    from sim.runs.ncap_grid import check_results
    from sim.runs.results_file import ResultsWriter

    out = tmp_path / "results.jsonl"
    out.write_text(json.dumps({"id": "a", "code": code_version(), "schema": 99}) + "\n")
    with pytest.raises(UserError) as err:
        check_results(out, restart=False)
    assert str(err.value).startswith(f"{out}:1: a result of schema 99, newer than this code's 1")
    with ResultsWriter(out), pytest.raises(UserError) as err:
        check_results(out, restart=True)
    assert str(err.value) == (
        f"{out}: another sweep is writing to it; wait for it or use another --out"
    )
    assert out.exists()
    check_results(out, restart=True)
    assert not out.exists() and (tmp_path / "results.schema99.jsonl").exists()
