"""Datasets of runs with several people: every visible person annotated from their own mask
(read and scored by pycocotools), and each run a MOTChallenge sequence that track-eval and
the image-sequence reader take as they take a real one."""

from __future__ import annotations

import configparser
import json
import shutil
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from monopic.evaluation.mot import evaluate_files, read_mot_rows
from monopic.image_sequence import ImageSequenceSource
from sim.dataset import build as build_module
from sim.dataset.build import DatasetTask, build, finished_runs, work
from sim.dataset.coco import mask_box, read_coco
from sim.dataset.mot import clipped_box
from sim.dataset.spec import DatasetRun, load_spec
from sim.scenario.spec import (
    CameraSpec,
    Occluder,
    PedestrianSpec,
    RoadLayout,
    RobotSpec,
    Scenario,
    SceneSpec,
)
from tests.paths import ROOT
from tests.sim.test_dataset import assert_pycocotools_reads_what_our_reader_reads, write_spec

WIDTH, HEIGHT = 320, 180
# A standing robot looks down the street: the scripted pedestrian crosses 8 m ahead from
# the right pavement; on the left pavement someone waits; on the right one a person stands
# behind a van taller than they are, wholly hidden; a fourth stands behind the robot.
CROSSING = PedestrianSpec(x=8.0, y=-4.0, heading_deg=90.0, speed=1.4)
WAITING = PedestrianSpec(x=10.0, y=4.5, heading_deg=270.0, speed=0.0, name="waiting")
HIDDEN = PedestrianSpec(x=15.0, y=-5.0, heading_deg=90.0, speed=0.0, name="behind the van")
BEHIND = PedestrianSpec(x=-6.0, y=5.0, heading_deg=0.0, speed=0.0, name="behind the robot")
VAN = Occluder(x=12.0, y=-5.0, length=5.0, width=2.4, height=2.6)
NAMES = ["ped", "waiting", "behind the van", "behind the robot"]


def scenario(*bystanders: PedestrianSpec) -> Scenario:
    return Scenario(
        name="people", pedestrian=CROSSING, bystanders=bystanders,
        robot=RobotSpec(speed=0.0, camera=CameraSpec(WIDTH, HEIGHT)),
        scene=SceneSpec(occluders=(VAN,), road=RoadLayout(buildings=False)), duration=0.4,
    )  # fmt: skip


def dataset_run(index: int, name: str, sc: Scenario) -> DatasetRun:
    params = {"family": "people", "kind": "test", "scale": "small", "parameters": {}, "seed": 0}
    return DatasetRun(index, f"people/{index}-{name}", params, sc)


# A run of four people, then the same street with the scripted pedestrian alone.
RUNS = [
    dataset_run(0, "four", scenario(WAITING, HIDDEN, BEHIND)),
    dataset_run(1, "alone", scenario()),
]
FRAMES = RUNS[0].scenario.frames


def in_process(tasks: Sequence[DatasetTask], on_result: Any) -> None:
    for task in tasks:
        on_result(work(task))


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("people")
    spec = load_spec(write_spec(folder))  # a spec for the card; its runs are replaced
    out = folder / "out"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(build_module, "expand", lambda _spec: RUNS)
        outcome = build(spec, out, in_process, 1, report=lambda _: None, progress=False)
    assert outcome.counts is not None, outcome.failed
    return out


def truth_lines(out: Path, run: DatasetRun) -> list[dict[str, Any]]:
    text = (out / "truth" / f"{run.id}.jsonl").read_text()
    return [json.loads(line) for line in text.splitlines()]


