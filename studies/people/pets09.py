"""Everyone followed on a real multi-person sequence: PETS09-S2L1 against its ground truth.

Three questions, each answered on the sequence's own frames and its MOTChallenge ground
truth (../shared/data/mot-pets09-s2l1, read where it lies, never copied):
1. the detector's recall per person: on every `--every`-th frame, the BlazePose detector
   run on the whole frame and on every tile of the tracker's cascade at once (more than the
   tracker's bounded search ever looks at in one frame): a ground-truth person is found
   when a detection's mid-hip keypoint lies in their box;
2. the tracks, scored with monopic.evaluation.mot (motmetrics): the people tracker with
   landmarks, beside the box-only baseline (the same detection and association fed the
   detector's boxes alone), each run writing its MOTChallenge tracks file;
3. spanning poses: accepted poses whose visible keypoints lie, at least SPAN_SHARE of them
   each, in two ground-truth boxes and in neither of the other's (one skeleton across two
   people).

    .venv/bin/python -m studies.people.pets09 --out recordings/pets09 [--frames 1-300]

Each run's tracks file and spanning count land in --out when the run is whole, so a rerun
skips what is done; the summary table is printed and written to --out/summary.md.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from monopic.errors import UserError
from monopic.evaluation.mot import (
    Box,
    FrameRange,
    MotRow,
    TrackScores,
    ground_truth_file,
    parse_frame_range,
    read_mot,
    read_mot_rows,
    score_tracks,
)
from monopic.frame import Frame
from monopic.framelog import mot_row
from monopic.image_sequence import ImageSequenceSource
from monopic.output import atomic_path
from monopic.people.box import ABOVE_HIPS, BELOW_HIPS, HEAD_TOP, SOLE
from monopic.people.tracker import PeopleConfig, PeopleTracker
from monopic.pose.detector import Detection, PoseDetector
from monopic.pose.landmarks import Pose
from monopic.pose.search import Window, search_windows
from monopic.pose.tracker import TrackerConfig
from monopic.pose.warp import WideFrame

# Real data is read where it is kept, never copied: $MONOPIC_SHARED_DATA, else
# ../shared/data beside the checkout.
ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = Path(os.environ.get("MONOPIC_SHARED_DATA") or ROOT.parent / "shared" / "data")
SEQUENCE = SHARED_DATA / "mot-pets09-s2l1"
SPAN_SHARE = 0.25
VISIBLE = 0.5

# Each run: its people settings and the detector windows a frame (the tracker's bounded
# search, or 0: the whole frame and every tile, every time it detects).
RUNS = {
    "landmarks": (PeopleConfig(), TrackerConfig.search_budget),
    # The baseline sees only the detector's boxes, so it detects every frame (the
    # landmark tracker fills the frames between detections with poses) ...
    "box-only": (PeopleConfig(landmarks=False, detect_every=1), TrackerConfig.search_budget),
    # ... and, at its best, with every tile every frame (about ten times the work).
    "box-only, every tile": (PeopleConfig(landmarks=False, detect_every=1), 0),
}
# A ceiling, not a tracker: the landmark tracker fed the ground truth's boxes in place of
# the detector's (CEILING_RUN below): what a detector that finds everyone would give.
CEILING_RUN = "landmarks, ground-truth detections (ceiling)"


@dataclass(frozen=True)
class Span:
    """One accepted pose over two ground-truth people."""

    frame: int
    person_id: int
    gt_ids: tuple[int, int]


def frames_of(sequence: Path, frames: FrameRange) -> Iterator[tuple[int, Frame]]:
    """The sequence's frames in `frames`, with their numbers as its ground truth counts."""
    source = ImageSequenceSource.from_folder(sequence, None)
    for frame in source:
        number = frame.index + source.first_number
        if number > frames.last:
            return
        if number in frames:
            yield number, frame


