"""Synthetic datasets: scenario runs rendered into images, COCO keypoints, masks and truth rows.

A dataset spec (see scenarios/datasets/README.md) is a sweep spec: the runs
sim.runs.sweep expands it into, with the sweep's run ids, scenarios and seeds (the ids
hold a slash, so the per-run files below nest a folder deeper). Every frame of a run is
one image. For each run the folder gets:

- images/<run>/<frame>.jpg: the robot camera's frame (JPEG, quality 90);
- masks/<run>/<frame>.png: the scripted pedestrian's pixels from MuJoCo's segmentation
  rendering (0/255; occluders, other people included, hide it as in the image); with
  several people, masks/<run>/<frame>-<id>.png each other person's (id as in gt.txt);
- truth/<run>.jsonl: one line per frame, GroundTruth.to_dict() plus the case label and
  the image and mask file names (the intent labels, sim.world.intent, among the truth;
  with several people a `people` list, every person's truth with name and visibility);
- mot/<run>/: the run as a MOTChallenge sequence (sim.dataset.mot): gt/gt.txt, one
  line per person per frame where the person is in the image, seqinfo.ini, and img1/
  linking to the images numbered from 1;
- features/<run>.csv: the pipeline's own per-frame output in the authors' log columns
  (monopic.framelog.AUTHORS_COLUMNS, then ours), the rows `monopic video --csv` writes
  whose authors' columns are all finite (not a track's first frame, which has no
  velocity yet), so `monopic tree train` and `monopic replay` read them as they read the
  authors' logs (the pipeline sees only the frames; their reader takes occupiedHeights
  as a fraction of a 432 px frame, so use 432 px high frames for training);
- runs/<run>.json: written last, the mark of a finished run (resuming skips it).

Merged over the finished runs after every invocation: annotations/blazepose33.json and
annotations/coco17.json (COCO keypoints: one 'person' annotation per person per image
where any pixel of that person is visible, box from that person's mask, visibility 0
outside the image, 1 hidden behind another object, 2 in view; RLE masks; with several
people in any run, every annotation names its person: `person`, `track_id`, `mask_file`),
frames.csv (one row per image, the scripted pedestrian's truth), runs.csv and README.md
(the card: what, how, counts, licence).

The runs execute on the sweep's executors (sim.runs.executors: spawned local workers,
each keeping its GL context from run to run, or Ray tasks): every run writes its own
files, its record comes back to this process, and the merge takes the records in the
spec's order, whichever worker finished first.

Deterministic for a spec, whatever the number of workers: the run seeds (the gait phase)
are the sweep's, the renderer and the pose models are deterministic on one machine, and
every run renders in a worker with the same one-thread environment; only measured times
differ between invocations: the features' …Ms columns and each run record's `seconds`
(which time estimates use).
"""

from __future__ import annotations

import csv
import io
import json
import math
import shutil
import time
import traceback
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from monopic.errors import UserError
from monopic.framelog import FRAME_COLUMNS as FEATURE_COLUMNS
from monopic.framelog import authors_finite, frame_row
from monopic.output import atomic_path, write_text_atomically
from monopic.pipeline import Pipeline
from monopic.predict.base import Mode
from monopic.predict.rules import RulePredictor
from sim.dataset.card import readme
from sim.dataset.coco import SKELETONS, category, encode_mask, mask_box, select_keypoints
from sim.dataset.mot import MOT, SEQINFO, clipped_box, gt_line, link_images, seqinfo
from sim.dataset.spec import FORMAT_VERSION, JPEG_QUALITY, DatasetRun, DatasetSpec, expand
from sim.runs.estimate import (
    DATASET_START_S,
    TimeEstimate,
    bench_frame_seconds,
    estimate_time,
)
from sim.runs.loop import Listener, LoopFrame, OnBoard, run_loop
from sim.runs.sweep import SweepSpec, run_missing
from sim.scenario.spec import CameraSpec, Scenario, person_name
from sim.world.ground_truth import GroundTruth, PersonTruth
from sim.world.render import KeptRenderContext
from sim.world.world import World

# Bytes per frame before any run is measured: JPEG at quality 90 of these renders is about
# 0.16 byte per pixel; mask, truth line, features row and annotations add a few kB.
EST_JPEG_BYTES_PER_PIXEL = 0.17
EST_OTHER_BYTES = 6000


# -- the spec file -------------------------------------------------------------------


# -- runs --------------------------------------------------------------------------------


# -- rendering one run -------------------------------------------------------------------


