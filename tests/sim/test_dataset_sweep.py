"""Datasets from sweep specs: the same runs as `monopic sweep`, strict one-line errors for
either form, and a tiny sweep-form dataset rendered, read by pycocotools and resumed."""

from __future__ import annotations

import csv
import json
import shutil
from collections import Counter
from pathlib import Path

import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from sim.dataset.build import prepare_folder
from sim.dataset.spec import expand, load_spec
from sim.runs import sweep
from tests.paths import SCENARIOS
from tests.sim.test_dataset import (
    _without_timing,
    assert_pycocotools_reads_what_our_reader_reads,
    build_on,
    comparable,
)

SWEEP_KEYS = ", ".join(sorted(sweep.SPEC_KEYS))  # the form detection takes these for a sweep's
CASES = SCENARIOS / "cases"
# Two shipped case files, one random draw each, cut to 0.5 s on a small camera: seconds.
TINY_SWEEP = f"""\
name = "tiny-sweep"
description = "two short runs for the tests"
licence = "CC0-1.0"
[[include]]
files = ["{CASES}/case5_*.toml", "{CASES}/case6_*.toml"]
sampling = "random"
runs = 1
seed = 4
[include.parameters]
duration = [0.5]
"robot.camera.width" = [384]
"robot.camera.height" = [216]
"""


def write_spec(folder: Path, text: str = TINY_SWEEP, name: str = "spec.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


# -- the spec ------------------------------------------------------------------------


@pytest.mark.parametrize("spec", ["datasets/ncap-small.toml", "sweeps/demo.toml"])
def test_a_sweep_spec_gives_the_runs_monopic_sweep_runs(spec: str) -> None:
    path = SCENARIOS / spec
    ours = expand(load_spec(path))
    theirs = sweep.expand_spec(sweep.load_spec(path))
    assert ours and [r.id for r in ours] == [r.id for r in theirs]
    for run, run_spec in zip(ours, theirs, strict=True):
        assert run.scenario == run_spec.scenario  # name and seed included
        assert run.params["parameters"] == run_spec.params
        assert run.params["seed"] == run_spec.scenario.seed
        assert run.params["family"] == run_spec.family


def test_the_shipped_example_is_a_few_small_robot_families_at_one_or_two_runs() -> None:
    spec = load_spec(SCENARIOS / "datasets" / "ncap-small.toml")
    runs = expand(spec)
    per_family = Counter(r.params["family"] for r in runs)
    assert len(per_family) >= 3 and set(per_family.values()) <= {1, 2}
    assert {r.params["scale"] for r in runs} == {"small"}
    assert sum(r.scenario.frames for r in runs) <= 450  # a minute or two on two cores
    assert spec.licence == "CC-BY-4.0" and spec.name == "ncap-small"


def test_monopic_sweep_accepts_the_dataset_keys_of_a_sweep_spec(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = SCENARIOS / "datasets" / "ncap-small.toml"
    assert sweep.load_spec(path).licence == "CC-BY-4.0"
    assert main(["sweep", str(path), "--dry-run", "--out", str(tmp_path / "r.jsonl")]) == 0
    assert "6 runs in 4 families" in capsys.readouterr().out
    bad = write_spec(tmp_path, TINY_SWEEP.replace('"CC0-1.0"', "3"))
    with pytest.raises(UserError, match=r"licence = 3: must be a string, not an integer"):
        sweep.load_spec(bad)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (('licence = "CC0-1.0"', "licence = 3"), "licence = 3: must be a string, not an integer"),
        (('licence = "CC0-1.0"', 'licence = " "'), "licence = ' ': must not be empty"),
        (('name = "tiny-sweep"', 'name = "a b"'), "name = 'a b': must be a non-empty name"),
        # The seeds come from the includes, not from the top of the spec.
        (("licence", "seed = 3\nlicence"), f"seed = 3: unknown key (known here: {SWEEP_KEYS}; see"),
        (("runs = 1", "runs = 0"), "include[0].runs = 0: must be an integer >= 1"),
        (("sampling = \"random\"", "sampling = \"all\""), "include[0].sampling = 'all': must be"),
        (("case6_*", "case66_*"), "include[0].files = '/"),
        (("duration = [0.5]", "duration = [-1.0]"), "duration = -1.0: must be > 0 s"),
        (("[[include]]", "[grid]\ncases = [5]\n[[include]]"),
         "grid = {cases = [5]}: the [grid] form is gone: a dataset spec is a sweep spec"),
        (("include", "includes"), "includes = [{files = ['/"),
    ],
)  # fmt: skip
def test_a_bad_sweep_form_spec_is_one_line_naming_file_field_and_value(
    tmp_path: Path, change: tuple[str, str], expected: str
) -> None:
    path = write_spec(tmp_path, TINY_SWEEP.replace(*change))
    with pytest.raises(UserError) as err:
        expand(load_spec(path))  # some mistakes show only when the runs are built
    message = str(err.value)
    assert expected in message and "\n" not in message, message
    assert message.startswith(str(path)) or message.startswith(str(CASES)), message