def spans(pose: Pose, truth: Sequence[tuple[int, object]]) -> list[tuple[int, int]]:
    """The pairs of ground-truth people this pose lies across (see SPAN_SHARE)."""
    visible = pose.visibility >= VISIBLE
    points = pose.landmarks[visible, :2] if visible.sum() >= 5 else pose.landmarks[:, :2]
    inside = np.array([[box.contains(x, y) for x, y in points] for _, box in truth])
    if inside.size == 0:
        return []
    pairs = []
    for a in range(len(truth)):
        for b in range(a + 1, len(truth)):
            only_a = (inside[a] & ~inside[b]).mean()
            only_b = (inside[b] & ~inside[a]).mean()
            if only_a >= SPAN_SHARE and only_b >= SPAN_SHARE:
                pairs.append((truth[a][0], truth[b][0]))
    return pairs


def follow(
    sequence: Path,
    frames: FrameRange,
    people: PeopleConfig,
    config: TrackerConfig,
    ceiling: bool = False,
) -> tuple[list[MotRow], list[Span]]:
    """Run the people tracker over the frames: its tracks and its spanning poses; with
    `ceiling`, its detector replaced by the ground truth's scored boxes."""
    truth = read_mot(ground_truth_file(sequence))
    tracker = PeopleTracker(config, people)
    if ceiling:
        scored = read_mot(ground_truth_file(sequence), scored_only=True)
        now = {"frame": 0}

        def detect(w: int, h: int, band: object) -> tuple[list[Detection], int]:
            return [_detection(box) for _, box in scored.get(now["frame"], [])], 1

        tracker._detect = detect  # type: ignore[method-assign]
    rows: list[MotRow] = []
    spanning: list[Span] = []
    for number, frame in frames_of(sequence, frames):
        if ceiling:
            now["frame"] = number
        result = tracker.process(frame.image, frame.timestamp)
        for s in result.sightings:
            x0, y0, x1, y1 = s.box
            rows.append(MotRow(number, s.person_id, Box(x0, y0, x1 - x0, y1 - y0), 1.0, None, 0))
            if s.pose is not None:
                for pair in spans(s.pose, truth.get(number, [])):
                    spanning.append(Span(number, s.person_id, pair))
    return rows, spanning


def _detection(box: Box) -> Detection:
    """The detection monopic.people.box.detection_box turns back into `box`: its mid-hip
    keypoint and full-body radius r (the box spans HEAD_TOP and SOLE beyond the
    landmarks, which run from ABOVE_HIPS r above the hips to BELOW_HIPS r below)."""
    span = ABOVE_HIPS + BELOW_HIPS
    r = box.height / (span * (1 + HEAD_TOP + SOLE))
    hx, hy = box.left + box.width / 2, box.top + HEAD_TOP * span * r + ABOVE_HIPS * r
    keypoints = np.array([[hx, hy], [hx, hy - r], [hx, hy - 0.5 * r], [hx, hy - r]])
    face = (hx - 0.1 * r, hy - r, hx + 0.1 * r, hy - 0.8 * r)
    return Detection(1.0, face, keypoints)


def detector_recall(
    sequence: Path, frames: FrameRange, every: int, config: TrackerConfig
) -> tuple[dict[int, tuple[int, int]], int]:
    """Per ground-truth person: (frames found, frames scored) on every `every`-th frame,
    with the detector run on the whole frame and on every tile of the cascade; and the
    number of windows a frame that took."""
    truth = read_mot(ground_truth_file(sequence), scored_only=True)
    detector = PoseDetector(
        config.threads, config.min_detection_score, config.runtime, config.detector
    )
    wide = WideFrame()
    counts: dict[int, list[int]] = {}
    windows: list[Window] = []
    for number, frame in frames_of(sequence, frames):
        if (number - frames.first) % every:
            continue
        h, w = frame.image.shape[:2]
        wide.start(frame.image)
        levels = search_windows(
            w, h, config.acquire_tiles, config.far_tiles, config.tile_overlap, None
        )
        windows = [Window(0, 0, w, h), *(win for level in levels for win in level)]
        hips = [d.keypoints[0] for d in detector.detect(wide.whole(), windows)]
        for gt_id, box in truth.get(number, []):
            seen = counts.setdefault(gt_id, [0, 0])
            seen[1] += 1
            seen[0] += any(box.contains(float(x), float(y)) for x, y in hips)
    recall = {gt_id: (found, n) for gt_id, (found, n) in sorted(counts.items())}
    return recall, len(windows)


