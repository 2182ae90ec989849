"""Synthetic datasets: the spec loader, the COCO files (against pycocotools when installed),
masks, keypoints, truth and feature files, determinism and resuming."""

from __future__ import annotations

import csv
import json
import shutil
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from monopic.replay.logs import read_log
from sim.dataset.build import (
    BuildOutcome,
    DatasetTask,
    build,
    estimate_duration,
    prepare_folder,
    work,
)
from sim.dataset.coco import (
    COCO17_FROM_BLAZEPOSE,
    COCO17_NAMES,
    decode_mask,
    encode_mask,
    read_coco,
    rle_counts,
)
from sim.dataset.spec import DatasetSpec, expand, load_spec
from sim.runs.estimate import DATASET_START_S
from sim.runs.executors import local_executor, ray_executor, ray_runtime_env
from sim.world.intent import Intent
from sim.world.render import KeptRenderContext
from tests.paths import SCENARIOS

CASE_GRID = SCENARIOS / "datasets" / "case_grid.toml"
TINY = f"""\
name = "tiny"
description = "two short runs for the tests"
[[include]]
files = ["{CASE_GRID}"]
sampling = "grid"
[include.parameters]
"path.case" = [5, 6]
"path.distance" = [4.5]
"robot.speed" = [1.0]
duration = [0.5]
"robot.camera.width" = [384]
"robot.camera.height" = [216]
"""
TIMING_COLUMNS = ("detectMs", "landmarksMs", "featuresMs", "predictMs", "warningMs", "totalMs")


def write_spec(folder: Path, text: str = TINY) -> Path:
    path = folder / "tiny.toml"
    path.write_text(text)
    return path


def build_on(spec: DatasetSpec, out: Path, workers: int = 1, report=lambda _: None) -> BuildOutcome:
    """The dataset built as `monopic dataset --workers N` builds it (no progress bar)."""
    executor = local_executor(workers, run=work)
    return build(spec, out, executor, workers, report=report, progress=False)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> tuple[Path, Path, dict]:
    folder = tmp_path_factory.mktemp("ds")
    spec = write_spec(folder)
    out = folder / "out"
    counts = build_on(load_spec(spec), out).counts
    assert counts is not None
    return spec, out, counts


# -- the spec ------------------------------------------------------------------------


def test_the_old_grid_form_is_refused_with_the_way_to_write_it(tmp_path):
    path = write_spec(tmp_path, 'name = "old"\n[grid]\ncases = [5]\ndistances = [4.0]\n')
    with pytest.raises(UserError) as err:
        load_spec(path)
    message = str(err.value)
    assert message.startswith(f"{path}: grid = ") and "path.case" in message
    assert "case_grid.toml" in message and "\n" not in message


def test_a_dataset_refuses_the_people_tracker_in_one_line(tmp_path):
    text = TINY.replace(
        'description = "two short runs for the tests"\n',
        'description = "two short runs for the tests"\ntracker = "everyone"\n',
    )
    path = write_spec(tmp_path, text)
    with pytest.raises(UserError) as err:
        load_spec(path)
    message = str(err.value)
    assert message.startswith(f"{path}: tracker = ") and "monopic video" in message
    assert "\n" not in message
    assert load_spec(write_spec(tmp_path, text.replace("everyone", "one"))).source.tracker == "one"


def test_a_case_grid_expands_in_a_fixed_order_with_distinct_seeds_and_no_repeats(tmp_path):
    text = TINY.replace('"path.case" = [5, 6]', '"path.case" = [5, 6, 9]')
    text = text.replace(
        '"robot.speed" = [1.0]', '"robot.speed" = [1.0]\n"pedestrian.speed" = [1.0, 1.4]'
    )
    spec = load_spec(write_spec(tmp_path, text))
    runs = expand(spec)
    # Two walking speeds for two walking cases, one run of the standing person (case 9).
    assert [r.scenario.case for r in runs] == [5, 5, 6, 6, 9]
    assert [r.id for r in expand(spec)] == [r.id for r in runs]
    assert all(r.id.startswith("case-grid/") for r in runs)
    assert len({r.scenario.seed for r in runs}) == 5
    assert [r.scenario.seed for r in expand(spec)] == [r.scenario.seed for r in runs]
    assert runs[-1].scenario.pedestrian.speed == 0.0  # standing still


