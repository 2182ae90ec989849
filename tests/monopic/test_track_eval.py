"""`monopic track-eval`: tracks scored against MOTChallenge ground truth, on files whose
answer is known by hand, on motmetrics' own published example, on the real PETS09 ground
truth, and its refusals."""

from __future__ import annotations

import json
import math
from pathlib import Path

import motmetrics
import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from monopic.evaluation.mot import (
    Box,
    FrameRange,
    evaluate_files,
    parse_frame_range,
    read_mot,
    read_mot_rows,
)
from tests.paths import PETS09 as PETS
from tests.paths import needs_pets09 as needs_pets

# Three people walking right, 40 px apart, in frames 1-10: (frame, id, left, top, w, h).
PEOPLE = [
    (f, pid, 10.0 * f + 40 * pid, 100.0, 20.0, 50.0) for f in range(1, 11) for pid in (1, 2, 3)
]


def write_mot(path: Path, rows, conf: float = 1.0, extra: str = ",-1,-1,-1") -> Path:
    """MOTChallenge lines, results style (`conf,-1,-1,-1`) unless `extra` says otherwise."""
    lines = [f"{f},{i},{x:g},{y:g},{w:g},{h:g},{conf:g}{extra}" for f, i, x, y, w, h in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def score(tmp_path: Path, tracks, truth=PEOPLE, **kwargs):
    return evaluate_files(
        write_mot(tmp_path / "tracks.txt", tracks), write_mot(tmp_path / "gt.txt", truth), **kwargs
    )


def test_a_perfect_copy_scores_one_everywhere(tmp_path):
    s = score(tmp_path, [(f, 100 + i, x, y, w, h) for f, i, x, y, w, h in PEOPLE])
    assert (s.mota, s.motp, s.idf1, s.idp, s.idr, s.recall, s.precision) == (1, 1, 1, 1, 1, 1, 1)
    assert (s.switches, s.fragmentations, s.false_positives, s.misses) == (0, 0, 0, 0)
    assert (s.gt_boxes, s.track_boxes, s.matches, s.gt_identities) == (30, 30, 30, 3)
    assert (s.mostly_tracked, s.partially_tracked, s.mostly_lost) == (3, 0, 0)
    assert [(i.gt_id, i.frames, i.matched, i.track_ids) for i in s.identities] == [
        (1, 10, 10, (101,)), (2, 10, 10, (102,)), (3, 10, 10, (103,))
    ]  # fmt: skip


def test_two_ids_swapped_half_way_are_two_switches_and_half_the_identity_score(tmp_path):
    """People 1 and 2 are followed by tracks 10 and 20, which trade people at frame 6:
    each person switches once (MOTA = 1 - 2/30); the best one-to-one identity mapping
    keeps 5 of the 10 frames of persons 1 and 2 (IDF1 = (5 + 5 + 10) / 30)."""
    swapped = {1: 20, 2: 10}
    tracks = [
        (f, (swapped.get(i, 30) if f >= 6 else {1: 10, 2: 20}.get(i, 30)), x, y, w, h)
        for f, i, x, y, w, h in PEOPLE
    ]
    s = score(tmp_path, tracks)
    assert s.switches == 2 and s.fragmentations == 0
    assert s.mota == pytest.approx(1 - 2 / 30)
    assert s.idf1 == pytest.approx(20 / 30)
    assert s.recall == 1 and s.false_positives == 0
    assert {i.gt_id: i.track_ids for i in s.identities} == {1: (10, 20), 2: (10, 20), 3: (30,)}
    # Before the swap nothing is wrong: --frames scores a part of the sequence.
    before = score(tmp_path, tracks, frames=FrameRange(1, 5))
    assert (before.mota, before.idf1, before.switches, before.gt_boxes) == (1, 1, 0, 15)


def test_a_missing_person_lowers_recall_by_their_share(tmp_path):
    s = score(tmp_path, [r for r in PEOPLE if r[1] != 3])
    assert s.recall == pytest.approx(2 / 3) and s.misses == 10
    assert s.mota == pytest.approx(2 / 3) and s.precision == 1
    assert s.idr == pytest.approx(2 / 3) and s.idf1 == pytest.approx(0.8)
    assert (s.mostly_tracked, s.mostly_lost) == (2, 1)
    missing = next(i for i in s.identities if i.gt_id == 3)
    assert (missing.frames, missing.matched, missing.recall, missing.track_ids) == (10, 0, 0, ())


def test_a_gap_in_a_track_is_a_fragmentation(tmp_path):
    tracks = [r for r in PEOPLE if not (r[1] == 1 and r[0] in (4, 5))]
    s = score(tmp_path, tracks)
    assert (s.fragmentations, s.switches, s.misses) == (1, 0, 2)
    assert next(i for i in s.identities if i.gt_id == 1).matched == 8


def test_the_iou_threshold_decides_a_match(tmp_path):
    """A box 8 px to the right of a 20x50 one overlaps it by 12/28 of the union... times
    the height: IoU = (12 * 50) / (28 * 50) = 0.4286: a miss and a false positive at 0.5,
    a match (MOTP = that IoU) at 0.4."""
    truth = [(1, 1, 0.0, 0.0, 20.0, 50.0)]
    tracks = [(1, 7, 8.0, 0.0, 20.0, 50.0)]
    strict = score(tmp_path, tracks, truth)
    assert (strict.matches, strict.misses, strict.false_positives) == (0, 1, 1)
    loose = score(tmp_path, tracks, truth, min_iou=0.4)
    assert (loose.matches, loose.misses, loose.false_positives) == (1, 0, 0)
    assert loose.motp == pytest.approx(12 / 28)


def test_unscored_ground_truth_is_no_miss_and_a_track_on_it_a_counted_false_positive(tmp_path):
    """conf 0 rows (MOTChallenge: not to be scored) are not misses; as in the official
    2D MOT 2015 evaluation, a track box on one is a false positive, and it is counted
    apart so a reader can tell it from a box on nobody."""
    tracks = write_mot(tmp_path / "tracks.txt", [r for r in PEOPLE if r[1] != 3])
    gt = tmp_path / "gt.txt"
    gt.write_text(
        write_mot(tmp_path / "a.txt", [r for r in PEOPLE if r[1] != 3]).read_text()
        + write_mot(tmp_path / "b.txt", [r for r in PEOPLE if r[1] == 3], conf=0).read_text()
    )
    s = evaluate_files(tracks, gt)
    assert (s.mota, s.recall, s.misses, s.gt_identities) == (1, 1, 0, 2)
    s = evaluate_files(write_mot(tmp_path / "all.txt", PEOPLE), gt)
    assert (s.false_positives, s.false_positives_on_unscored, s.misses) == (10, 10, 0)
    assert s.mota == pytest.approx(1 - 10 / 20)


def test_mot16_classes_score_pedestrians_and_take_out_boxes_on_distractors(tmp_path):
    """Nine fields (conf, class, visibility): person 1 a pedestrian (class 1), person 2 a
    static person (7, a distractor), person 3 a car (3). Track boxes on all three: the one
    on the static person is taken out, the one on the car is a false positive."""
    classes = {1: 1, 2: 7, 3: 3}
    gt = tmp_path / "gt.txt"
    gt.write_text(
        "".join(
            f"{f},{i},{x:g},{y:g},{w:g},{h:g},1,{classes[i]},1\n" for f, i, x, y, w, h in PEOPLE
        )
    )
    s = evaluate_files(write_mot(tmp_path / "tracks.txt", PEOPLE), gt)
    assert (s.gt_identities, s.gt_boxes, s.matches) == (1, 10, 10)
    assert (s.distractor_boxes, s.track_boxes, s.false_positives) == (10, 20, 10)
    assert s.mota == 0 and s.recall == 1
    assert read_mot(gt, scored_only=True) == {
        f: [(1, Box(10.0 * f + 40, 100.0, 20.0, 50.0))] for f in range(1, 11)
    }


def test_motmetrics_own_example_gives_its_published_figures(tmp_path):
    """TUD-Campus as shipped in motmetrics, read by our reader and fed through our IoU
    wiring, gives the figures motmetrics' own test expects (its test_motchallenge_files);
    its MOTP there is a distance, ours the MOTChallenge overlap (1 - distance)."""
    data = Path(motmetrics.__file__).parent / "data" / "TUD-Campus"
    s = evaluate_files(data / "test.txt", data / "gt.txt")
    got = (s.idf1, s.idp, s.idr, s.recall, s.precision, s.mota, 1 - s.motp)
    expected = (0.557659, 0.729730, 0.451253, 0.582173, 0.941441, 0.526462, 0.277201)
    assert got == pytest.approx(expected, abs=1e-6)
    assert (s.gt_identities, s.mostly_tracked, s.partially_tracked, s.mostly_lost) == (8, 1, 6, 1)
    assert (s.false_positives, s.misses, s.switches, s.fragmentations) == (13, 150, 7, 7)


@needs_pets
def test_pets09_ground_truth_scored_against_itself(tmp_path):
    """The real PETS09-S2L1 boxes as tracks: the scored rows give a perfect score; the
    whole file, unscored people too, gives their 174 boxes as false positives on them."""
    lines = (PETS / "gt" / "gt.txt").read_text().splitlines()
    scored = tmp_path / "scored.txt"
    scored.write_text("\n".join(line for line in lines if line.split(",")[6] != "0"))
    s = evaluate_files(scored, PETS, frames=FrameRange(1, 300))
    assert (s.mota, s.idf1, s.switches, s.gt_identities, s.gt_boxes) == (1, 1, 0, 10, 1700)
    assert all(i.recall == 1 and len(i.track_ids) == 1 for i in s.identities)
    whole = evaluate_files(PETS / "gt" / "gt.txt", PETS)
    assert (whole.false_positives, whole.false_positives_on_unscored, whole.misses) == (174, 174, 0)
    people = read_mot(PETS / "gt" / "gt.txt")
    assert len(people) == 300 and sum(map(len, people.values())) == len(lines)


def test_read_mot_and_box_contains(tmp_path):
    path = write_mot(tmp_path / "t.txt", [(2, 5, 10, 20, 30, 40), (1, 4, 0, 0, 1, 1)])
    assert read_mot(path) == {1: [(4, Box(0, 0, 1, 1))], 2: [(5, Box(10, 20, 30, 40))]}
    box = Box(10, 20, 30, 40)
    assert box.contains(10, 20) and box.contains(40, 60) and not box.contains(40.5, 30)
    # Six fields are enough (conf is then 1); whitespace-separated lines are read too.
    short = tmp_path / "short.txt"
    short.write_text("3 1 0 0 4 4\n\n3,2,5,5,4,4\n")
    assert [(r.frame, r.identity, r.conf) for r in read_mot_rows(short)] == [(3, 1, 1), (3, 2, 1)]


def test_json_holds_every_figure(tmp_path, capsys):
    tracks = write_mot(tmp_path / "tracks.txt", [r for r in PEOPLE if r[1] != 3])
    gt = write_mot(tmp_path / "gt.txt", PEOPLE)
    out = tmp_path / "new" / "scores.json"
    assert main(["track-eval", str(tracks), "--gt", str(gt), "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "MOTA 0.667" in printed and "IDF1 0.800" in printed
    document = json.loads(out.read_text())
    assert document["frames"] == [1, 10] and document["hota"] is None
    assert document["metrics"]["misses"] == 10 and document["metrics"]["mota"] == pytest.approx(
        2 / 3
    )
    assert document["identities"][2] == {
        "gt_id": 3, "frames": 10, "matched": 0, "recall": 0.0, "track_ids": []
    }  # fmt: skip
    assert [p.name for p in out.parent.iterdir()] == ["scores.json"]


def test_a_sequence_folder_is_read_as_its_gt_file(tmp_path):
    (tmp_path / "seq" / "gt").mkdir(parents=True)
    write_mot(tmp_path / "seq" / "gt" / "gt.txt", PEOPLE)
    s = evaluate_files(write_mot(tmp_path / "tracks.txt", PEOPLE), tmp_path / "seq")
    assert s.mota == 1


def run_refused(capsys, *argv: str) -> str:
    """The one stderr line of a refused `monopic track-eval`, whichever layer refuses it
    (the argument parser exits, a UserError returns 2)."""
    try:
        code = main(["track-eval", *argv])
    except SystemExit as stop:
        code = stop.code
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1, err
    return err.strip()


@pytest.mark.parametrize(
    ("line", "says"),
    [
        ("1,1,0,0,10", "gt.txt:2: 5 field(s), expected at least 6"),
        ("x,1,0,0,10,10,1,-1,-1,-1", "gt.txt:2: frame 'x' is not an integer >= 1"),
        ("0,1,0,0,10,10,1,-1,-1,-1", "gt.txt:2: frame '0' is not an integer >= 1"),
        ("1.5,1,0,0,10,10,1,-1,-1,-1", "gt.txt:2: frame '1.5' is not an integer >= 1"),
        ("1,-1,0,0,10,10,1,-1,-1,-1", "gt.txt:2: id '-1' is not an integer >= 0"),
        ("1,2,nan,0,10,10,1,-1,-1,-1", "gt.txt:2: bb_left 'nan' is not a finite number"),
        ("1,2,0,0,abc,10,1,-1,-1,-1", "gt.txt:2: bb_width 'abc' is not a finite number >= 0"),
        ("1,2,0,0,10,-3,1,-1,-1,-1", "gt.txt:2: bb_height '-3' is not a finite number >= 0"),
        ("1,2,0,0,10,10,high,-1,-1,-1", "gt.txt:2: conf 'high' is not a finite number"),
        ("1,2,0,0,10,10,1,car,1", "gt.txt:2: class 'car' is not an integer >= -1"),
        ("1,1,5,5,10,10,1,-1,-1,-1", "gt.txt:2: id 1 twice in frame 1 (lines 1 and 2)"),
    ],
)
def test_a_malformed_line_is_named_by_file_line_and_field(tmp_path, capsys, line, says):
    good = write_mot(tmp_path / "good.txt", PEOPLE)
    for name in ("gt.txt", "tracks.txt"):
        bad = tmp_path / name
        bad.write_text("1,1,0,0,10,10,1,-1,-1,-1\n" + line + "\n")
        argv = (str(good), "--gt", str(bad)) if name == "gt.txt" else (str(bad), "--gt", str(good))
        assert says.replace("gt.txt", name) in run_refused(capsys, *argv)


@pytest.mark.parametrize("bad", ["5", "3-1", "0-4", "a-b", "1-", "-2", "1-2-3"])
def test_a_malformed_frame_range_is_refused(tmp_path, capsys, bad):
    tracks = write_mot(tmp_path / "tracks.txt", PEOPLE)
    err = run_refused(capsys, str(tracks), "--gt", str(tracks), f"--frames={bad}")
    assert "--frames" in err and repr(bad) in err
    with pytest.raises(ValueError):
        parse_frame_range(bad)


@pytest.mark.parametrize("bad", ["0", "1.5", "-0.2", "nan", "half"])
def test_an_iou_outside_zero_to_one_is_refused(tmp_path, capsys, bad):
    tracks = write_mot(tmp_path / "tracks.txt", PEOPLE)
    assert "--iou" in run_refused(capsys, str(tracks), "--gt", str(tracks), f"--iou={bad}")


def test_missing_files_and_nothing_to_score_are_refused(tmp_path, capsys):
    tracks = write_mot(tmp_path / "tracks.txt", PEOPLE)
    gt = write_mot(tmp_path / "gt.txt", PEOPLE)
    out = tmp_path / "out" / "s.json"
    cases = [
        ((str(tmp_path / "none.txt"), "--gt", str(gt)), "none.txt: no such file"),
        ((str(tracks), "--gt", str(tmp_path / "nogt")), "--gt " + str(tmp_path / "nogt")),
        ((str(tracks), "--gt", str(tmp_path)), "a folder without gt/gt.txt"),
        ((str(tmp_path), "--gt", str(gt)), "is a folder, not a MOTChallenge text file"),
        ((str(tracks), "--gt", str(gt), "--frames", "20-30"),
         "tracks.txt: no track line in frames 20-30"),
    ]  # fmt: skip
    for argv, says in cases:
        assert says in run_refused(capsys, *argv, "--json", str(out)), argv
    empty = tmp_path / "empty.txt"
    empty.write_text("\n")
    assert "empty.txt: no track line" in run_refused(capsys, str(empty), "--gt", str(gt))
    unscored = write_mot(tmp_path / "unscored.txt", PEOPLE, conf=0)
    assert "no scored ground-truth line in frames 1-10" in run_refused(
        capsys, str(tracks), "--gt", str(unscored)
    )
    assert not out.parent.exists()  # a refusal leaves no output behind
    with pytest.raises(UserError):
        evaluate_files(empty, gt)
    assert math.isfinite(evaluate_files(tracks, gt).mota)
