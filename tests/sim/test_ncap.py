"""The Euro NCAP grid: protocol figures vs the calculator, the AEB, the nose dip, the scoring."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import openpyxl
import pytest

from monopic.cli.main import main
from sim.analysis import ncap_score
from sim.analysis.ncap_report import latency_line, measured_latency
from sim.analysis.ncap_score import Cell, band_colour, score
from sim.runs import ncap_grid
from sim.runs.aeb import AebParams, JerkLimitedBrake, run_aeb
from sim.runs.executors import local_executor
from sim.runs.latency import AppliedLatency, replay_latencies
from sim.runs.ncap_grid import DECLARED, FIXED, GRID, MEASURED, LatencySetting, latency_setting
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
        px = step.truth.pedestrian.body.landmarks_px
        assert np.allclose(
            px, true.project(step.truth.pedestrian.body.landmarks_robot), equal_nan=True
        )
        assert not np.allclose(px, world.camera.project(step.truth.pedestrian.body.landmarks_robot))
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
            longitudinal = PROTOCOL.tests[pt.test].kind == "longitudinal"
            v = 0.0 if pt.function == "FCW" else pt.speed_kmh - (5.0 if longitudinal else 0)
        cells.append(Cell(case, pt.function, pt.speed_kmh, pt.impact,
                          band_colour(case, pt.function, pt.speed_kmh, v), v))  # fmt: skip
    return cells


@pytest.mark.slow
def test_the_calculator_scores_hand_made_cases(tmp_path):
    from euroncap_rating_2026.crash_avoidance import data_model

    claimed = {"CPNA", "CPFA", "CPNCO", "CPLA"}
    best = score(tmp_path / "avoided", _cells(True), claimed)
    for name, lc in best.load_cases.items():  # both halves of every standard range
        halves = [data_model.TOTAL_SCORES[f"{name} {half}"] for half in ("day", "night")]
        top = sum(h["Standard"] for h in halves)
        assert lc.standard == pytest.approx(top)
        assert lc.extended == 0 and lc.robustness == 0  # not run, not claimed
    assert best.pedestrian_score == pytest.approx(6.0)
    assert best.verification and all(v["Colour"] == "Green" for v in best.verification)
    worst = score(tmp_path / "hit", _cells(False), claimed)
    assert worst.pedestrian_score == 0 and worst.ped_cyc_score == 0
    assert (tmp_path / "hit" / "ca_preprocessed_template.xlsx").exists()


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--tests", "cpna,cpta"], "--tests: unknown test 'cpta'"),
        (["--speeds-kmh", "90"], "--speeds-kmh 90: not a test speed of the protocol's grid"),
        (["--speeds-kmh", "25"], "--speeds-kmh 25: not a test speed"),
        (["--speeds-kmh", "fast"], "--speeds-kmh: expected km/h numbers separated by commas"),
        (["--policies", "oracle"], "--policies: 'oracle' is not PREDICTOR/MODE"),
        (["--beside", "no/such/grid"], "--beside no/such/grid: no scored grid there"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys, argv, expected):
    out = tmp_path / "out"
    assert main(["ncap", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--latency-ms", "40", "--measured-latency"], "not allowed with argument --latency-ms"),
        (["--latency-ms", "-5"], "--latency-ms: must be a finite number >= 0"),
    ],
)
def test_latency_options_refused_in_one_line(tmp_path, capsys, argv, expected):
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal (monopic.cli.main)
        main(["ncap", *argv, "--out", str(out)])
    assert stop.value.code == 2
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
    argv = ["ncap", "--tests", "cpna", "--quick", "--speeds-kmh", "20", "--runs-per-point", "1",
            "--policies", "rules/ground", "--no-near-misses", "--workers", "2",
            "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    rows = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert len(rows) == 2 and {r["role"] for r in rows} == {"grid", "verify"}
    assert all(r["speed_kmh"] == 20 and r["impact"] == 0.5 for r in rows)
    for row in rows:  # the declared latency applied; the measured one kept per frame
        assert row["latency"] == {"source": DECLARED, "applied_ms": CAR.latency_ms}
        assert 0 < len(row["outcome"]["latencies_ms"]) <= row["outcome"]["frames"]
    printed = capsys.readouterr().out
    report = (out / "report.md").read_text()
    assert "euroncap-rating-2026 5.4.9" in report and "matrix-rules-ground.png" in report
    assert "## Runs to look at" in report  # each with `monopic rerun RESULTS RUN_ID`
    measured = measured_latency(rows)
    line = (
        f"Latency applied: declared {CAR.latency_ms:g} ms ({CAR.path} latency_ms). Pipeline "
        f"latency measured during the runs: p50 {measured.p50_ms:.1f} ms, p95 "
        f"{measured.p95_ms:.1f} ms over {measured.frames} frames of 2 runs."
    )
    assert line in report and line in printed
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


# -- the latency the AEB applies -------------------------------------------------------


def _cpna20(latency: LatencySetting | None = None, car=CAR) -> list[ncap_grid.NcapRun]:
    """The quick grid's CPNA 20 km/h point, one jittered run and its verification run."""
    return ncap_grid.expand(PROTOCOL, car, ["cpna"], ["rules/ground"], quick=True,
                            speeds=[20], seeds=1, near_misses=False, latency=latency)  # fmt: skip