def test_the_shipped_case_grids_hold_every_case(tmp_path):
    for name, runs in (("cases-train", 68), ("cases-heldout", 18)):
        spec = load_spec(SCENARIOS / "datasets" / f"{name}.toml")
        expanded = expand(spec)
        assert len(expanded) == runs
        assert {r.scenario.case for r in expanded} == set(range(1, 10))


def test_rle_round_trip():
    rng = np.random.default_rng(1)
    for _ in range(50):
        mask = rng.random(tuple(rng.integers(1, 30, 2))) < rng.random()
        assert np.array_equal(decode_mask(encode_mask(mask)), mask)
        assert sum(rle_counts(mask)) == mask.size


# -- the dataset -----------------------------------------------------------------------


@pytest.mark.slow
def test_coco_files_keypoints_and_masks(dataset):
    _, out, counts = dataset
    b33 = read_coco(out / "annotations" / "blazepose33.json")
    c17 = read_coco(out / "annotations" / "coco17.json")
    assert b33.num_keypoints == 33 and c17.num_keypoints == 17
    assert c17.category["keypoints"] == list(COCO17_NAMES)
    assert len(b33.images) == counts["images"] == 2 * 8 and len(b33.annotations) >= 12
    assert [a["id"] for a in b33.annotations] == [a["id"] for a in c17.annotations]
    for a33, a17 in zip(b33.annotations, c17.annotations, strict=True):
        k33, k17 = b33.keypoints(a33), c17.keypoints(a17)
        assert np.array_equal(k17, k33[list(COCO17_FROM_BLAZEPOSE)])
        assert set(k33[:, 2]) <= {0, 1, 2}
        assert a33["num_keypoints"] == int((k33[:, 2] > 0).sum())
        mask = b33.mask(a33)
        assert mask.sum() == a33["area"] > 0  # an annotation only where the person shows
        png = cv2.imread(str(out / b33.images[a33["image_id"]]["mask_file"]), cv2.IMREAD_GRAYSCALE)
        assert np.array_equal(png > 0, mask)
        x, y, w, h = a33["bbox"]
        ys, xs = np.nonzero(mask)
        assert (x, y, w, h) == (
            xs.min(),
            ys.min(),
            xs.max() + 1 - xs.min(),
            ys.max() + 1 - ys.min(),
        )
        # In-view keypoints lie on the image, mostly near the mask.
        seen = k33[k33[:, 2] == 2]
        assert np.all((seen[:, 0] >= 0) & (seen[:, 0] < 384) & (seen[:, 1] < 216))
    # A person fully in view gets an annotation on every frame.
    truth = [json.loads(line) for p in sorted((out / "truth").rglob("*.jsonl"))
             for line in p.read_text().splitlines()]  # fmt: skip
    in_view = {t["image"] for t in truth if t["in_frame"] and t["visible_fraction"] == 1.0}
    annotated = {b33.images[a["image_id"]]["file_name"] for a in b33.annotations}
    assert in_view and in_view <= annotated


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # pycocotools 2.0.11 on numpy 2
def test_pycocotools_reads_what_our_reader_reads(dataset):
    _, out, _ = dataset
    assert_pycocotools_reads_what_our_reader_reads(out)


def assert_pycocotools_reads_what_our_reader_reads(out: Path) -> None:
    """Both annotation files load in pycocotools with our images, masks and keypoints."""
    coco_module = pytest.importorskip("pycocotools.coco")
    for name in ("blazepose33", "coco17"):
        ours = read_coco(out / "annotations" / f"{name}.json")
        theirs = coco_module.COCO(str(out / "annotations" / f"{name}.json"))
        assert ours.images and ours.annotations
        assert sorted(theirs.getImgIds()) == sorted(ours.images)
        ann_ids = theirs.getAnnIds(catIds=[1])
        assert len(ann_ids) == len(ours.annotations)
        for ann in ours.annotations:
            ref = theirs.loadAnns([ann["id"]])[0]
            assert np.array_equal(theirs.annToMask(ref).astype(bool), ours.mask(ann))
            assert ref["keypoints"] == ann["keypoints"]