def test_a_spec_without_includes_is_a_one_line_error_through_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    typo = write_spec(tmp_path, TINY_SWEEP.replace("include", "includes"), "typo.toml")
    empty = write_spec(tmp_path, 'name = "x"\nlicence = "CC0-1.0"\n', "empty.toml")
    out = str(tmp_path / "out")
    assert main(["dataset", str(typo), "--out", out]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{typo}: includes = [" in err and "unknown key (did you mean 'include'? known" in err
    assert "\n" not in err
    assert main(["dataset", str(empty), "--out", out]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"{empty}: include = []: a sweep needs at least one [[include]]")
    assert not (tmp_path / "out").exists()


# -- the dataset -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def sweep_dataset(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("sweep-ds")
    spec = write_spec(folder)
    out = folder / "out"
    assert main(["dataset", str(spec), "--out", str(out)]) == 0
    return spec, out


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # pycocotools 2.0.11 on numpy 2
def test_a_sweep_form_dataset_renders_and_loads_in_pycocotools(sweep_dataset) -> None:
    spec_path, out = sweep_dataset
    ids = [r.id for r in sweep.expand_spec(sweep.load_spec(spec_path))]
    assert len(ids) == 2 and all("/" in i for i in ids)
    assert_pycocotools_reads_what_our_reader_reads(out)
    for run_id in ids:  # the sweep's run ids, nested as its recordings are
        assert len(list((out / "images" / run_id).glob("*.jpg"))) == 8
        assert (out / "truth" / f"{run_id}.jsonl").is_file()
        assert (out / "features" / f"{run_id}.csv").is_file()
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert [r["run"] for r in rows] == ids
    assert {r["family"] for r in rows} == {"cases"}
    assert all(json.loads(r["parameters"])["duration"] == 0.5 for r in rows)
    frames = list(csv.DictReader((out / "frames.csv").open()))
    assert {f["run"] for f in frames} == set(ids) and len(frames) == 16
    card = (out / "README.md").read_text()
    assert "CC0-1.0" in card and "Runs per family: cases: 2." in card
    assert "`monopic sweep` expands it" in card and "duration in [0.5]" in card
    copies = sorted(p.name for p in (out / "scenarios").rglob("*.toml"))
    assert copies == ["case5_perpendicular_right.toml", "case6_perpendicular_left.toml"]


@pytest.mark.slow
def test_a_sweep_form_dataset_resumes_with_the_same_files(sweep_dataset, tmp_path: Path) -> None:
    spec_path, out = sweep_dataset
    spec = load_spec(spec_path)
    second = expand(spec)[1].id
    again = tmp_path / "again"
    shutil.copytree(out, again)
    (again / "runs" / f"{second}.json").unlink()
    (again / "images" / second / "0003.jpg").unlink()
    messages: list[str] = []
    build_on(spec, again, report=messages.append)
    assert any("1 of 2 runs already finished, 1 to render" in m for m in messages)
    assert comparable(again) == comparable(out)  # the same images, masks, truth, COCO
    for path in sorted((out / "features").rglob("*.csv")):
        assert _without_timing(path) == _without_timing(again / path.relative_to(out))


def test_an_edited_scenario_file_makes_another_dataset(tmp_path: Path) -> None:
    """The spec's text alone does not say what a sweep-form dataset's runs are."""
    cases = tmp_path / "cases"
    shutil.copytree(CASES, cases)
    path = write_spec(tmp_path, TINY_SWEEP.replace(str(CASES), str(cases)))
    out = tmp_path / "out"
    prepare_folder(load_spec(path), out)
    copied = out / "scenarios" / "cases" / "case5_perpendicular_right.toml"
    assert copied.read_text() == (cases / copied.name).read_text()
    edited = (cases / copied.name).read_text().replace("distance = 8.0", "distance = 9.0")
    (cases / copied.name).write_text(edited)
    with pytest.raises(UserError, match="made from another spec"):
        build_on(load_spec(path), out)
