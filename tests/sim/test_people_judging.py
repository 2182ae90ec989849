"""Whose warning: warnings attributed to the person the pipeline looked at."""

from __future__ import annotations

import pytest

from sim.analysis.people import person_at, summarise_people, warned_people
from sim.analysis.report import people_lines
from sim.runs.result import (
    CameraSummary,
    DecisionColumns,
    PersonColumns,
    PipelineColumns,
    RunResult,
    ScenarioSummary,
    TruthColumns,
)

# Two people side by side in the image: "far" on the left (on a collision course from
# frame 2), "near" a taller box on the right that overlaps far's right edge.
FAR_BOX = [100.0, 50.0, 140.0, 150.0]
NEAR_BOX = [130.0, 20.0, 200.0, 200.0]


def person(name: str, box: list[float], collision: list[int], ttc: list) -> PersonColumns:
    n = len(collision)
    return PersonColumns(name=name, collision=collision, contact=[0] * n, ttc=ttc,
                         box=[box] * n)  # fmt: skip


def run(warn: list[int], feet: list, people: list[PersonColumns] | None = None) -> RunResult:
    n = len(warn)
    people = people if people is not None else [
        person("far", FAR_BOX, [0, 0, 1, 1, 1], [None, None, 2.0, 1.9, 1.8]),
        person("near", NEAR_BOX, [0] * 5, [None] * 5),
    ]  # fmt: skip
    summary = ScenarioSummary("r", None, 2.0, 0.6, 0.8, 1.0, 0.1, 0.5,
                              CameraSummary(320, 180, 65.0, 1.2, 5.0), 1.8, 1.4, 0)  # fmt: skip
    pipeline = PipelineColumns(foot=feet, decisions={"rules/image": DecisionColumns(warn=warn)})
    return RunResult(
        id="r/0", family="f", truth=TruthColumns(t=[0.1 * k for k in range(n)]),
        scenario=summary, pipelines={"main": pipeline}, people=people,
    )  # fmt: skip


def test_a_foot_point_belongs_to_the_smallest_box_holding_it_else_the_nearest() -> None:
    people = run([0] * 5, [None] * 5).people
    assert person_at(people, 0, [120.0, 140.0]) == 0  # only far's box
    assert person_at(people, 0, [135.0, 140.0]) == 0  # both: far's is the smaller
    assert person_at(people, 0, [180.0, 190.0]) == 1
    assert person_at(people, 0, [300.0, 200.0]) == 1  # neither: near's bottom is nearer
    assert person_at(people, 0, None) is None
    assert person_at(people, 0, [None, 3.0]) is None


def test_warnings_for_the_threat_the_wrong_person_or_nobody_are_counted_apart() -> None:
    feet = [None, [180.0, 190.0], [120.0, 140.0], [180.0, 190.0], None]
    row = run([0, 1, 1, 1, 1], feet)
    assert warned_people(row, "rules/image") == [None, 1, 0, 1, None]
    s = summarise_people([row], "rules/image")
    assert (s.runs, s.threat_runs, s.near_misses) == (1, 1, 0)
    assert (s.warned_frames, s.for_threat, s.wrong_person, s.unattributed) == (4, 1, 2, 1)
    assert s.runs_wrong_person == 1 and s.wrong_share == pytest.approx(2 / 3)
    # Contact is 0.2 + 2.0 s: the first warning while anyone is on course (frame 2, 0.2 s)
    # leads it by 2 s, which meets the 1 s goal.
    assert s.warned_1s == 1


def test_runs_with_one_person_are_left_to_the_usual_metrics() -> None:
    row = run([1] * 5, [[120.0, 140.0]] * 5, people=[])
    assert summarise_people([row], "rules/image").runs == 0


def test_a_near_miss_warned_for_a_bystander_is_a_wrong_person_warning() -> None:
    people = [person("a", FAR_BOX, [0] * 3, [None] * 3), person("b", NEAR_BOX, [0] * 3, [None] * 3)]
    s = summarise_people([run([0, 1, 0], [None, [180.0, 190.0], None], people)], "rules/image")
    assert (s.near_misses, s.near_misses_warned, s.wrong_person) == (1, 1, 1)


def test_the_sweep_report_says_whose_warning_only_with_several_people() -> None:
    feet = [None, [180.0, 190.0], [120.0, 140.0], [180.0, 190.0], None]
    lines = people_lines([run([0, 1, 1, 1, 1], feet)], ["rules/image"])
    assert lines[0] == "## Several people: whose warning"
    row = next(line for line in lines if line.startswith("| f "))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[3:7] == ["1/1", "-", "67 % (2/3)", "1"]
    assert people_lines([run([1] * 5, [None] * 5, people=[])], ["rules/image"]) == []
