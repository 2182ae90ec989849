"""Everyone followed on real footage: the PETS09-S2L1 sequence against its ground truth
(tracks file -> track-eval, poses across two people counted), and the street clip (no
track jumps across the frame). At a size CI allows; the whole sequence is the study's
(studies/people/pets09.py, docs/people/pets09.md)."""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import pytest

from monopic.cli.main import main
from monopic.evaluation.mot import FrameRange, read_mot_rows
from monopic.people.tracker import PeopleConfig
from monopic.pose.tracker import TrackerConfig
from studies.people.pets09 import follow
from tests.paths import PETS09, STREET_CLIP, needs_pets09, needs_street_clip

pytestmark = pytest.mark.slow


@needs_pets09
def test_pets09_tracks_file_scores_with_track_eval(tmp_path: Path, capsys) -> None:
    """`monopic video` on the MOTChallenge folder writes tracks numbered as its ground
    truth, which `monopic track-eval` scores: people found and kept under one identity."""
    # The first 30 frames (4 s at 7 fps), through the command a tracking user runs.
    frames = tmp_path / "img"
    frames.mkdir()
    for k in range(1, 31):
        (frames / f"{k:06d}.jpg").symlink_to(PETS09 / "img1" / f"{k:06d}.jpg")
    tracks, scores = tmp_path / "tracks.txt", tmp_path / "scores.json"
    pattern = str(frames / "%06d.jpg")
    assert main(["video", pattern, "--fps", "7", "--tracks", str(tracks)]) == 0
    rows = read_mot_rows(tracks)
    assert {r.frame for r in rows} <= set(range(1, 31)) and len({r.identity for r in rows}) >= 3
    assert main(["track-eval", str(tracks), "--gt", str(PETS09), "--frames", "1-30",
                 "--json", str(scores)]) == 0  # fmt: skip
    s = json.loads(scores.read_text())["metrics"]
    # Measured MOTA 0.50, IDF1 0.68, 1 switch on these frames (docs/people/pets09.md has
    # the whole sequence); a tracker that loses people or swaps them falls well below.
    assert s["mota"] > 0.3 and s["idf1"] > 0.5 and s["switches"] <= 2, s


@needs_pets09
@pytest.mark.xfail(
    strict=True,
    reason="measured: a few poses in frames 141-166 lie across two people walking side by "
    "side or crossing (docs/people/pets09.md): a goal not yet met",
)
def test_no_pose_on_pets09_spans_two_people() -> None:
    """A pose whose visible keypoints lie, a quarter each, in two ground-truth boxes and
    not in the other's is one skeleton across two people."""
    _, spanning = follow(PETS09, FrameRange(135, 170), PeopleConfig(), TrackerConfig())
    assert spanning == []


@needs_street_clip
def test_street_clip_tracks_never_jump_across_the_frame(tmp_path: Path) -> None:
    """On the real street clip (1-6 people, groups, shadows) a track moves at most 0.15 of
    the frame width between consecutive frames: it follows one person, never hops."""
    tracks = tmp_path / "street.txt"
    clip = tmp_path / "street.mp4"
    import cv2

    capture = cv2.VideoCapture(str(STREET_CLIP))
    fps = capture.get(cv2.CAP_PROP_FPS)
    width = int(capture.get(cv2.CAP_PROP_FRAME_WIDTH))
    height = int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT))
    writer = cv2.VideoWriter(str(clip), cv2.VideoWriter_fourcc(*"mp4v"), fps, (width, height))
    for k in range(400):  # 280-400: 5 s with 4-6 people, groups crossing
        ok, image = capture.read()
        assert ok
        if k >= 280:
            writer.write(image)
    writer.release()
    assert main(["video", str(clip), "--tracks", str(tracks)]) == 0
    centres: dict[int, dict[int, float]] = defaultdict(dict)
    for r in read_mot_rows(tracks):
        centres[r.identity][r.frame] = r.box.left + r.box.width / 2
    jumps = [
        abs(track[f] - track[f - 1]) / width
        for track in centres.values()
        for f in track
        if f - 1 in track
    ]
    assert len(centres) >= 4 and jumps and max(jumps) <= 0.15
