"""Whom the car braked for: the closed loop and the Euro NCAP runs name the person of the
warning the brake acted on, count brakes for the wrong person apart, and record it."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

from monopic.cli.main import main
from monopic.pipeline import FrameResult, PersonResult
from sim.runs.closed_loop import (
    NEEDLESS,
    NO_BRAKE,
    OPTIONAL,
    WRONG_PERSON,
    LoopOutcome,
    format_runs,
    format_table,
    outcome_json,
    summarise,
    went_wrong,
)
from sim.world.warned_for import NOBODY, warned_for

TWO_PEOPLE = Path("scenarios/families/small/people/child_beside_adult.toml")


def _result(person_id: int | None, boxes: dict[int, tuple[float, float, float, float]]):
    people = tuple(
        PersonResult(pid, box, None, None, (), "rules/image") for pid, box in boxes.items()
    )
    return FrameResult(0, 0.0, None, None, (), {}, (640, 360), "rules/image", people, person_id)  # type: ignore[arg-type]


def _truth(*people: tuple[str, tuple[float, float, float, float] | None, float | None]):
    """Just what warned_for reads of a GroundTruth: each person's name, box and time to
    collision (None: not on a collision course)."""
    return SimpleNamespace(
        people=tuple(SimpleNamespace(name=n, box=b, time_to_collision=t) for n, b, t in people)
    )


def test_a_warning_is_for_the_person_its_track_overlaps_or_for_nobody():
    truth = _truth(
        ("child", (100.0, 100.0, 140.0, 220.0), 2.5),  # beyond a 1.5 s horizon: still on course
        ("adult", (300.0, 60.0, 360.0, 240.0), None),
    )
    boxes = {3: (102.0, 98.0, 141.0, 218.0), 5: (298.0, 65.0, 358.0, 238.0), 8: (500, 50, 540, 150)}
    child = warned_for(_result(3, boxes), truth)  # type: ignore[arg-type]
    assert child is not None and (child.name, child.track, child.on_course) == ("child", 3, True)
    assert (
        not child.wrong
        and child.said() == "child (track 3, on a collision course, contact in 2.50 s)"
    )
    adult = warned_for(_result(5, boxes), truth)  # type: ignore[arg-type]
    assert adult is not None and adult.name == "adult" and adult.wrong
    assert adult.said() == "adult (track 5, not on a collision course)"
    phantom = warned_for(_result(8, boxes), truth)  # type: ignore[arg-type]
    assert phantom is not None and phantom.name == NOBODY and phantom.wrong
    assert phantom.said() == "nobody (track 8, a phantom)"
    assert warned_for(_result(None, boxes), truth) is None  # type: ignore[arg-type]


def test_two_tracks_on_one_person_the_better_overlap_is_them_the_other_nobody():
    truth = _truth(("child", (100.0, 100.0, 140.0, 220.0), 1.0))
    boxes = {1: (100.0, 100.0, 140.0, 220.0), 2: (95.0, 110.0, 135.0, 230.0)}
    assert warned_for(_result(1, boxes), truth).name == "child"  # type: ignore[arg-type,union-attr]
    assert warned_for(_result(2, boxes), truth).name == NOBODY  # type: ignore[arg-type,union-attr]


def _outcome(policy: str, seed: int, **kw) -> LoopOutcome:
    base = dict(scenario="two", policy=policy, seed=seed, frames=60, contact=False,
                contact_time=None, impact_speed=None, min_gap=1.0, first_warning_time=None,
                brake_time=None, warned_frames=0, start_speed=2.0, final_speed=2.0)  # fmt: skip
    return LoopOutcome(**{**base, **kw})


BRAKED = dict(first_warning_time=1.0, brake_time=1.2, warned_frames=5, final_speed=0.0)


def _runs() -> list[LoopOutcome]:
    """Seeds 0-3 of a two-person scenario: without braking seeds 0 and 1 hit the child."""
    runs = [_outcome(NO_BRAKE, s, contact=s < 2, contact_time=3.0 if s < 2 else None,
                     impact_speed=2.0 if s < 2 else None, min_gap=0.0 if s < 2 else 1.0,
                     people=2) for s in range(4)]  # fmt: skip
    who = dict(braked_for_track=2, people=2)
    child = dict(braked_for="child", braked_for_on_course=True, braked_for_ttc=1.2)
    runs += [
        _outcome("rules/ground", 0, **BRAKED, **who, **child),
        # avoided the contact, but braking for the adult on the kerb: luck, not right
        _outcome(
            "rules/ground", 1, **BRAKED, **who, braked_for="adult", braked_for_on_course=False
        ),
        _outcome("rules/ground", 2, **BRAKED, **who, braked_for=NOBODY, braked_for_on_course=False),
        _outcome("rules/ground", 3, **BRAKED, **who, **child),
    ]
    return runs


def test_brakes_for_the_wrong_person_are_counted_apart_and_listed_with_the_person():
    runs = _runs()
    rows = {r.policy: r for r in summarise(runs)}
    ground = rows["rules/ground"]
    assert (ground.braked, ground.wrong_person, ground.avoided) == (4, 2, 2)
    assert ground.needless_stops == 2  # seeds 2 and 3: the baseline ended without contact
    assert rows[NO_BRAKE].wrong_person is None  # never braked, names no one
    wrong = went_wrong(runs)[4:]
    assert wrong == [None, WRONG_PERSON, WRONG_PERSON, NEEDLESS]
    assert runs[5].braked_for_said() == "braked for adult (track 2, not on a collision course)"
    assert runs[6].braked_for_said() == "braked for nobody (track 2, a phantom)"
    table = format_table(summarise(runs))
    head, _, *lines = table.splitlines()
    cells = [c.strip() for c in head.strip("|").split("|")]
    column = cells.index("braked for the wrong person")
    ground_line = next(line for line in lines if line.startswith("| rules/ground "))
    assert ground_line.strip("|").split("|")[column].strip() == "2"
    shown = format_runs(runs)
    assert "| adult (track 2, not on a collision course) |" in shown
    assert "| child (track 2, on a collision course, contact in 1.20 s) |" in shown
    assert replace(runs[4], braked_for_ttc=None).braked_for_said() == (
        "braked for child (track 2, on a collision course)"
    )


def test_runs_that_name_no_one_give_the_tables_they_always_gave():
    runs = [replace(o, braked_for=None, braked_for_track=None, braked_for_on_course=None)
            for o in _runs()]  # fmt: skip
    table = format_table(summarise(runs))
    assert "wrong person" not in table and table.splitlines()[1] == "|" + " --- |" * 11
    assert "braked for" not in format_runs(runs).splitlines()[0]
    assert WRONG_PERSON not in went_wrong(runs)


def test_whom_it_braked_for_is_written_only_for_the_people_tracker_or_several_people():
    from sim.runs.closed_loop_grid import outcome_of

    one = _outcome("rules/image", 0, **BRAKED, braked_for="ped", braked_for_track=1,
                   braked_for_on_course=True)  # fmt: skip
    plain = outcome_json(one, "one")
    assert not set(OPTIONAL) & set(plain)  # the line a one-tracker run always wrote
    row = json.loads(json.dumps({"outcome": plain}))
    assert outcome_of(row).braked_for is None  # an old line reads back with the default
    for data in (outcome_json(one, "everyone"), outcome_json(replace(one, people=2), "one")):
        assert set(OPTIONAL) <= set(data)
        again = outcome_of(json.loads(json.dumps({"outcome": data})))
        assert (again.braked_for, again.braked_for_on_course) == ("ped", True)


def test_the_tracker_enters_a_runs_id_only_when_it_is_the_people_tracker():
    from sim.runs import closed_loop_grid as grid
    from sim.runs.latency import FIXED, LatencySetting

    sources = grid.file_sources([TWO_PEOPLE], None, None)
    scenarios = grid.scenarios_of(sources)
    latency = LatencySetting(FIXED, 100.0)
    one = grid.expand(sources, scenarios, ["rules/image"], latency)
    everyone = grid.expand(sources, scenarios, ["rules/image"], latency, tracker="everyone")
    default = grid.loop_run(scenarios[0], "rules/image", sources[0], latency)
    assert one[0].id == default.id and one[0].tracker == "one"
    assert everyone[0].id != one[0].id and everyone[0].tracker == "everyone"
    with pytest.raises(ValueError, match="tracker must be one of one, everyone"):
        replace(one[0], tracker="all")


def test_the_commands_trackers_are_the_runs():
    from sim.commands import tracker_option
    from sim.runs.run_spec import TRACKERS

    assert tracker_option.TRACKERS == TRACKERS


@pytest.mark.parametrize("command", [["closed-loop", "--cases", "5"], ["ncap", "--out", "x"]])
def test_a_bad_tracker_is_refused_in_one_line(capsys, command):
    with pytest.raises(SystemExit) as stop:
        main([*command, "--tracker", "all"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "argument --tracker: invalid choice: 'all' (choose from" in err


def test_the_ncap_report_counts_the_wrong_person_apart_only_where_runs_name_it():
    from sim.analysis.ncap_report import braked_for, braked_for_lines

    def row(policy: str, braked: bool, **named) -> dict:
        return {"policy": policy, "outcome": {"brake_time": 1.0 if braked else None, **named}}

    rows = [
        row("rules/ground", True, braked_for="target", braked_for_on_course=True),
        row("rules/ground", True, braked_for="walker", braked_for_on_course=False),
        row("rules/ground", True, braked_for=NOBODY, braked_for_on_course=False),
        row("rules/ground", False),
        row("rules/image", True, braked_for="target", braked_for_on_course=True),
    ]
    counts = {c.policy: c for c in braked_for(rows)}
    ground = counts["rules/ground"]
    assert (ground.braked, ground.right, ground.bystander, ground.nobody) == (3, 1, 1, 1)
    assert ground.wrong == 2 and counts["rules/image"].wrong == 0
    assert "| rules/ground | 3 | 1 | 2 | 1 | 1 |" in braked_for_lines(rows)
    assert braked_for_lines([row("rules/ground", True)]) == []  # one-tracker lines


@pytest.mark.slow
def test_a_two_person_run_with_the_people_tracker_names_whom_it_braked_for(tmp_path):
    """The child steps out from beside an adult: with everyone tracked the brake acts on
    the worst person's warning, and the run names a person of the scenario (or nobody);
    its recording, read back with rerun's reader, says whom the warnings were for."""
    from sim.runs.closed_loop import run_closed_loop
    from sim.runs.closed_loop_grid import file_sources, scenarios_of
    from tests.rrd import column

    scenario = scenarios_of(file_sources([TWO_PEOPLE], None, None))[0]
    names = {"child", "adult", NOBODY}
    rrd = tmp_path / "run.rrd"
    o = run_closed_loop(
        scenario, "rules/ground", seed=scenario.seed, latency_ms=0.0, rrd=rrd, tracker="everyone"
    )
    assert o.people == 2 and o.braked, o
    assert o.braked_for in names and o.braked_for_track is not None
    assert o.braked_for != NOBODY or o.braked_for_on_course is False
    texts = [t.split("  ", 1)[1] for t in column(rrd, "/events", "TextLog:text") for t in t]
    brake = [t for t in texts if t.startswith("BRAKE at")]
    assert len(brake) == 1 and f"braking for {o.braked_for} (track {o.braked_for_track}" in brake[0]
    warned = [t for t in texts if t.startswith("truth: the warning (rules/ground) is for ")]
    assert warned and all(any(f"for {n} (track " in t for n in names) for t in warned)
    onsets = [t for t in texts if t.startswith("COLLISION IMMINENT (rules/ground): id ")]
    assert onsets and all(" box), case " in t for t in onsets)