def test_the_declared_latency_is_the_default_and_the_options_replace_it():
    assert CAR.latency_ms is not None and CAR.latency_ms > 0  # car.toml declares it
    assert latency_setting(CAR) == LatencySetting(DECLARED, CAR.latency_ms)
    assert latency_setting(CAR, 40.0) == LatencySetting(FIXED, 40.0)
    assert latency_setting(CAR, measured=True) == LatencySetting(MEASURED, None)
    assert latency_setting(replace(CAR, latency_ms=None)) == LatencySetting(MEASURED, None)
    with pytest.raises(ValueError):
        latency_setting(CAR, 40.0, measured=True)
    for run in _cpna20():
        assert run.aeb.latency_ms == CAR.latency_ms and run.latency.source == DECLARED


def test_runs_with_another_latency_or_brake_are_other_runs(tmp_path):
    settings = [None, LatencySetting(FIXED, 40.0), LatencySetting(MEASURED, None)]
    ids = [{r.id for r in _cpna20(s)} for s in settings]
    assert ids[0] == {r.id for r in _cpna20()}  # stable: a results file resumes
    assert all(len(i) == 2 for i in ids) and not (ids[0] & ids[1] or ids[0] & ids[2] or
                                                   ids[1] & ids[2])  # fmt: skip
    assert not ids[0] & {r.id for r in _cpna20(car=replace(CAR, brake_delay=0.2))}
    # A results file of runs with the declared latency: a run with the measured one
    # resumes none of them.
    out = tmp_path / "results.jsonl"
    given: list[list[str]] = []

    def executor(specs, on_result):
        given.append([s.id for s in specs])
        for spec in specs:
            on_result({"id": spec.id, "code": spec.code, "latency": spec.latency.to_json()})

    ncap_grid.run_grid(_cpna20(), out, executor, progress=False)
    again = ncap_grid.run_grid(_cpna20(), out, executor, progress=False)
    assert again.skipped == 2 and len(given) == 1
    measured = ncap_grid.run_grid(_cpna20(settings[2]), out, executor, progress=False)
    assert measured.skipped == 0 and set(given[1]) == ids[2]
    rows = ncap_grid.read_results(out, _cpna20(settings[2]))
    assert [r["latency"]["source"] for r in rows] == [MEASURED, MEASURED]


def test_a_replay_applies_the_recorded_latency_of_each_frame_and_checks_their_count():
    latency = AppliedLatency(recorded=[30.0, 45.5])
    assert latency.next_ms(12.0) == 30.0 and latency.next_ms(99.0) == 45.5
    assert latency.measured == [12.0, 99.0]
    latency.check_used()
    with pytest.raises(ValueError, match="end after 2 frames"):
        latency.next_ms(10.0)
    short = AppliedLatency(recorded=[30.0, 45.5])
    short.next_ms(1.0)
    with pytest.raises(ValueError, match="cover 2 frames; this run processed 1"):
        short.check_used()
    fixed = AppliedLatency(latency_ms=50.0)
    assert fixed.next_ms(12.0) == 50.0 and fixed.measured == [12.0]
    assert AppliedLatency().next_ms(12.0) == 12.0
    with pytest.raises(ValueError):
        AppliedLatency(latency_ms=50.0, recorded=[1.0])
    with pytest.raises(ValueError):
        AppliedLatency(recorded=[math.nan])


def _rows(latencies: list[list[float]]) -> list[dict]:
    return [{"outcome": {"latencies_ms": v}} for v in latencies]


def test_the_report_line_gives_the_latency_applied_and_the_measured_one_beside_it():
    rows = _rows([[10.0, 20.0, 30.0], [40.0, 50.0]])
    m = measured_latency(rows)
    assert (m.runs, m.frames, m.p50_ms) == (2, 5, 30.0)
    assert m.p95_ms == pytest.approx(48.0)
    car = replace(CAR, latency_ms=465.0)
    declared = latency_line(LatencySetting(DECLARED, 465.0), car, rows)
    assert declared == (
        f"Latency applied: declared 465 ms ({car.path} latency_ms). Pipeline latency "
        "measured during the runs: p50 30.0 ms, p95 48.0 ms over 5 frames of 2 runs."
    )
    assert "applied: fixed 40 ms (--latency-ms); the car file declares 465 ms" in latency_line(
        LatencySetting(FIXED, 40.0), car, rows
    )
    assert "applied: the measured one, per frame; the car file declares none" in latency_line(
        LatencySetting(MEASURED, None), replace(car, latency_ms=None), rows
    )
    assert "no frame measured" in latency_line(LatencySetting(DECLARED, 465.0), car, _rows([]))