def dataset_pipeline(scenario: Scenario) -> Pipeline:
    """The paper's image-mode pipeline (rule cascade) whose features the CSV holds."""
    from sim.runs.pipelines import scenario_pipeline

    return scenario_pipeline(scenario, [RulePredictor(mode=Mode.IMAGE)])


def keypoints33(person: PersonTruth, width: int, height: int) -> list[float]:
    """Flat COCO [x, y, v] * 33: v 0 outside the image (x = y = 0), 1 occluded, 2 in view."""
    out: list[float] = []
    for (u, v), hidden in zip(person.landmarks_px, person.landmarks_occluded, strict=True):
        if not (math.isfinite(u) and math.isfinite(v) and 0 <= u < width and 0 <= v < height):
            out += [0, 0, 0]
        else:
            out += [round(float(u), 2), round(float(v), 2), 1 if hidden else 2]
    return out


# A bystander's annotation id: the image's id plus this times (their MOT id - 1), so the
# scripted pedestrian's keeps the image's id (as with one person) and no two collide while
# image ids, (run index + 1) * 10000 + frame, stay below it.
PERSON_ID_STRIDE = 10**10
# Annotation keys a dataset of one person per run leaves out (its files as before people).
PERSON_KEYS = ("person", "track_id", "mask_file")


def mask_name(run_id: str, frame: int, track_id: int) -> str:
    """A person's mask file: the scripted pedestrian's (id 1) <frame>.png as always, the
    others' <frame>-<id>.png."""
    suffix = "" if track_id == 1 else f"-{track_id}"
    return f"masks/{run_id}/{frame:04d}{suffix}.png"


def _truth_line(run: DatasetRun, frame: int, image: str, mask: str, truth: GroundTruth) -> str:
    row = {"run": run.id, "frame": frame, "image": image, "mask": mask}
    row.update(truth.to_dict())
    row["case_name"] = truth.pedestrian.case.label
    return json.dumps(row, separators=(",", ":"), default=_plain)