def test_every_visible_person_has_an_annotation_from_their_own_mask(dataset: Path) -> None:
    coco = read_coco(dataset / "annotations" / "coco17.json")
    assert len(coco.images) == 2 * FRAMES
    by_image: dict[int, dict[str, dict[str, Any]]] = defaultdict(dict)
    for ann in coco.annotations:
        assert ann["person"] not in by_image[ann["image_id"]]
        by_image[ann["image_id"]][ann["person"]] = ann
    assert len({a["id"] for a in coco.annotations}) == len(coco.annotations)
    four, alone = RUNS
    for image in coco.images.values():
        people = by_image[image["id"]]
        # The crossing and the waiting person show; the one behind the van and the one
        # behind the robot do not, and have no annotation.
        expected = ["ped", "waiting"] if image["run"] == four.id else ["ped"]
        assert sorted(people) == expected
        seen = np.zeros((HEIGHT, WIDTH), dtype=bool)
        for name, ann in people.items():
            track_id = NAMES.index(name) + 1
            assert ann["track_id"] == track_id and ann["iscrowd"] == 0
            suffix = "" if track_id == 1 else f"-{track_id}"
            assert ann["mask_file"] == f"masks/{image['run']}/{image['frame']:04d}{suffix}.png"
            png = cv2.imread(str(dataset / ann["mask_file"]), cv2.IMREAD_GRAYSCALE) > 0
            mask = coco.mask(ann)
            assert np.array_equal(png, mask)
            assert ann["area"] == mask.sum() > 0 and ann["bbox"] == mask_box(mask)
            assert not (seen & mask).any()  # each pixel is one person's
            seen |= mask
            kp = coco.keypoints(ann)
            assert ann["num_keypoints"] == int((kp[:, 2] > 0).sum()) > 0
        if image["run"] == four.id:
            for track_id in (3, 4):  # the hidden people's masks are written, and empty
                path = dataset / "masks" / image["run"] / f"{image['frame']:04d}-{track_id}.png"
                assert not cv2.imread(str(path), cv2.IMREAD_GRAYSCALE).any()
    # The scripted pedestrian's annotation keeps the image's id and mask file.
    assert all(by_image[i]["ped"]["id"] == i for i in coco.images)
    assert all(
        by_image[i]["ped"]["mask_file"] == img["mask_file"] for i, img in coco.images.items()
    )


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # pycocotools 2.0.11 on numpy 2
def test_pycocotools_scores_the_ground_truth_against_itself_at_ap_one(dataset: Path) -> None:
    assert_pycocotools_reads_what_our_reader_reads(dataset)
    coco_module = pytest.importorskip("pycocotools.coco")
    cocoeval = pytest.importorskip("pycocotools.cocoeval")
    for name in ("coco17", "blazepose33"):
        gt = coco_module.COCO(str(dataset / "annotations" / f"{name}.json"))
        # The annotations as detections: their boxes, masks and keypoints, score 1.
        detections = [{**a, "score": 1.0} for a in gt.loadAnns(gt.getAnnIds())]
        dt = gt.loadRes(detections)
        for iou_type in ("bbox", "segm", "keypoints"):
            evaluation = cocoeval.COCOeval(gt, dt, iou_type)
            if name == "blazepose33":  # COCO gives sigmas for its own 17 keypoints only
                evaluation.params.kpt_oks_sigmas = np.full(33, 0.05)
            evaluation.evaluate()
            evaluation.accumulate()
            evaluation.summarize()
            assert evaluation.stats[0] == pytest.approx(1.0), (name, iou_type)