@pytest.mark.slow
def test_truth_rows_and_features_in_the_authors_format(dataset):
    _, out, counts = dataset
    rows = list(csv.DictReader((out / "frames.csv").open()))
    assert len(rows) == counts["images"]
    assert {r["case"] for r in rows} == {"5", "6"}  # perpendicular right, left
    # The intent labels (sim.world.intent): a time exactly when something happens.
    assert {r["intent"] for r in rows} <= {i.value for i in Intent}
    assert all((r["intent_time"] == "") == (r["intent"] == "keep going") for r in rows)
    assert {r["case_now"] for r in rows} <= {str(c) for c in range(1, 10)}
    runs = list(csv.DictReader((out / "runs.csv").open()))
    assert [r["run"] for r in runs] == [r.id for r in expand(load_spec(dataset[0]))]
    for path in sorted((out / "features").rglob("*.csv")):
        log = read_log(path)  # the authors' log reader accepts it
        assert len(log) >= 5
        feats = list(csv.DictReader(path.open()))
        assert sum(r["phiRate"] != "" for r in feats) >= len(feats) - 2  # from the 4th frame
        assert all(r["groundSpeed"] == "" or float(r["groundSpeed"]) >= 0 for r in feats)
    card = (out / "README.md").read_text()
    assert "## Licence" in card and "CC-BY-4.0" in card and f"| runs | {counts['runs']} |" in card


def _without_timing(path: Path) -> list[list[str]]:
    rows = list(csv.reader(path.open()))
    keep = [i for i, name in enumerate(rows[0]) if name not in TIMING_COLUMNS]
    return [[r[i] for i in keep] for r in rows]


def _files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.parts[len(folder.parts)] != "features"
    }


def comparable(folder: Path) -> dict[str, object]:
    """A dataset's files less what the measured times move: the features, the byte counts
    (a time's digits change a features file's size) and each run's seconds."""
    out: dict[str, object] = {}
    for name, data in _files(folder).items():
        if name.startswith("runs/"):
            record = json.loads(data)
            record.pop("bytes")
            record.pop("seconds")
            out[name] = record
        elif name == "runs.csv":
            out[name] = [row[:-1] for row in csv.reader(data.decode().splitlines())]
        elif name == "README.md":
            out[name] = [x for x in data.decode().splitlines() if not x.startswith("| size")]
        else:
            out[name] = data
    return out


@pytest.mark.slow
def test_deterministic_and_resumable(dataset, tmp_path):
    spec_path, out, _ = dataset
    spec = load_spec(spec_path)
    # Resume: a run whose record is gone is rendered again, the finished one is skipped.
    again = tmp_path / "again"
    shutil.copytree(out, again)
    second = expand(spec)[1].id
    (again / "runs" / f"{second}.json").unlink()
    (again / "images" / second / "0003.jpg").unlink()
    messages: list[str] = []
    build_on(spec, again, report=messages.append)
    assert any("1 of 2 runs already finished, 1 to render" in m for m in messages)
    assert comparable(again) == comparable(out)
    for path in sorted((out / "features").rglob("*.csv")):
        relative = path.relative_to(out / "features")
        assert _without_timing(path) == _without_timing(again / "features" / relative)
    # Another spec may not write into the same folder.
    other = load_spec(write_spec(tmp_path, TINY.replace("[4.5]", "[4.6]")))
    with pytest.raises(UserError, match="made from another spec"):
        build_on(other, again)


# -- workers -------------------------------------------------------------------------------


def test_the_time_estimate_shares_the_runs_among_the_workers(tmp_path, capsys):
    spec_path = write_spec(tmp_path)
    runs = expand(load_spec(spec_path))
    one, two = (estimate_duration(runs, [], workers) for workers in (1, 2))
    assert one.seconds is not None and two.seconds is not None
    assert two.seconds - DATASET_START_S == pytest.approx((one.seconds - DATASET_START_S) / 2)
    assert estimate_duration(runs, [], None).seconds is None  # a Ray cluster: CPU time only
    out = tmp_path / "out"
    assert main(["dataset", str(spec_path), "--out", str(out), "--estimate-only",
                 "--workers", "2"]) == 0  # fmt: skip
    assert f"time: about {two.seconds:.0f} s on 2 workers:" in capsys.readouterr().out
    assert not out.exists()