def _plain(value: object) -> object:
    """numpy scalars as Python ones (GroundTruth.to_dict leaves e.g. a numpy bool)."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


FEATURES = "features"  # the on-board pipeline whose per-frame features the CSV holds


@dataclass
class FrameWriter(Listener):
    """Writes each frame of a dataset run: image, mask, annotation, truth line, features row."""

    run: DatasetRun
    out: Path
    world: World | None = None
    images: list[dict[str, Any]] = field(default_factory=list)
    annotations: list[dict[str, Any]] = field(default_factory=list)
    truth_lines: list[str] = field(default_factory=list)
    gt_lines: list[str] = field(default_factory=list)  # MOTChallenge gt.txt
    feature_rows: list[list[Any]] = field(default_factory=list)
    found: int = 0

    def start(self, world: World) -> None:
        self.world = world

    def frame(self, frame: LoopFrame) -> None:
        assert self.world is not None and frame.step.frame is not None
        run, out, k, truth = self.run, self.out, frame.index, frame.truth
        scenario = run.scenario
        cam = scenario.robot.camera
        image_name = f"images/{run.id}/{k:04d}.jpg"
        bgr = cv2.cvtColor(frame.step.frame.image, cv2.COLOR_RGB2BGR)
        if not cv2.imwrite(str(out / image_name), bgr, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY]):
            raise OSError(f"cannot write {out / image_name}")
        result = frame.results[FEATURES]
        assert result is not None
        self.found += int(result.pose.found)
        if result.features is not None:
            row = frame_row(result, 1.0 / scenario.dt, scenario.horizon)
            if authors_finite(row):
                self.feature_rows.append(row)
        image_id = (run.index + 1) * 10000 + k
        self.images.append(
            {
                "id": image_id,
                "file_name": image_name,
                "width": cam.width,
                "height": cam.height,
                "run": run.id,
                "frame": k,
                "time": round(frame.step.time, 6),
                "mask_file": mask_name(run.id, k, 1),
            }
        )
        masks = self.world.person_masks()
        for track_id, person in enumerate(truth.people, start=1):
            self._person(image_id, k, track_id, person, masks[person.name])
        self.truth_lines.append(_truth_line(run, k, image_name, mask_name(run.id, k, 1), truth))

    def _person(
        self, image_id: int, k: int, track_id: int, person: PersonTruth, mask: np.ndarray
    ) -> None:
        """One person's mask, COCO annotation (if any pixel shows) and gt.txt line (if in
        the image)."""
        assert self.world is not None
        cam = self.run.scenario.robot.camera
        name = mask_name(self.run.id, k, track_id)
        cv2.imwrite(str(self.out / name), mask.astype(np.uint8) * 255)
        area = int(mask.sum())
        if area > 0:
            self.annotations.append(
                {
                    "id": image_id + (track_id - 1) * PERSON_ID_STRIDE,
                    "image_id": image_id,
                    "category_id": 1,
                    "iscrowd": 0,
                    "area": area,
                    "bbox": mask_box(mask),
                    "amodal_bbox": clipped_box(person.box, cam.width, cam.height),
                    "segmentation": encode_mask(mask),
                    "keypoints33": keypoints33(person, cam.width, cam.height),
                    "case": int(person.case),
                    "occluded": bool(person.occluded),
                    "person": person.name,
                    "track_id": track_id,
                    "mask_file": name,
                }
            )
        line = gt_line(k + 1, track_id, person, cam.width, cam.height)
        if line is not None:
            self.gt_lines.append(line)


def render_run(run: DatasetRun, out: Path, kept: KeptRenderContext | None = None) -> dict[str, Any]:
    """Render one run into `out`; returns (and writes last) its runs/<id>.json record.

    `kept`: a GL context lent from run to run (sim.world.render), else the run makes its own.
    """
    start = time.perf_counter()
    scenario = run.scenario
    cam = scenario.robot.camera
    for sub in ("images", "masks"):
        shutil.rmtree(out / sub / run.id, ignore_errors=True)  # a partial earlier attempt
        (out / sub / run.id).mkdir(parents=True)
    sequence = out / MOT / run.id
    shutil.rmtree(sequence, ignore_errors=True)
    for sub in ("truth", "features", "runs"):  # a sweep's run ids nest: <scenario>/<draw>-…
        (out / sub / run.id).parent.mkdir(parents=True, exist_ok=True)
    writer = FrameWriter(run, out)
    context = kept.fitting(cam.width, cam.height) if kept is not None else None
    with World(scenario, render=True, render_context=context) as world:
        onboard = OnBoard(FEATURES, dataset_pipeline(scenario))
        end = run_loop(world, [onboard], [writer], frames=scenario.frames)
    with atomic_path(out / "truth" / f"{run.id}.jsonl") as tmp:
        tmp.write_text("\n".join(writer.truth_lines) + "\n", encoding="utf-8")
    buf = io.StringIO()
    csv_writer = csv.writer(buf, lineterminator="\n")
    csv_writer.writerow(FEATURE_COLUMNS)
    csv_writer.writerows(writer.feature_rows)
    write_text_atomically(out / "features" / f"{run.id}.csv", buf.getvalue())
    link_images(sequence, [out / image["file_name"] for image in writer.images])
    fps = 1.0 / scenario.dt
    info = seqinfo(run.id, fps, len(writer.images), cam.width, cam.height)
    write_text_atomically(sequence / SEQINFO, info)
    (sequence / "gt").mkdir(parents=True, exist_ok=True)
    write_text_atomically(sequence / "gt" / "gt.txt", "".join(f"{x}\n" for x in writer.gt_lines))
    record = {
        "format": FORMAT_VERSION,
        "id": run.id,
        "index": run.index,
        "scenario": scenario.name,
        "params": run.params,
        "people": [person_name(p, i) for i, p in enumerate(scenario.people)],
        "frames": len(writer.images),
        "pose_found": writer.found,
        "feature_rows": len(writer.feature_rows),
        "contact_time": end.contact_time,
        "images": writer.images,
        "annotations": writer.annotations,
    }
    record["bytes"] = _run_bytes(out, run.id)
    record["seconds"] = round(time.perf_counter() - start, 3)  # measured: for time estimates
    write_text_atomically(out / "runs" / f"{run.id}.json", json.dumps(record, default=_plain))
    return record


@dataclass(frozen=True)
class DatasetTask:
    """One run as a worker receives it: the run and the dataset folder it writes into (a
    Ray task writes there on its own node: the folder must be the same one on every node)."""

    run: DatasetRun
    out: Path

    @property
    def id(self) -> str:  # the executors name a run by its id (a dead worker's, a failure)
        return self.run.id


def work(task: DatasetTask, kept: KeptRenderContext | None = None) -> dict[str, Any]:
    """One run in a worker: its record, or {"id", "error"} (the other runs go on).

    `kept`: the worker's GL context, lent to the run.
    """
    try:
        return render_run(task.run, task.out, kept)
    except Exception:  # noqa: BLE001 - reported per run, as a sweep's
        return {"id": task.id, "error": traceback.format_exc()}


def _run_bytes(out: Path, run_id: str) -> int:
    total = 0
    for sub in ("images", "masks"):
        total += sum(p.stat().st_size for p in (out / sub / run_id).iterdir())
    names = (f"truth/{run_id}.jsonl", f"features/{run_id}.csv", f"{MOT}/{run_id}/{SEQINFO}",
             f"{MOT}/{run_id}/gt/gt.txt")  # fmt: skip
    for name in names:
        total += (out / name).stat().st_size
    return total


# -- the whole dataset ---------------------------------------------------------------------


@dataclass(frozen=True)
class SizeEstimate:
    runs: int
    frames: int  # upper bound: runs stop at contact
    bytes_per_frame: float
    measured: bool

    @property
    def total_bytes(self) -> float:
        return self.frames * self.bytes_per_frame

    def text(self) -> str:
        how = "measured on finished runs" if self.measured else "estimated"
        return (
            f"{self.runs} runs x up to {self.frames // max(self.runs, 1)} frames = up to "
            f"{self.frames} images, ~{self.bytes_per_frame / 1e3:.0f} kB per frame ({how}) "
            f"-> ~{self.total_bytes / 1e6:.0f} MB"
        )


def estimate(runs: list[DatasetRun], finished: list[dict[str, Any]]) -> SizeEstimate:
    frames = sum(r.scenario.frames for r in runs)
    measured = [r for r in finished if r["frames"] > 0]
    if measured:
        per = sum(r["bytes"] for r in measured) / sum(r["frames"] for r in measured)
        return SizeEstimate(len(runs), frames, per, True)
    # From each run's camera: a sweep's families differ in resolution.
    guess = sum(r.scenario.frames * _frame_bytes(r.scenario.robot.camera) for r in runs)
    per = guess / frames if frames else _frame_bytes(CameraSpec())
    return SizeEstimate(len(runs), frames, per, False)


def estimate_duration(
    todo: list[DatasetRun], finished: list[dict[str, Any]], workers: int | None
) -> TimeEstimate:
    """The time the runs still to render take on `workers` local workers (None: a Ray
    cluster, CPU time only): per frame as measured on the finished runs' own times (each
    on one worker), else the benchmark (sim.runs.estimate)."""
    return estimate_time(
        [(r.scenario.frames, bench_frame_seconds(r.scenario.robot.camera, False)) for r in todo],
        [(r["frames"], r.get("seconds", 0.0)) for r in finished],
        workers=workers,
        measured_where="of this dataset",
        start_seconds=DATASET_START_S,
    )


def _frame_bytes(cam: CameraSpec) -> float:
    return cam.width * cam.height * EST_JPEG_BYTES_PER_PIXEL + EST_OTHER_BYTES


def finished_runs(out: Path, runs: list[DatasetRun]) -> dict[str, dict[str, Any]]:
    """Records of the runs already done (their runs/<id>.json exists and matches)."""
    done = {}
    for run in runs:
        path = out / "runs" / f"{run.id}.json"
        if not path.exists():
            continue
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError:
            continue  # written atomically, so only a foreign file gets here: redo the run
        if record.get("format") != FORMAT_VERSION or record.get("params") != run.params:
            continue
        # A run rendered before the MOT sequences were written is rendered again.
        if (out / MOT / run.id / "gt" / "gt.txt").is_file():
            done[run.id] = record
    return done


def check_folder(spec: DatasetSpec, out: Path) -> bool:
    """Every check of the dataset folder before anything is rendered: a folder (or none
    yet, with nothing in the way), empty or holding this spec's dataset. True when it holds
    one (a resume). `--estimate-only` makes the same checks, so it refuses what a build
    would refuse, with the same line."""
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: is a file, not a dataset folder")
    for part in out.parents:
        if part.exists():
            if not part.is_dir():
                raise UserError(f"--out {part}: a file is in the way of this folder")
            break
    marker = out / "dataset.json"
    if marker.exists():
        try:
            made = json.loads(marker.read_text(encoding="utf-8"))
        except json.JSONDecodeError:
            raise UserError(f"{marker}: not a dataset marker (invalid JSON)") from None
        if made.get("spec_digest") != spec.digest:
            raise UserError(
                f"{out}: holds dataset {made.get('name')!r} made from another spec "
                f"(digest {made.get('spec_digest')} vs {spec.digest}); choose another --out"
            )
        return True
    if out.exists() and any(out.iterdir()):
        raise UserError(f"{out}: exists and is not empty (and is not a dataset of this spec)")
    return False


def prepare_folder(spec: DatasetSpec, out: Path) -> None:
    """Create the folder, or check that it holds the same spec's dataset (resume)."""
    if check_folder(spec, out):
        return
    for sub in ("images", "masks", "truth", "features", "runs", "annotations", MOT):
        (out / sub).mkdir(parents=True, exist_ok=True)
    write_text_atomically(out / "spec.toml", spec.text)
    for name, text in spec.scenario_files:
        (out / "scenarios" / name).parent.mkdir(parents=True, exist_ok=True)
        write_text_atomically(out / "scenarios" / name, text)
    write_text_atomically(
        out / "dataset.json",
        json.dumps(
            {"name": spec.name, "spec_digest": spec.digest, "format": FORMAT_VERSION}, indent=1
        ),
    )