def test_each_run_is_a_mot_sequence_with_every_person_in_the_image(dataset: Path) -> None:
    four, alone = RUNS
    folder = dataset / "mot" / four.id
    rows = read_mot_rows(folder / "gt" / "gt.txt")
    # One line per person in the image per frame, frames from 1: the one behind the
    # robot never is; the one behind the van is, wholly hidden (visibility 0).
    per_frame = defaultdict(list)
    for row in rows:
        per_frame[row.frame].append(row.identity)
    assert sorted(per_frame) == list(range(1, FRAMES + 1))
    assert all(ids == [1, 2, 3] for ids in per_frame.values())
    assert all(r.conf == 1 and r.class_id == 1 for r in rows)
    lines = (folder / "gt" / "gt.txt").read_text().splitlines()
    visibility = {
        (r.frame, r.identity): float(x.split(",")[8]) for r, x in zip(rows, lines, strict=True)
    }
    for (_, identity), seen in visibility.items():
        assert seen == 0.0 if identity == 3 else seen > 0.9
    # The ids are the people's: each box is that person's whole-body box from the truth.
    for frame, truth in enumerate(truth_lines(dataset, four), start=1):
        assert [p["name"] for p in truth["people"]] == NAMES
        for row in (r for r in rows if r.frame == frame):
            person = truth["people"][row.identity - 1]
            box = clipped_box(tuple(person["box"]), WIDTH, HEIGHT)
            assert list(row.box) == pytest.approx(box, abs=0.006)
            assert visibility[frame, row.identity] == pytest.approx(
                person["visibility"]["visible"], abs=1e-4
            )
    alone_rows = read_mot_rows(dataset / "mot" / alone.id / "gt" / "gt.txt")
    assert [(r.frame, r.identity) for r in alone_rows] == [(f, 1) for f in range(1, FRAMES + 1)]
    # track-eval reads the folder as it reads a real sequence: the gt as tracks is perfect.
    scores = evaluate_files(folder / "gt" / "gt.txt", folder)
    assert scores.mota == 1.0 and scores.idf1 == 1.0 and scores.gt_identities == 3
    # seqinfo.ini and img1/ make it a sequence the image-sequence reader plays, numbered
    # as the gt numbers the frames.
    info = configparser.ConfigParser()
    info.optionxform = str  # type: ignore[assignment,method-assign]
    info.read(folder / "seqinfo.ini")
    assert dict(info["Sequence"]) == {
        "name": four.id, "imDir": "img1", "frameRate": "15", "seqLength": str(FRAMES),
        "imWidth": str(WIDTH), "imHeight": str(HEIGHT), "imExt": ".jpg",
    }  # fmt: skip
    source = ImageSequenceSource.from_folder(folder, None)
    assert source.first_number == 1 and source.frame_count == FRAMES and source.fps == 15
    assert (source.width, source.height) == (WIDTH, HEIGHT)
    images = dataset / "images" / four.id
    for number, file in enumerate(source.files):
        assert file.read_bytes() == (images / f"{number:04d}.jpg").read_bytes()


def test_the_card_counts_every_person(dataset: Path) -> None:
    card = (dataset / "README.md").read_text()
    annotations = len(read_coco(dataset / "annotations" / "coco17.json").annotations)
    assert annotations == 3 * FRAMES  # two people in one run's frames, one in the other's
    assert "| people per run | 1 to 4 |" in card
    assert f"image where any pixel shows) | {annotations} |" in card
    assert "`mot/<run>/`" in card and "`iscrowd` is always 0" in card


def test_a_run_without_its_mot_sequence_is_rendered_again(tmp_path: Path) -> None:
    run = RUNS[1]
    record = {"format": 1, "id": run.id, "params": run.params}
    (tmp_path / "runs" / "people").mkdir(parents=True)
    (tmp_path / "runs" / f"{run.id}.json").write_text(json.dumps(record))
    assert finished_runs(tmp_path, [run]) == {}  # a record written before the sequences
    (tmp_path / "mot" / run.id / "gt").mkdir(parents=True)
    (tmp_path / "mot" / run.id / "gt" / "gt.txt").write_text("")
    assert finished_runs(tmp_path, [run]) == {run.id: record}


def test_a_dataset_keeps_the_people_files_its_runs_are_made_from(tmp_path: Path) -> None:
    folder = tmp_path / "specs"
    (folder / "people").mkdir(parents=True)
    shutil.copy(ROOT / "scenarios/families/small/cpna25.toml", folder / "cpna25.toml")
    shutil.copy(ROOT / "scenarios/people/pavement_pair.toml", folder / "people/pair.toml")
    spec = folder / "d.toml"
    spec.write_text(
        'name = "d"\ndescription = "x"\n[[include]]\nfiles = ["cpna25.toml"]\n'
        'people = "people/pair.toml"\n'
    )
    names = dict(load_spec(spec).scenario_files)
    assert set(names) == {"cpna25.toml", "people/pair.toml"}
    before = load_spec(spec).digest
    (folder / "people/pair.toml").write_text(
        (folder / "people/pair.toml").read_text().replace("2.4", "2.5", 1)
    )
    assert load_spec(spec).digest != before  # a changed people file is another dataset