def _names(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


@pytest.mark.slow
def test_one_or_two_workers_make_the_same_dataset_file_by_file(dataset, tmp_path):
    # The fixture's two runs rendered one after the other in one worker, on one GL
    # context; here each has a worker of its own and they finish in either order.
    spec_path, out, _ = dataset
    two = tmp_path / "two"
    assert main(["dataset", str(spec_path), "--out", str(two), "--workers", "2"]) == 0
    assert _names(two) == _names(out)
    # Byte for byte (JPEG encoding included): images, masks, truth, COCO files, frames.csv;
    # less the measured times (features' …Ms columns, run seconds) and the byte counts.
    assert comparable(two) == comparable(out)
    for path in sorted((out / "features").rglob("*.csv")):
        assert _without_timing(path) == _without_timing(two / path.relative_to(out))


@pytest.mark.slow
def test_a_failed_run_is_named_the_others_finish_and_the_same_command_completes_it(
    dataset, tmp_path, capsys
):
    spec_path, out, _ = dataset
    spec = load_spec(spec_path)
    first, second = (r.id for r in expand(spec))
    again = tmp_path / "again"
    prepare_folder(spec, again)
    blocker = again / "images" / first  # a file where the run makes its image folder
    blocker.parent.mkdir(parents=True)
    blocker.write_text("")
    argv = ["dataset", str(spec_path), "--out", str(again), "--workers", "2"]
    assert main(argv) == 1
    printed = capsys.readouterr().out
    assert f"run {first} failed: FileExistsError: " in printed
    assert "1 of 2 runs failed, 1 rendered now, 0 were already there" in printed
    assert (again / "runs" / f"{second}.json").is_file()
    assert not (again / "runs" / f"{first}.json").exists()
    assert not any((again / "annotations").iterdir())  # nothing merged from half a dataset
    assert not (again / "frames.csv").exists() and not (again / "README.md").exists()
    blocker.unlink()
    assert main(argv) == 0
    assert "1 of 2 runs already finished, 1 to render" in capsys.readouterr().out
    assert comparable(again) == comparable(out)


def work_on_another_node(task: DatasetTask, kept: KeptRenderContext | None) -> dict[str, Any]:
    """A worker that sees another folder at the dataset's path (a Ray node without a shared
    folder): it writes beside the dataset instead."""
    return work(replace(task, out=task.out.with_name(task.out.name + "-node")), kept)


@pytest.mark.slow
def test_runs_rendered_where_the_dataset_folder_is_not_stop_the_build_in_one_line(tmp_path):
    spec = load_spec(write_spec(tmp_path))
    out = tmp_path / "out"
    executor = local_executor(1, run=work_on_another_node)
    with pytest.raises(UserError) as err:
        build(spec, out, executor, 1, report=lambda _: None, progress=False)
    assert str(err.value).startswith(f"--out {out.absolute()}: run {expand(spec)[0].id} was "
                                      "rendered where this folder is not")  # fmt: skip
    assert (tmp_path / "out-node" / "runs").is_dir() and not any((out / "runs").iterdir())


@pytest.mark.slow
def test_ray_tasks_make_the_same_dataset(dataset, tmp_path):
    ray = pytest.importorskip("ray", reason="Ray is not installed (the optional [ray] extra)")
    spec_path, out, _ = dataset
    on_ray = tmp_path / "ray"
    ray.init(num_cpus=2, include_dashboard=False, runtime_env=ray_runtime_env())
    try:
        outcome = build(load_spec(spec_path), on_ray, ray_executor(None, run=work), None,
                        report=lambda _: None, progress=False)  # fmt: skip
    finally:
        ray.shutdown()
    assert outcome.finished == 2 and not outcome.failed
    assert comparable(on_ray) == comparable(out)
