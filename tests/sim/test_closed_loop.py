"""The closed loop: braking on the warning, late by the pipeline's latency, avoids contacts."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from monopic.cases import Case
from monopic.cli.main import main
from sim.runs.closed_loop import (
    NO_BRAKE,
    ORACLE,
    LatencyBrake,
    format_table,
    run_closed_loop,
    summarise,
)
from sim.scenario.cases import CasePlacement
from sim.scenario.spec import CameraSpec, RobotSpec

DT = 1.0 / 15.0


def crossing(case: Case, speed: float = 2.0, meet: float = 2.0):
    """A crossing on a collision course: the robot reaches the path at `meet` seconds.

    Half-size frames (384x216) keep the test quick; the pose is still found at these ranges.
    """
    return CasePlacement(
        case, distance=speed * meet, robot_speed=speed, meet_time=meet, duration=meet + 0.6
    ).scenario(
        robot=RobotSpec(camera=CameraSpec(width=384, height=216)), name=f"case{int(case)}@{speed:g}"
    )


def test_commands_act_at_the_first_frame_boundary_after_the_latency():
    brake = LatencyBrake(DT, deceleration=8.0)
    assert [brake.delay_frames(s) for s in (0.0, 0.03, DT, 0.07, 0.2)] == [0, 1, 1, 2, 3]
    brake.observe(0, False, 0.03)
    brake.observe(4, True, 0.07)  # known at t4 + 70 ms: acts from frame 6
    assert [brake.action(k) for k in range(4, 8)] == [0.0, 0.0, -8.0, -8.0]
    brake.observe(5, True, 0.01)  # a faster later frame cannot act before frame 6 either
    assert brake.brake_from == 6 and brake.first_warning == 4
    brake.observe(9, False, 0.01)
    assert brake.braking(20)  # latched: brakes to a standstill
    with pytest.raises(ValueError):
        brake.delay_frames(math.nan)


@pytest.mark.slow
def test_latency_delays_the_brake():
    scenario = crossing(Case.PERPENDICULAR_RIGHT)
    prompt = run_closed_loop(scenario, ORACLE, latency_ms=0.0)
    late = run_closed_loop(scenario, ORACLE, latency_ms=200.0)  # 3 frames at 15 fps
    assert prompt.first_warning_time == late.first_warning_time
    assert prompt.brake_time == pytest.approx(prompt.first_warning_time)
    assert late.brake_time == pytest.approx(late.first_warning_time + 3 * DT)
    assert late.min_gap < prompt.min_gap


@pytest.mark.slow
def test_braking_on_the_ground_mode_warning_avoids_contacts():
    scenarios = [crossing(Case.PERPENDICULAR_RIGHT), crossing(Case.PERPENDICULAR_LEFT)]
    outcomes = [run_closed_loop(s, p) for s in scenarios for p in (NO_BRAKE, "rules/ground")]
    base = [o for o in outcomes if o.policy == NO_BRAKE]
    braking = [o for o in outcomes if o.policy == "rules/ground"]
    assert all(o.contact and o.impact_speed == pytest.approx(2.0) for o in base)
    assert all(o.min_gap == 0.0 and not o.braked for o in base)
    assert sum(o.contact for o in braking) < len(base)
    for o in braking:
        assert o.braked
        # The measured latency was applied: each warned frame's command waited for it.
        assert o.latencies_ms and all(d >= 1 for d in o.delays)
        assert o.brake_time >= o.first_warning_time + DT - 1e-9
        assert o.min_gap > 0 or o.impact_speed < 2.0
    rows = {r.policy: r for r in summarise(outcomes)}
    assert rows[NO_BRAKE].contacts == 2 and rows["rules/ground"].avoided >= 1
    table = format_table(list(rows.values()))
    assert table.count("\n") == 3 and "| rules/ground | 2 |" in table


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--cases", "7"], "case 7 (toward) does not cross the path"),
        (["--cases", "5", "--policies", "brake"], "'brake' is not a policy: use none, truth"),
        (
            ["--cases", "5", "--policies", "id3-tree/image"],
            "(constant-velocity|intent-tree|rules|tree)",
        ),
        (["--cases", "5", "--policies", "rules/sky"], "'rules/sky' is not a policy"),
        (["--cases", "5", "--robot-speeds", "fast"], "--robot-speeds: expected numbers"),
        # a case placement gets a small-scale file's checks: the small robot's max_speed
        (["--cases", "5", "--robot-speeds", "10"], "--robot-speeds 10: case 5: must be <= 3 m/s"),
        # a file's own max_speed, named with the option and the file
        (
            ["scenarios/families/car/cpna25.toml", "--robot-speeds", "25"],
            "--robot-speeds 25: scenarios/families/car/cpna25.toml: robot.speed = 25.0: must "
            "be <= 20 m/s (robot.max_speed)",
        ),
        (["--cases", "5", "--address", "host:1"], "--address is for --executor ray"),
        (
            ["--cases", "5", "--results", "scenarios"],
            "--results scenarios: is a folder; give a file name",
        ),
        (
            ["--cases", "5", "--out", "nowhere/t.jsonl"],
            "--out nowhere/t.jsonl: the tables would overwrite the results file nowhere/t.jsonl",
        ),
    ],
)
def test_closed_loop_command_rejects_bad_input_in_one_line(capsys, monkeypatch, argv, expected):
    import sim.runs.closed_loop_grid

    def no_run(*args, **kwargs):
        raise AssertionError("a run started before the input was checked")

    monkeypatch.setattr(sim.runs.closed_loop_grid, "run_runs", no_run)
    assert main(["closed-loop", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--seed", "-2"], "argument --seed: must be in [0, 2147483647], got '-2'"),
        (["--latency-ms", "-1"], "argument --latency-ms: must be >= 0, got '-1'"),
        (["--workers", "0"], "argument --workers: must be >= 1, got '0'"),
    ],
)
def test_ranged_options_are_refused_by_the_command_line_in_one_line(capsys, argv, expected):
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal (monopic.cli.main)
        main(["closed-loop", "--cases", "5", *argv])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err


def test_speeds_is_a_deprecated_name_of_robot_speeds(capsys):
    from monopic.cli.main import build_parser

    args = build_parser().parse_args(["closed-loop", "--cases", "5", "--speeds", "1,2"])
    assert args.robot_speeds == "1,2"
    assert capsys.readouterr().err == (
        "monopic closed-loop: warning: --speeds is deprecated, use --robot-speeds\n"
    )
    with pytest.raises(SystemExit):
        build_parser().parse_args(["closed-loop", "--help"])
    shown = capsys.readouterr().out
    assert "--robot-speeds" in shown and "--speeds" not in shown.replace("--robot-speeds", "")


CAR_FILE = """
name = "child-at-30"
scale = "car"
duration = 1.0
seed = 5
[robot]
speed = 8.33
[robot.camera]
width = 256
height = 144
[path]
kind = "case"
case = 5
distance = 4.0
"""


def test_a_file_runs_at_its_own_speed_and_seed_unless_given(tmp_path):
    """closed-loop FILE: the file's robot.speed and seed are the defaults; --robot-speeds
    and --seed replace them (the default families too: each at its own speed and seed)."""
    from sim.commands.closed_loop import FAMILY_FOLDER, NCAP_FAMILIES
    from sim.runs.closed_loop_grid import file_sources, scenarios_of
    from sim.scenario.files import load

    path = tmp_path / "car.toml"
    path.write_text(CAR_FILE)
    table = tmp_path / "table.md"
    argv = ["closed-loop", str(path), "--policies", "none", "--out", str(table), "--workers", "1"]
    assert main(argv) == 0
    text = table.read_text()
    assert "1 scenarios" in text and "robot speeds 8.33 m/s: each file's own" in text
    assert "seed 5 (each file's own)" in text
    assert "| child-at-30@8.33 | none | yes | 8.33 |" in text  # hit at the file's speed
    given = scenarios_of(file_sources([path], [4.0, 6.0], 9))
    assert [(s.name, s.robot.speed, s.seed) for s in given] == [
        ("child-at-30@4", 4.0, 9),
        ("child-at-30@6", 6.0, 9),
    ]
    families = [FAMILY_FOLDER / f"{name}.toml" for name in NCAP_FAMILIES]
    own = scenarios_of(file_sources(families, None, None))
    assert [(s.robot.speed, s.seed) for s in own] == [
        (load(f).base.robot.speed, load(f).base.seed) for f in families
    ]


# -- the runs on workers, their results file, rerun ----------------------------------------

# A crossing meeting the small robot at 2 s: rules/ground warns on it and brakes.
MEETING = """
name = "meet{case}"
scale = "small"
duration = 2.6
[robot]
speed = 2.0
[robot.camera]
width = 384
height = 216
[path]
kind = "case"
case = {case}
distance = 4.0
meet_time = 2.0
"""
POLICIES = "none,truth,rules/ground"


def _meeting(tmp_path, case: int = 5):
    path = tmp_path / f"meet{case}.toml"
    path.write_text(MEETING.format(case=case))
    return path


def _rows(path):
    from sim.runs.results_file import read_rows

    return list(read_rows(path))


def _section(text: str, title: str) -> str:
    return text.split(f"{title}\n\n", 1)[1].split("\n\n", 1)[0]


@pytest.mark.slow
def test_the_runs_on_workers_give_the_in_process_tables_with_one_or_two_workers(tmp_path):
    """The tables are made from the results rows; they are the tables the runs give in
    this process (the measured pipeline latency aside: a fixed latency is applied, so
    nothing else depends on the host), and one or two workers give the same rows."""
    from dataclasses import replace

    from sim.runs.closed_loop import format_runs
    from sim.runs.closed_loop_grid import (
        expand,
        file_sources,
        outcome_of,
        scenarios_of,
        without_timing,
    )
    from sim.runs.latency import FIXED, LatencySetting

    files = [_meeting(tmp_path, 5), _meeting(tmp_path, 6)]
    tables = []
    for workers in (1, 2):
        table = tmp_path / f"w{workers}.md"
        argv = ["closed-loop", *map(str, files), "--policies", POLICIES, "--latency-ms", "100",
                "--workers", str(workers), "--out", str(table)]  # fmt: skip
        assert main(argv) == 0
        tables.append(table)
    # The lines in the order the runs finished; the tables in the runs' order.
    one, two = ({r["id"]: r for r in _rows(t.with_suffix(".jsonl"))} for t in tables)
    assert len(one) == 6 and {k: without_timing(r) for k, r in one.items()} == {
        k: without_timing(r) for k, r in two.items()
    }

    scenarios = scenarios_of(file_sources(files, None, None))
    here = [run_closed_loop(s, p, seed=s.seed, latency_ms=100.0)
            for s in scenarios for p in POLICIES.split(",")]  # fmt: skip
    runs = expand(file_sources(files, None, None), scenarios, POLICIES.split(","),
                  LatencySetting(FIXED, 100.0))  # fmt: skip
    made = [outcome_of(two[r.id]) for r in runs]

    from dataclasses import fields

    from sim.runs.closed_loop import OPTIONAL, LoopOutcome

    # A one-tracker run of one person writes no braked_for fields (OPTIONAL's rule).
    unwritten = {f.name: f.default for f in fields(LoopOutcome) if f.name in OPTIONAL}

    def written(o):
        return replace(o, **(unwritten if o.people <= 1 else {}))

    def host_free(o):
        return replace(written(o), latencies_ms=())

    assert [host_free(o) for o in made] == [host_free(o) for o in here]
    text = tables[1].read_text()
    assert _section(text, "## Runs") == format_runs([written(o) for o in here])
    assert format_table(summarise(made)) in text  # the measured latency median: the rows'
    unmeasured = [replace(r, latency_ms_median=None) for r in summarise(made)]
    assert format_table(unmeasured) == format_table(
        [replace(r, latency_ms_median=None) for r in summarise([written(o) for o in here])]
    )
    assert "| rules/ground | 2 |" in text and "## Runs to look at" in text


@pytest.mark.slow
def test_rerun_gives_a_closed_loop_runs_outcome_and_recording_with_its_latencies(tmp_path, capsys):
    """A run made with the measured latency is made again with the latency it measured on
    each frame: a row whose host measured 200 ms per frame (its brake acts 3 frames late)
    gives its outcome again on a host that measures far less."""
    import json

    from sim.runs.closed_loop import outcome_json
    from sim.runs.closed_loop_grid import Source
    from tests.rrd import rows_per_entity

    path = _meeting(tmp_path)
    results, rrd_dir = tmp_path / "r.jsonl", tmp_path / "rrd"
    argv = ["closed-loop", str(path), "--policies", "rules/ground", "--results", str(results),
            "--rrd-dir", str(rrd_dir), "--workers", "1"]  # fmt: skip
    assert main(argv) == 0
    capsys.readouterr()
    none, braking = _rows(results)
    assert braking["latency"] == {"source": "measured", "applied_ms": None}
    assert none["policy"] == "none" and braking["outcome"]["brake_time"] is not None
    assert braking["source"] == {"file": str(path), "case": None, "given": {}, "meet_time": None}

    rrd = tmp_path / "again" / "run.rrd"
    assert main(["rerun", str(results), braking["id"], "--out", str(rrd)]) == 0
    said = capsys.readouterr().out
    assert said.splitlines()[-1] == "same outcome as in the run", said
    assert rows_per_entity(rrd) == rows_per_entity(Path(braking["recording"]))

    # The same run, as if its host had measured 200 ms on every frame.
    scenario = Source(file=str(path)).scenario()
    slow = run_closed_loop(scenario, "rules/ground", seed=scenario.seed, latency_ms=200.0)
    assert slow.braked and set(slow.delays) == {3}
    line = json.loads(json.dumps({**braking, "outcome": outcome_json(slow, "one")}))
    line["outcome"]["latencies_ms"] = [200.0] * len(slow.latencies_ms)
    measured = tmp_path / "measured.jsonl"
    measured.write_text(json.dumps(line) + "\n")
    assert main(["rerun", str(measured), line["id"]]) == 0
    said = capsys.readouterr().out
    assert said.splitlines()[-1] == "same outcome as in the run", said
    assert (tmp_path / "measured_rerun" / f"{line['id']}.rrd").is_file()

    # A line that does not hold what its run gives: the first difference, exit 1.
    line["outcome"]["brake_time"] += 1.0
    measured.write_text(json.dumps(line) + "\n")
    assert main(["rerun", str(measured), line["id"]]) == 1
    assert "first difference at outcome.brake_time: " in capsys.readouterr().out