Executor = Callable[[Sequence[DatasetTask], Callable[[dict[str, Any]], None]], None]


@dataclass(frozen=True)
class BuildOutcome:
    """What one invocation did; `counts` (the merged dataset's) only once every run is done."""

    runs: int  # in the spec
    skipped: int  # finished by an earlier invocation
    finished: int  # rendered now
    failed: tuple[tuple[str, str], ...]  # (run id, error), reported per run
    counts: dict[str, Any] | None  # None: runs failed, nothing merged


@dataclass
class _Records:
    """Where run_missing hands each finished run's record: checked to be in `out` here,
    kept by id; the size estimate is redone on the first one."""

    out: Path
    runs: list[DatasetRun]
    done: dict[str, dict[str, Any]]
    size: SizeEstimate
    report: Callable[[str], None]

    def append(self, record: dict[str, Any]) -> None:
        if not (self.out / "runs" / f"{record['id']}.json").is_file():
            raise UserError(
                f"--out {self.out}: run {record['id']} was rendered where this folder is not "
                "(a Ray node without it): give a folder every node sees at the same path"
            )
        self.done[record["id"]] = record
        if not self.size.measured:
            self.size = estimate(self.runs, list(self.done.values()))
            self.report(f"size, measured on the first run: {self.size.text()}")


