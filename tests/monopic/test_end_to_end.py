"""The real pipeline on the shipped rendered clip: pose found, shoulders near the truth,
and `monopic video` writes a video, a CSV and a recording rerun can read back."""

import csv
import subprocess
import sys

import cv2
import numpy as np
import pytest

from monopic.pipeline import Pipeline
from monopic.replay.logs import read_log
from monopic.video import VideoSource
from tests.paths import DATA
from tests.rrd import column, rows_per_entity

CLIP = DATA / "walk_clip.mp4"
TRUTH = DATA / "walk_clip_truth.csv"

pytestmark = pytest.mark.slow


def _truth() -> dict[int, dict[str, float]]:
    with TRUTH.open() as fh:
        return {int(r["frame"]): {k: float(v) for k, v in r.items()} for r in csv.DictReader(fh)}


def test_person_found_and_shoulders_within_a_few_pixels():
    truth = _truth()
    pipeline = Pipeline()
    found, errors = 0, []
    for frame in VideoSource(str(CLIP)):
        result = pipeline.process(frame)
        if result.pose.pose is None:
            continue
        found += 1
        lm = result.pose.pose.landmarks
        t = truth[frame.index]
        for idx in (11, 12):  # BlazePose left/right shoulder, the person's own sides
            errors.append(np.hypot(lm[idx, 0] - t[f"lm{idx}_u"], lm[idx, 1] - t[f"lm{idx}_v"]))
    assert found >= 0.9 * len(truth)
    # The mannequin spans ~230 px; its shoulders' truth is the joint centre, BlazePose's the
    # shoulder's surface point: a few pixels apart by definition.
    assert np.median(errors) < 6.0, np.median(errors)
    assert np.percentile(errors, 90) < 15.0


def test_video_command_writes_video_csv_and_recording(tmp_path):
    out, table, rrd = tmp_path / "a.mp4", tmp_path / "f.csv", tmp_path / "r.rrd"
    r = subprocess.run(
        [sys.executable, "-m", "monopic", "video", str(CLIP), "--variant", "path",
         "--out", str(out), "--csv", str(table), "--rrd", str(rrd)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mp4", "f.csv", "r.rrd"]

    cap = cv2.VideoCapture(str(out))
    n_video = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
    ok, first = cap.read()
    assert ok and first.shape == (432, 768, 3) and n_video == 60

    rows = list(csv.DictReader(table.open()))
    assert len(rows) >= 54
    assert {"frameNumber", "angleOfApproach", "predictedX", "case", "totalMs"} <= set(rows[0])
    assert len(read_log(table)) == len(rows)  # the authors' reader takes every row
    moving = [r for r in rows if r["case"] not in ("", "9")]
    # The mannequin walks from the camera's left to its right.
    assert sum(r["case"] == "5" for r in moving) >= 0.8 * len(moving)

    counts = rows_per_entity(rrd)
    assert counts["/camera/image"] == 60
    assert counts["/camera/pose"] == 60  # keypoints or an explicit clear, every frame
    assert counts["/features/phi"] >= 54
    frames = column(rrd, "/latency/total", "frame")
    assert frames == sorted(frames) and len(frames) == 60
    positions = column(rrd, "/camera/pose", "Points2D:positions")
    assert len(positions[0]) == 33
    xs = [p[0] for p in positions[0]]
    assert min(xs) >= 0 and max(xs) <= 768