def write_tracks(path: Path, rows: Sequence[MotRow]) -> None:
    """The tracks as `monopic video --tracks` writes them."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as handle:
        csv.writer(handle).writerows(
            mot_row(r.frame, r.identity, (r.box.left, r.box.top, r.box.left + r.box.width,
                                          r.box.top + r.box.height), r.conf)
            for r in rows
        )  # fmt: skip


def _row(name: str, scores: TrackScores, spanning: int) -> str:
    per_person = [i.recall for i in scores.identities]
    return (
        f"| {name} | {np.mean(per_person):.2f} | {scores.recall:.2f} | {scores.precision:.2f} "
        f"| {scores.mota:.2f} | {scores.idf1:.2f} | {scores.switches} | {spanning} |"
    )


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sequence", type=Path, default=SEQUENCE)
    parser.add_argument("--out", type=Path, required=True, help="folder for tracks and tables")
    parser.add_argument("--frames", type=parse_frame_range, default=FrameRange(1, 300))
    parser.add_argument("--every", type=int, default=10, help="detector recall's frame step")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args(argv)
    try:
        ground_truth_file(args.sequence)
    except UserError as err:
        parser.exit(2, f"{err}\n")
    args.out.mkdir(parents=True, exist_ok=True)
    config = TrackerConfig(threads=args.threads)
    truth = read_mot_rows(ground_truth_file(args.sequence))

    recall_file = args.out / "detector_recall.json"
    if not recall_file.exists():
        recall, windows = detector_recall(args.sequence, args.frames, args.every, config)
        with atomic_path(recall_file) as tmp:
            tmp.write_text(json.dumps({"windows": windows, "people": recall}))
    saved = json.loads(recall_file.read_text())
    recall = {int(k): v for k, v in saved["people"].items()}
    lines = [
        f"PETS09-S2L1 frames {args.frames}. Detector alone ({saved['windows']} windows: the "
        f"whole frame and every tile, every {args.every}th frame): per-person recall "
        f"{np.mean([f / n for f, n in recall.values()]):.2f} (mean over "
        f"{len(recall)} people), boxes found {sum(f for f, _ in recall.values())}/"
        f"{sum(n for _, n in recall.values())}.",
        "",
        "| run | recall per person (mean) | recall | precision | MOTA | IDF1 | ID switches "
        "| spanning poses |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for name, (people, search_budget) in RUNS.items():
        stem = name.replace(", ", "-").replace(" ", "-")
        tracks, done = args.out / f"{stem}.txt", args.out / f"{stem}.spans.json"
        if not done.exists():
            searched = replace(config, search_budget=search_budget)
            rows, spanning = follow(args.sequence, args.frames, people, searched)
            write_tracks(tracks, rows)
            with atomic_path(done) as tmp:
                tmp.write_text(json.dumps([[s.frame, s.person_id, *s.gt_ids] for s in spanning]))
        scores = score_tracks(read_mot_rows(tracks), truth, args.frames)
        lines.append(_row(name, scores, len(json.loads(done.read_text()))))
    tracks, done = args.out / "ceiling.txt", args.out / "ceiling.spans.json"
    if not done.exists():
        rows, spanning = follow(args.sequence, args.frames, PeopleConfig(), config, ceiling=True)
        write_tracks(tracks, rows)
        with atomic_path(done) as tmp:
            tmp.write_text(json.dumps([[s.frame, s.person_id, *s.gt_ids] for s in spanning]))
    scores = score_tracks(read_mot_rows(tracks), truth, args.frames)
    lines.append(_row(CEILING_RUN, scores, len(json.loads(done.read_text()))))
    text = "\n".join(lines) + "\n"
    with atomic_path(args.out / "summary.md") as tmp:
        tmp.write_text(text)
    print(text, end="")


if __name__ == "__main__":
    main()
