"""The results schema: a line written, read back as a record, equal field by field."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from sim.runs.result import (
    SCHEMA,
    CameraSummary,
    DecisionColumns,
    ExposureColumns,
    Machine,
    PersonColumns,
    PipelineColumns,
    ResultError,
    RunResult,
    ScenarioSummary,
    Timing,
    TrackColumns,
    TruthColumns,
)
from sim.runs.results_file import ResultsWriter, read_results


def every_field_set() -> RunResult:
    """A record whose every field holds a value other than its default."""
    n = 3
    truth = TruthColumns(
        **{
            f.name: [None, 1.5, 2] if f.name not in ("foot", "future") else [None, [1.0, None]]
            for f in dataclasses.fields(TruthColumns)
        }
    )
    decisions = DecisionColumns(
        warn=[None, 0, 1], case=[None, 5, 6], foot=[None, [1.0, 2.0], None],
        ground=[[0.5, -0.25], None, None], ttc=[None, 0.75, None],
    )  # fmt: skip
    pipeline = PipelineColumns(
        found=[0, 1, 1], phi=[None, 10.5, -3.0], foot=[None, [3.0, 4.0], [5.0, None]],
        height=[None, 120.0, 121.5], detector_runs=[2, 0, 1], decisions={"rules/image": decisions},
    )  # fmt: skip
    return RunResult(
        id="family/0003-abcdef12",
        family="cpna25",
        truth=truth,
        scenario=ScenarioSummary(
            name="family/0003-abcdef12",
            case=5,
            robot_speed=2.5,
            robot_width=0.6,
            robot_length=0.8,
            horizon=1.5,
            dt=1 / 15,
            duration=4.0,
            camera=CameraSummary(768, 432, 65.0, 1.2, 5.0),
            pedestrian_height=1.15,
            pedestrian_speed=1.4,
            occluders=2,
            behaviour="human",
            cues=True,
            lighting="overcast",
        ),  # fmt: skip
        schema=SCHEMA,
        sweep="demo",
        file="scenarios/families/small/cpna25.toml",
        kind="collision",
        scale="small",
        params={"robot.speed": 2.5, "scene.lighting": "overcast"},
        seed=123456,
        code="0123456789ab",
        frames=n,
        contact_time=2.6,
        recording="cpna25/0003-abcdef12.rrd",
        pipelines={"main": pipeline, "gtcrop": PipelineColumns(found=[1, 1, 1])},
        timing=Timing(
            wall_s=3.25,
            sim_ms=[30.0, 31.5, 29.0],
            ms={"main": {"total": [12.0, None, 11.0]}},
            machine=Machine(host="vm", cpu="AMD EPYC", cores=2),
        ),  # fmt: skip
        people=[
            PersonColumns(
                name=name,
                scripted=name == "ped",
                **{
                    f.name: [1, None, 0] if f.type == "list[int]" else [0.5, None, [1.0, 2.0]]
                    for f in dataclasses.fields(PersonColumns)
                    if f.name not in ("name", "scripted")
                },
            )
            for name in ("ped", "b1")
        ],
        first_threat="b1",
        tracker="everyone",
        tracks={
            "main": TrackColumns(
                boxes=[[[1, 10.0, 20.0, 30.0, 80.0]], [], [[1, 11.0, 20.0, 31.0, 80.0]]],
                warned_for={"rules/image": [None, None, 1]},
            )
        },
        camera="imx273",
        exposure=ExposureColumns(
            exposure_ms=[0.22, 0.23, None],
            gain=[1.0, 1.5, None],
            subframes=[1, 3, 1],
            signal=[0.18, None, 0.2],
        ),  # fmt: skip
    )


def test_a_written_line_reads_back_with_every_field_equal(tmp_path: Path) -> None:
    record = every_field_set()
    defaults = RunResult(id="x", family="f", truth=TruthColumns(), scenario=record.scenario)
    # The fixture really sets every optional field (else the round trip would not show it).
    unset = {"schema", "scenario"}  # the code's schema; a required field (no default)
    same = [
        f.name
        for f in dataclasses.fields(RunResult)
        if f.name not in unset and getattr(record, f.name) == getattr(defaults, f.name)
    ]
    assert same == []
    path = tmp_path / "r.jsonl"
    with ResultsWriter(path) as writer:
        writer.append(record.to_json())
    (back,) = read_results(path)
    assert back == record
    for f in dataclasses.fields(RunResult):
        assert getattr(back, f.name) == getattr(record, f.name), f.name
    assert json.loads(path.read_text()) == record.to_json()


def test_lines_keep_their_key_order_and_deterministic_drops_only_timing() -> None:
    record = every_field_set()
    assert list(record.to_json()) == [*RunResult.ORDER, *RunResult.OPTIONAL]
    ideal = dataclasses.replace(record, camera="", exposure=None)  # no `camera`, `exposure`
    assert list(ideal.to_json()) == [*RunResult.ORDER, *RunResult.OPTIONAL[:-2]]
    one = dataclasses.replace(ideal, tracker="", tracks={})  # the one-pedestrian tracker
    assert list(one.to_json()) == [*RunResult.ORDER, "people", "first_threat"]
    alone = dataclasses.replace(one, people=[], first_threat=None)  # one person
    assert list(alone.to_json()) == list(RunResult.ORDER)
    assert set(record.to_json()) - set(record.deterministic()) == {"timing"}


def test_a_field_added_later_loads_with_its_default_from_older_lines() -> None:
    line = every_field_set().to_json()
    del line["recording"], line["timing"]["sim_ms"]
    back = RunResult.from_json(line)
    assert back.recording is None and back.timing.sim_ms == []


def test_lines_before_the_walker_model_was_summarised_take_the_sweeps_setting() -> None:
    line = every_field_set().to_json()
    del line["scenario"]["behaviour"], line["scenario"]["cues"]
    line["params"] = {"pedestrian.behaviour.model": "human"}
    back = RunResult.from_json(line)
    assert (back.scenario.behaviour, back.scenario.cues) == ("human", False)
    del line["params"]["pedestrian.behaviour.model"]
    assert RunResult.from_json(line).scenario.behaviour == "rail"  # nothing set: the default
    named = every_field_set().to_json()
    named["scenario"]["behaviour"] = "rail"
    named["params"] = {"pedestrian.behaviour.model": "human"}  # the summary wins when present
    assert RunResult.from_json(named).scenario.behaviour == "rail"


def test_lines_before_the_lighting_was_recorded_read_as_the_preset_they_used() -> None:
    line = every_field_set().to_json()
    del line["scenario"]["lighting"]
    assert RunResult.from_json(line).scenario.lighting == "overcast"  # the sweep set it
    line["params"] = {}
    assert RunResult.from_json(line).scenario.lighting == "noon"  # a file's default
    line["file"] = ""
    assert RunResult.from_json(line).scenario.lighting == "day"  # built in code
    named = every_field_set().to_json()
    named["params"] = {"scene.lighting": "morning"}  # the summary wins when present
    assert RunResult.from_json(named).scenario.lighting == "overcast"


def test_lines_of_older_code_read_in_the_registry_vocabulary() -> None:
    """The ID3 tree was 'id3-tree' in results before its registry name 'tree' became the
    only name: such lines read as tree/image, so no report shows both names."""
    line = every_field_set().to_json()
    decisions = line["pipelines"]["main"]["decisions"]
    decisions["id3-tree/image"] = decisions["rules/image"]
    back = RunResult.from_json(line)
    assert sorted(back.pipelines["main"].decisions) == ["rules/image", "tree/image"]
    assert (
        back.pipelines["main"].decisions["tree/image"]
        == back.pipelines["main"].decisions["rules/image"]
    )


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.update(schema=SCHEMA + 1), r"r.jsonl:7: results schema 2.*newer code"),
        (lambda d: d.update(schema=0), r"results schema 0.*--restart"),
        (lambda d: d.pop("truth"), r"r.jsonl:7.truth: missing"),
        (lambda d: d["scenario"].pop("camera"), r"r.jsonl:7.scenario.camera: missing"),
        (lambda d: d.update(pipelines=[]), r"r.jsonl:7.pipelines: expected an object"),
        (
            lambda d: d["pipelines"]["main"].update(decisions={"rules/image": 3}),
            r"pipelines.main.decisions.rules/image: expected an object",
        ),
    ],
)
def test_a_line_that_does_not_fit_is_refused_in_one_line(edit, message) -> None:
    line = every_field_set().to_json()
    edit(line)
    with pytest.raises(ResultError, match=message):
        RunResult.from_json(line, "r.jsonl:7")