def _host_free(outcome) -> dict:
    return {k: v for k, v in asdict(outcome).items() if k not in ncap_grid.OUTCOME_TIMING}


@pytest.mark.slow
def test_an_aeb_run_replayed_with_its_recorded_latencies_is_the_same_run():
    run = _cpna20(LatencySetting(MEASURED, None))[0]
    first = run_aeb(run.scenario, run.policy, run.aeb, seed=run.index)
    assert first.warning_time is not None and len(first.latencies_ms) > 0
    row = {"latency": run.latency.to_json(), "outcome": asdict(first)}
    recorded = replay_latencies(json.loads(json.dumps(row)))  # as stored
    assert recorded == list(first.latencies_ms)
    again = run_aeb(run.scenario, run.policy, run.aeb, seed=run.index, latencies_ms=recorded)
    # The same frames and decisions: down to the float, the warning was issued at the
    # warned frame's capture time plus the latency recorded for it, not this run's.
    assert _host_free(again) == _host_free(first)
    with pytest.raises(ValueError, match="not the run they were recorded in"):
        run_aeb(run.scenario, run.policy, run.aeb, seed=run.index, latencies_ms=recorded[:-1])


@pytest.mark.slow
def test_a_closed_loop_run_replayed_with_its_recorded_latencies_is_the_same_run():
    from monopic.cases import Case
    from sim.runs.closed_loop import run_closed_loop
    from tests.sim.test_closed_loop import crossing

    scenario = crossing(Case.PERPENDICULAR_RIGHT)
    first = run_closed_loop(scenario, "rules/ground")
    assert first.braked and first.latencies_ms and first.delays
    recorded = json.loads(json.dumps(list(first.latencies_ms)))  # as a results file keeps them
    again = run_closed_loop(scenario, "rules/ground", latencies_ms=recorded)
    assert len(again.latencies_ms) == len(first.latencies_ms)
    assert replace(again, latencies_ms=()) == replace(first, latencies_ms=())  # delays too
    with pytest.raises(ValueError, match="not the run they were recorded in"):
        run_closed_loop(scenario, "rules/ground", latencies_ms=recorded[: len(recorded) // 2])


def _busy_loops(n: int) -> list[subprocess.Popen]:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]


def _one_run(out: Path) -> dict:
    run = [r for r in _cpna20() if r.role == GRID]
    assert len(run) == 1
    outcome = ncap_grid.run_grid(run, out, local_executor(1, run=ncap_grid.work), progress=False)
    assert outcome.finished == 1 and not outcome.failed
    (row,) = ncap_grid.read_results(out, run)
    return row


@pytest.mark.slow
def test_with_the_declared_latency_a_grid_point_is_the_same_under_load(tmp_path):
    plain = _one_run(tmp_path / "plain.jsonl")
    load = _busy_loops(2)
    try:
        loaded = _one_run(tmp_path / "loaded.jsonl")
    finally:
        for proc in load:
            proc.kill()
            proc.wait()
    assert plain["latency"] == {"source": DECLARED, "applied_ms": CAR.latency_ms}
    assert plain["outcome"]["warning_time"] is not None  # the brake acted on a warning
    assert ncap_grid.without_timing(loaded) == ncap_grid.without_timing(plain)


def test_the_tests_named_in_the_help_are_the_protocols_day_tests():
    from sim.commands.ncap import TESTS

    assert set(TESTS) == set(PROTOCOL.tests)


def test_the_renamed_options_still_work_and_say_they_are_deprecated(tmp_path, capsys):
    """--speeds and --seeds (before --speeds-kmh and --runs-per-point) are aliases that
    warn; the check after them is the new option's (one line, nothing written)."""
    out = tmp_path / "out"
    assert main(["ncap", "--speeds", "90", "--seeds", "2", "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0] == "monopic ncap: warning: --speeds is deprecated, use --speeds-kmh"
    assert lines[1] == "monopic ncap: warning: --seeds is deprecated, use --runs-per-point"
    assert lines[2].startswith("monopic ncap: error: --speeds-kmh 90: not a test speed")
    assert len(lines) == 3 and not out.exists()


# -- a grid's run again: monopic rerun ------------------------------------------------------


@pytest.mark.slow
def test_rerun_gives_a_grid_points_outcome_and_a_readable_recording(tmp_path, capsys):
    from tests.rrd import rows_per_entity

    results = tmp_path / "results.jsonl"
    row = _one_run(results)  # the declared latency
    assert row["protocol"] == str(PROTOCOL.path) and row["car"] == str(CAR.path)
    rrd = tmp_path / "again" / "run.rrd"
    assert main(["rerun", str(results), row["id"], "--out", str(rrd)]) == 0
    said = capsys.readouterr().out
    assert said.splitlines()[-1] == "same outcome as in the run", said
    assert said.startswith(f"run {row['id']} (CPNA day AEB 20 km/h, impact 50%, grid run 0, ")
    # Every processed frame's camera image, read back with rerun's own reader (a run that
    # stops without contact counts the state it stopped in as a frame too).
    frames = row["outcome"]["frames"] - (not row["outcome"]["contact"])
    assert rows_per_entity(rrd)["/camera/image"] == frames > 0


@pytest.mark.slow
def test_a_measured_latency_grid_row_is_rerun_with_the_latency_it_measured(tmp_path, capsys):
    """A row whose host measured 300 ms on every frame: its warning was issued 300 ms after
    each warned frame's capture. Run again on a host that measures far less, it gives the
    same outcome down to the float, because the rerun applies the stored latencies."""
    from sim.runs.code_version import code_version

    run = _cpna20(LatencySetting(MEASURED, None))[0]
    fixed = replace(
        run, aeb=replace(run.aeb, latency_ms=300.0), latency=LatencySetting(FIXED, 300.0)
    )
    frames = len(run_aeb(fixed.scenario, fixed.policy, fixed.aeb, seed=fixed.index).latencies_ms)
    made = ncap_grid.work(replace(run, code=code_version(), replay=(300.0,) * frames))
    assert "error" not in made and made["outcome"]["warning_time"] is not None
    line = json.loads(json.dumps(made))
    assert line["latency"] == {"source": MEASURED, "applied_ms": None}
    line["outcome"]["latencies_ms"] = [300.0] * frames  # as that host measured them
    results = tmp_path / "results.jsonl"
    results.write_text(json.dumps(line) + "\n")
    assert main(["rerun", str(results), line["id"]]) == 0
    said = capsys.readouterr().out
    assert said.splitlines()[-1] == "same outcome as in the run", said
    assert (tmp_path / "results_rerun" / f"{line['id']}.rrd").is_file()  # the default --out

    line["outcome"]["warning_ttc"] += 0.5  # not what the run gives: its first difference
    results.write_text(json.dumps(line) + "\n")
    assert main(["rerun", str(results), line["id"]]) == 1
    assert "first difference at outcome.warning_ttc: " in capsys.readouterr().out


def _grid_line(**changes) -> dict:
    """A grid's results line of this code (its real id; an outcome nobody ran), changed."""
    from sim.runs.code_version import code_version

    run = replace(_cpna20()[0], code=code_version())
    line = {"schema": 1, "id": run.id, "code": run.code, "policy": run.policy,
            "role": run.role, "index": run.index, **run.meta,
            "latency": run.latency.to_json(), "outcome": {"contact": False}}  # fmt: skip
    line.update(changes)
    return json.loads(json.dumps(line))


@pytest.mark.parametrize(
    ("changes", "run_id", "expected"),
    [
        ({}, "rules/ground/nope", "no run 'rules/ground/nope' in it (1 runs, ids such as"),
        ({"code": "0123456789ab"}, None, "made by other code (0123456789ab; this code is"),
        ({"car": "gone/car.toml"}, None, "gone/car.toml: no such car file"),
        ({"protocol": "gone/p.toml"}, None, "gone/p.toml: no such protocol file"),
        ({"car": "CHANGED"}, None, "they no longer give run rules/ground/cpna/AEB/20kmh/50/grid0-"),
        ({"impact": 0.75}, None, "they no longer give run"),
        ({"latency": {"source": "measured"}}, None, "is not a Euro NCAP grid's line as this"),
    ],
)
def test_what_of_a_grid_cannot_be_rerun_is_one_line(tmp_path, capsys, changes, run_id, expected):
    if changes.get("car") == "CHANGED":  # the car file edited since the grid ran
        car = tmp_path / "car.toml"
        car.write_text(CAR.path.read_text().replace("brake_delay = 0.15", "brake_delay = 0.2"))
        assert car.read_text() != CAR.path.read_text()
        changes = {"car": str(car)}
    line = _grid_line(**changes)
    results = tmp_path / "results.jsonl"
    results.write_text(json.dumps(line) + "\n")
    out = tmp_path / "out" / "run.rrd"
    assert main(["rerun", str(results), run_id or line["id"], "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err, err
    assert not (tmp_path / "out").exists()  # nothing made for a refused input
