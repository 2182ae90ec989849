"""A sweep or dataset spec's `camera`: every run under one sensor preset, with the runs
(ids and seeds) the files' own scenarios give, results kept apart by the code version,
and a rerun that gives the run back with its camera."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from monopic.errors import UserError
from sim.dataset.card import _sweep_card
from sim.dataset.spec import expand as expand_dataset
from sim.dataset.spec import load_spec as load_dataset_spec
from sim.runs.code_version import code_version
from sim.runs.executors import work
from sim.runs.rebuild import Asked, code_of, rebuild, rebuild_sweep_line
from sim.runs.result import PipelineColumns, RunResult, TruthColumns
from sim.runs.run_spec import RunSpec
from sim.runs.runner import scenario_summary
from sim.runs.sweep import (
    check_output,
    expand_spec,
    load_spec,
    sweep_code,
    with_camera,
)
from sim.scenario.toml_table import FieldError
from sim.sensor import spec as sensor_spec
from sim.sensor.spec import IMX273
from tests.sim.test_sweep import SCENARIO as TINY


# test_sweep's three 6-frame crossings on a 256x144 camera, the sensor's lines (if any)
# in its [robot.camera].
def scenario_text(sensor: str) -> str:
    return TINY.replace("height = 144\n", f"height = 144\n{sensor}\n", 1)


SPEC = """
name = "tiny"
{camera}
[[include]]
files = ["tiny.toml"]
"""


def spec_file(folder: Path, camera: str | None, sensor: str = "") -> Path:
    """A spec of the tiny file (whose [robot.camera] adds `sensor`) with that `camera`."""
    (folder / "tiny.toml").write_text(scenario_text(sensor))
    path = folder / f"spec-{camera}.toml"
    path.write_text(SPEC.format(camera="" if camera is None else f'camera = "{camera}"'))
    return path


def runs_of(folder: Path, camera: str | None, sensor: str = "") -> list[RunSpec]:
    return expand_spec(load_spec(spec_file(folder, camera, sensor)))


def test_the_key_is_read_and_absent_is_each_file_s_own_camera(tmp_path: Path) -> None:
    assert load_spec(spec_file(tmp_path, None)).camera is None
    assert load_spec(spec_file(tmp_path, "ideal")).camera == "ideal"
    assert load_spec(spec_file(tmp_path, "imx273")).camera == "imx273"


@pytest.mark.parametrize(
    ("value", "said"),
    [('"nikon"', "'nikon': must be one of ideal, imx273"), ("3", "must be a string")],
)
def test_a_bad_camera_is_refused_in_one_line_naming_the_spec_and_field(
    tmp_path: Path, value: str, said: str
) -> None:
    path = spec_file(tmp_path, None)
    path.write_text(f"camera = {value}\n" + path.read_text())
    with pytest.raises(UserError) as err:
        load_spec(path)
    message = str(err.value)
    assert message.startswith(f"{path}: camera = ") and said in message
    assert "\n" not in message


def test_a_camera_keeps_the_file_s_run_ids_and_seeds_and_sets_the_sensor(
    tmp_path: Path,
) -> None:
    own = runs_of(tmp_path, None)
    real = runs_of(tmp_path, "imx273")
    assert len(own) == 3
    assert [r.id for r in real] == [r.id for r in own]
    assert [r.scenario.seed for r in real] == [r.scenario.seed for r in own]
    assert {r.scenario.robot.camera.sensor for r in own} == {None}
    assert {r.scenario.robot.camera.sensor for r in real} == {IMX273}
    for a, b in zip(own, real, strict=True):  # the camera's sensor is all that differs
        camera = replace(a.scenario.robot.camera, sensor=IMX273)
        assert b.scenario == replace(a.scenario, robot=replace(a.scenario.robot, camera=camera))
        assert b.params == a.params
    # "ideal" over a file that names the real camera: that file's ids, the ideal camera.
    sensor = 'preset = "imx273"'
    filed = runs_of(tmp_path, None, sensor)
    ideal = runs_of(tmp_path, "ideal", sensor)
    assert {r.scenario.robot.camera.sensor for r in filed} == {IMX273}
    assert {r.scenario.robot.camera.sensor for r in ideal} == {None}
    assert [r.id for r in ideal] == [r.id for r in filed] != [r.id for r in own]
    assert [r.scenario.seed for r in ideal] == [r.scenario.seed for r in filed]


def test_each_camera_key_has_its_own_code_so_no_sweep_resumes_another_s_results(
    tmp_path: Path,
) -> None:
    specs = {c: load_spec(spec_file(tmp_path, c)) for c in (None, "ideal", "imx273")}
    codes = {c: sweep_code(s) for c, s in specs.items()}
    assert codes[None] == code_version()
    assert len(set(codes.values())) == 3
    assert codes["imx273"].endswith("+camera-imx273")
    # `monopic rerun` checks the code without the tag.
    assert {code_of({"code": c}) for c in codes.values()} == {code_version()}
    # A results file of the ideal camera is not resumed by the real camera's sweep.
    out = tmp_path / "results.jsonl"
    ids = [r.id for r in expand_spec(specs[None])]
    out.write_text(json.dumps({"id": ids[0], "sweep": "tiny", "code": codes[None]}) + "\n")
    assert check_output(specs[None], out, "none").done == {ids[0]}
    with pytest.raises(UserError, match="holds runs of other code"):
        check_output(specs["imx273"], out, "none")


def line_of(run: RunSpec, code: str) -> RunResult:
    """The result line a sweep would write for `run` (its columns left empty)."""
    return RunResult(
        id=run.id,
        family=run.family,
        truth=TruthColumns(),
        scenario=scenario_summary(run.scenario),
        sweep=run.sweep,
        file=run.file,
        kind=run.kind,
        scale=run.scale,
        params=run.params,
        seed=run.scenario.seed,
        code=code,
        pipelines={"main": PipelineColumns()},
    )


@pytest.mark.parametrize(("camera", "sensor"), [("imx273", ""), ("ideal", 'preset = "imx273"')])
def test_a_line_is_rebuilt_with_the_camera_its_sweep_named(
    tmp_path: Path, camera: str, sensor: str
) -> None:
    spec = load_spec(spec_file(tmp_path, camera, sensor))
    code = sweep_code(spec)
    asked = Asked(tmp_path / "results.jsonl", tmp_path / "again.rrd")
    for run in expand_spec(spec):
        again = rebuild(line_of(run, code), asked)
        assert again.scenario == run.scenario
        assert again.id == run.id and again.code == code
    # A line of the file's own camera is rebuilt with the file's camera.
    (own,) = expand_spec(load_spec(spec_file(tmp_path, None, sensor)))[:1]
    assert rebuild(line_of(own, code_version()), asked).scenario == own.scenario
    # An unknown camera in a line's code (newer code's preset): one line naming the field.
    with pytest.raises(FieldError, match=r"results\.jsonl: camera = 'nikon': .*unknown camera"):
        rebuild(line_of(own, f"{code_version()}+camera-nikon"), asked)


def test_a_camera_that_cannot_keep_the_frame_rate_is_refused_naming_the_spec(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    slow = replace(IMX273, name="slow", max_fps=10.0)
    monkeypatch.setitem(sensor_spec.PRESETS, "slow", slow)
    (run,) = runs_of(tmp_path, None)[:1]
    spec = tmp_path / "spec.toml"
    with pytest.raises(FieldError) as err:
        with_camera(run.scenario, "slow", spec)
    message = str(err.value)
    assert message.startswith(f"{spec}: camera = 'slow': run {run.id}: fps = 15")
    assert "\n" not in message


def test_a_dataset_spec_takes_the_camera_with_the_same_runs(tmp_path: Path) -> None:
    path = spec_file(tmp_path, "imx273")
    dataset = load_dataset_spec(path)
    runs = expand_dataset(dataset)
    own = runs_of(tmp_path, None)
    assert [r.id for r in runs] == [r.id for r in own]
    assert [r.params["seed"] for r in runs] == [r.scenario.seed for r in own]
    assert {r.scenario.robot.camera.sensor for r in runs} == {IMX273}
    counts = {"image_sizes": [(256, 144)], "families": {"tiny": 3}}
    assert "spec's `camera`, imx273" in _sweep_card(dataset, dataset.source, counts)[2]
    path.write_text('camera = "nikon"\n' + spec_file(tmp_path, None).read_text())
    with pytest.raises(UserError) as err:
        load_dataset_spec(path)
    message = str(err.value)
    assert message.startswith(f"{path}: camera = 'nikon': must be one of") and "\n" not in message


def test_a_real_camera_run_writes_its_camera_and_rebuilds_from_its_line(tmp_path: Path) -> None:
    spec = load_spec(spec_file(tmp_path, "imx273"))
    run = replace(expand_spec(spec)[2], code=sweep_code(spec), ablation=False)
    row = work(run)
    assert "error" not in row, row.get("error")
    assert row["camera"] == "imx273" and row["code"].endswith("+camera-imx273")
    assert (row["id"], row["seed"]) == (run.id, run.scenario.seed)
    plain = json.loads(json.dumps(row))  # as a results file holds it
    again = rebuild_sweep_line(plain, Asked(tmp_path / "r.jsonl", tmp_path / "again.rrd"))
    assert again.scenario == run.scenario and again.ablation is False