def build(
    spec: DatasetSpec,
    out: Path,
    executor: Executor,
    workers: int | None,
    report: Callable[[str], None] = print,
    progress: bool = True,
) -> BuildOutcome:
    """Render every unfinished run of `spec` into `out` on `executor`, then merge.

    `workers`: how many runs the executor runs at once, for the time estimate (None: a
    Ray cluster's, unknown). `report` gets one-line messages (the size estimate first);
    `progress` shows a bar of finished runs. A failed run is named as it fails and the
    others go on; the merged files (COCO, frames.csv, runs.csv, the card) are written
    only when every run is finished, so they never describe a part of the dataset.
    """
    runs = expand(spec)
    prepare_folder(spec, out)
    done = finished_runs(out, runs)
    todo = [r for r in runs if r.id not in done]
    skipped = len(done)
    size = estimate(runs, list(done.values()))
    report(f"size: {size.text()}")
    report(f"{len(done)} of {len(runs)} runs already finished, {len(todo)} to render")
    report(f"time: {estimate_duration(todo, list(done.values()), workers).text()}")

    tasks = [DatasetTask(r, out.absolute()) for r in todo]  # a Ray worker has its own cwd
    records = _Records(out, runs, done, size, report)
    finished, failed = run_missing(tasks, executor, records, spec.name, progress)
    if failed:
        return BuildOutcome(len(runs), skipped, finished, tuple(failed), None)
    counts = merge(spec, out, [done[r.id] for r in runs])
    return BuildOutcome(len(runs), skipped, finished, (), counts)


