"""The closed loop: braking on the warning, late by the pipeline's latency, avoids contacts."""

from __future__ import annotations

import math

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
        (["--cases", "5", "--speeds", "fast"], "--speeds: expected numbers"),
        # a case placement gets a small-scale file's checks: the small robot's max_speed
        (["--cases", "5", "--speeds", "10"], "--speeds 10: case 5: must be <= 3 m/s"),
        # a file's own max_speed, named with the option and the file
        (
            ["scenarios/families/car/cpna25.toml", "--speeds", "25"],
            "--speeds 25: scenarios/families/car/cpna25.toml: robot.speed = 25.0: must be "
            "<= 20 m/s (robot.max_speed)",
        ),
        (
            ["scenarios/families/car/cpna25.toml", "--seed", "-2"],
            "--seed -2: scenarios/families/car/cpna25.toml: seed = -2: must be an integer",
        ),
    ],
)
def test_closed_loop_command_rejects_bad_input_in_one_line(capsys, monkeypatch, argv, expected):
    import sim.runs.closed_loop

    def no_run(*args, **kwargs):
        raise AssertionError("a run started before the input was checked")

    monkeypatch.setattr(sim.runs.closed_loop, "run_closed_loop", no_run)
    assert main(["closed-loop", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err


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
    """closed-loop FILE: the file's robot.speed and seed are the defaults; --speeds and
    --seed replace them (the default families too: each at its own speed and seed)."""
    from sim.commands.closed_loop import FAMILY_FOLDER, NCAP_FAMILIES, file_scenarios
    from sim.scenario.files import load

    path = tmp_path / "car.toml"
    path.write_text(CAR_FILE)
    table = tmp_path / "table.md"
    assert main(["closed-loop", str(path), "--policies", "none", "--out", str(table)]) == 0
    text = table.read_text()
    assert "1 scenarios" in text and "robot speeds 8.33 m/s: each file's own" in text
    assert "seed 5 (each file's own)" in text
    assert "| child-at-30@8.33 | none | yes | 8.33 |" in text  # hit at the file's speed
    given = file_scenarios([path], [4.0, 6.0], 9)
    assert [(s.name, s.robot.speed, s.seed) for s in given] == [
        ("child-at-30@4", 4.0, 9),
        ("child-at-30@6", 6.0, 9),
    ]
    families = [FAMILY_FOLDER / f"{name}.toml" for name in NCAP_FAMILIES]
    own = file_scenarios(families, None, None)
    assert [(s.robot.speed, s.seed) for s in own] == [
        (load(f).base.robot.speed, load(f).base.seed) for f in families
    ]