def merge(spec: DatasetSpec, out: Path, records: list[dict[str, Any]]) -> dict[str, Any]:
    """Write the COCO files, frames.csv, runs.csv and README.md from the run records."""
    images = [img for r in records for img in r["images"]]
    anns = [a for r in records for a in r["annotations"]]
    if not any(len(r["people"]) > 1 for r in records):  # every run of one person: as before
        anns = [{k: v for k, v in a.items() if k not in PERSON_KEYS} for a in anns]
    for skeleton in SKELETONS:
        coco = {
            "info": {
                "description": f"MonoPIC synthetic dataset {spec.name!r} ({skeleton} keypoints)",
                "version": str(FORMAT_VERSION),
                "contributor": "MonoPIC test bed (sim.dataset)",
            },
            "licenses": [{"id": 1, "name": spec.licence}],
            "images": images,
            "annotations": [_coco_annotation(a, skeleton) for a in anns],
            "categories": [category(skeleton)],
        }
        write_text_atomically(out / "annotations" / f"{skeleton}.json", json.dumps(coco))
    frames_csv, case_counts = _frames_csv(out, records)
    write_text_atomically(out / "frames.csv", frames_csv)
    write_text_atomically(out / "runs.csv", _runs_csv(spec, records))
    visibility = Counter(v for a in anns for v in a["keypoints33"][2::3])
    counts = {
        "runs": len(records),
        "images": len(images),
        "annotations": len(anns),
        "feature_rows": sum(r["feature_rows"] for r in records),
        "pose_found": sum(r["pose_found"] for r in records),
        "contacts": sum(r["contact_time"] is not None for r in records),
        "keypoints_visible": visibility.get(2, 0),
        "keypoints_occluded": visibility.get(1, 0),
        "keypoints_outside": visibility.get(0, 0),
        "people": sorted({len(r["people"]) for r in records}),
        "cases": dict(sorted(case_counts.items())),
    }
    if isinstance(spec.source, SweepSpec):
        counts["families"] = dict(Counter(r["params"]["family"] for r in records))
        counts["image_sizes"] = sorted({(i["width"], i["height"]) for i in images})
    counts["bytes"] = sum(r["bytes"] for r in records)
    write_text_atomically(out / "README.md", readme(spec, counts))
    counts["bytes"] = _folder_bytes(out)
    return counts


def _coco_annotation(a: dict[str, Any], skeleton: str) -> dict[str, Any]:
    kp = select_keypoints(a["keypoints33"], skeleton)
    out = {k: v for k, v in a.items() if k != "keypoints33"}
    out["keypoints"] = kp
    out["num_keypoints"] = sum(1 for v in kp[2::3] if v > 0)
    return out


FRAME_COLUMNS = (
    "run", "frame", "image", "mask", "time", "case", "case_name", "phi", "forward", "lateral",
    "velocity_forward", "velocity_left", "heading_robot_deg", "speed", "robot_speed",
    "time_to_collision", "collision", "contact", "in_frame", "occluded", "visible_fraction",
    "box_u0", "box_v0", "box_u1", "box_v1", "foot_u", "foot_v", "case_now", "intent",
    "intent_time",
)  # fmt: skip


def _frames_csv(out: Path, records: list[dict[str, Any]]) -> tuple[str, Counter]:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(FRAME_COLUMNS)
    cases: Counter = Counter()
    for r in records:
        for line in (out / "truth" / f"{r['id']}.jsonl").read_text(encoding="utf-8").splitlines():
            t = json.loads(line)
            cases[t["case"]] += 1
            box = t["box"] or [None] * 4
            foot = t["foot_px"] or [None, None]
            w.writerow(
                [
                    t["run"], t["frame"], t["image"], t["mask"], t["time"], t["case"],
                    t["case_name"], t["phi"], *t["position_robot"], *t["velocity_robot"],
                    math.degrees(t["heading_robot"]), t["speed"], t["robot"]["speed"],
                    t["time_to_collision"], int(t["collision"]), int(t["contact"]),
                    int(t["in_frame"]), int(t["occluded"]), t["visible_fraction"], *box, *foot,
                    t["case_now"], t["intent"], t["intent_time"],
                ]
            )  # fmt: skip
    return buf.getvalue(), cases


SWEEP_RUN_COLUMNS = ("family", "kind", "scale", "parameters", "seed")  # parameters: JSON


def _runs_csv(spec: DatasetSpec, records: list[dict[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    keys = SWEEP_RUN_COLUMNS
    w.writerow(("run", *keys, "frames", "annotated", "pose_found", "contact_time", "bytes"))
    for r in records:
        p = r["params"]
        cells = (json.dumps(p[k]) if isinstance(p[k], dict) else p[k] for k in keys)
        w.writerow(
            (r["id"], *cells, r["frames"], len(r["annotations"]), r["pose_found"],
             r["contact_time"], r["bytes"])
        )  # fmt: skip
    return buf.getvalue()


def _folder_bytes(out: Path) -> int:
    """The bytes of the folder's files (the MOT sequences' links to the images not again)."""
    return sum(p.stat().st_size for p in out.rglob("*") if p.is_file() and not p.is_symlink())
