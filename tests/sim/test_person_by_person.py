"""Person by person: the people tracker's warnings judged against the person each warned
track is paired with, its tracking scored as track-eval scores it, and both in the report."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from sim.analysis.metrics import compute
from sim.analysis.person_by_person import judge_run, judge_runs, summarise_rows, warned_frames
from sim.analysis.person_report import person_by_person_lines
from sim.analysis.report import people_lines, write_report
from sim.analysis.tracking import INSTALL, sequence, tracking_by_family, truth_rows
from sim.runs.result import PersonColumns, RunResult, TrackColumns
from sim.runs.run_spec import EVERYONE
from tests.sim.test_metrics import row as metrics_row

pytest.importorskip("motmetrics", reason="tracking quality needs the [tracking] extra")

N = 22  # frames of 0.1 s; the child's contact is at 2.2 s, the end of the run
CHILD_BOX = [100.0, 80.0, 130.0, 160.0]
ADULT_BOX = [200.0, 40.0, 250.0, 170.0]
NOBODY_BOX = [10.0, 10.0, 30.0, 60.0]  # a track on no one (a phantom)
CHILD, ADULT, GHOST = 1, 2, 3  # track ids


def person(name: str, box: list[float], course_from: int | None, contact: float | None):
    """A person standing still in the image, on a collision course from frame
    `course_from` (None: never) with contact at `contact` s."""
    on = [int(course_from is not None and k >= course_from) for k in range(N)]
    ttc = [None if contact is None else round(contact - 0.1 * k, 4) for k in range(N)]
    return PersonColumns(name=name, scripted=name == "child", collision=on, contact=[0] * N,
                         ttc=ttc, box=[list(box)] * N, in_frame=[1] * N)  # fmt: skip


def line(
    whom: dict[int, int],
    run_id: str = "fam/0",
    people: list[PersonColumns] | None = None,
    boxes: list[list[list[float]]] | None = None,
) -> RunResult:
    """A people-tracker line: the child on course from frame 5 (contact 2.2 s), the adult
    never; rules/image warned for track whom[k] at frame k."""
    people = people or [person("child", CHILD_BOX, 5, 2.2), person("adult", ADULT_BOX, None, None)]
    warned = [whom.get(k) for k in range(N)]
    ttc = [round(2.2 - 0.1 * k, 4) for k in range(N)]
    row = metrics_row(run_id, ttc, [int(w is not None) for w in warned], horizon=1.7)
    frames = boxes or [[[CHILD, *CHILD_BOX], [ADULT, *ADULT_BOX], [GHOST, *NOBODY_BOX]]] * N
    tracks = TrackColumns(boxes=frames, warned_for={"rules/image": warned})  # type: ignore[dict-item]
    return replace(row, people=people, first_threat="child", tracker=EVERYONE,
                   tracks={"main": tracks})  # fmt: skip


def frames(track: int, ks: range | list[int]) -> dict[int, int]:
    return dict.fromkeys(ks, track)


def test_a_warning_for_the_threat_1_2_s_ahead_is_recalled() -> None:
    v = judge_run(line(frames(CHILD, range(10, N))), "rules/image")
    assert v is not None and v.threatened and v.first_threat == 0
    assert v.lead == pytest.approx(1.2) and v.warned_1s_for_threat
    assert (v.for_threat_frames, v.wrong_person_frames, v.phantom_frames) == (12, 0, 0)
    assert v.missed == () and v.threat_people == (0,)


def test_a_warning_only_for_the_bystander_is_for_the_wrong_person_and_misses_the_threat() -> None:
    row = line(frames(ADULT, range(10, N)))
    assert [w.person for w in warned_frames(row, "rules/image") or []] == [1] * 12
    v = judge_run(row, "rules/image")
    assert v is not None and v.threatened and v.lead is None and not v.warned_1s_for_threat
    assert (v.for_threat_frames, v.wrong_person_frames, v.wrong_people) == (0, 12, (1,))
    assert v.missed == (0,)


def test_a_track_on_nobody_is_a_phantom_and_a_warning_before_the_course_is_early() -> None:
    # Frames 3-4: for the child before they are on course (early); 8-9 a phantom; from
    # 11 (1.1 s) for the child on course: 1.1 s before contact.
    row = line({3: CHILD, 4: CHILD, 8: GHOST, 9: GHOST, **frames(CHILD, range(11, N))})
    v = judge_run(row, "rules/image")
    assert v is not None
    assert (v.for_threat_frames, v.early_frames, v.wrong_person_frames) == (11, 2, 0)
    assert v.phantom_frames == 2 and v.wrong_people == ()
    assert v.lead == pytest.approx(1.1) and v.warned_1s_for_threat
    late = judge_run(line(frames(CHILD, range(15, N))), "rules/image")
    assert late is not None and late.lead == pytest.approx(0.7) and not late.warned_1s_for_threat
    assert late.missed == ()  # warned, though late


def test_missed_people_are_counted_people_not_runs_and_near_misses_apart() -> None:
    both = [person("child", CHILD_BOX, 5, 2.2), person("adult", ADULT_BOX, 8, 3.0)]
    row = line(frames(CHILD, range(10, N)), "fam/1", people=both)
    nobody = [person("child", CHILD_BOX, None, None), person("adult", ADULT_BOX, None, None)]
    near = replace(line(frames(ADULT, [4]), "fam/2", people=nobody), first_threat=None)
    v = judge_runs(row, ["rules/image", "rules/ground"])
    assert set(v) == {"rules/image"}  # no column for rules/ground: not judged
    assert v["rules/image"].missed == (1,)
    s = summarise_rows([row, near, line(frames(CHILD, range(10, N)))], "rules/image")
    assert (s.runs, s.threat_runs, s.warned_1s) == (3, 2, 2)
    assert (s.threat_people, s.missed_people) == (3, 1)
    assert (s.near_misses, s.near_misses_warned, s.runs_wrong_person) == (1, 1, 1)


def test_one_tracker_lines_are_left_to_the_foot_point_judge() -> None:
    row = replace(line(frames(CHILD, range(10, N))), tracker="", tracks={})
    assert judge_run(row, "rules/image") is None
    assert summarise_rows([row], "rules/image").runs == 0
    assert people_lines([row], ["rules/image"])[0] == "## Several people: whose warning"
    assert person_by_person_lines([row], ["rules/image"]) == []


def test_perfect_tracks_score_mota_and_idf1_1_and_a_swap_counts_switches() -> None:
    perfect = line({})
    boxes = [[[CHILD, *CHILD_BOX], [ADULT, *ADULT_BOX]]] * N
    perfect = replace(perfect, tracks={"main": TrackColumns(boxes=boxes)})
    s = tracking_by_family([perfect])["fam"]  # type: ignore[index]
    assert (s.mota, s.idf1, s.switches, s.gt_boxes) == (1.0, 1.0, 0, 2 * N)
    swapped = [[[ADULT if t == CHILD else CHILD, *b] for t, *b in f] if k >= 11 else f
               for k, f in enumerate(boxes)]  # fmt: skip
    swap = replace(perfect, id="fam/1", tracks={"main": TrackColumns(boxes=swapped)})
    s = tracking_by_family([swap])["fam"]  # type: ignore[index]
    assert s.switches == 2  # each person's track changes once
    assert s.mota == pytest.approx(1 - 2 / (2 * N)) and s.idf1 < 1.0
    assert s.switches_per_100 == pytest.approx(100 * 2 / (2 * N))
    both = tracking_by_family([perfect, swap])["fam"]  # type: ignore[index]
    assert (both.sequences, both.gt_boxes, both.switches) == (2, 4 * N, 2)


def test_the_truth_is_the_datasets_in_view_boxes_clipped_to_the_image() -> None:
    child = person("child", [-20.0, 80.0, 30.0, 200.0], 5, 2.2)  # off the left and bottom
    adult = replace(person("adult", ADULT_BOX, None, None), in_frame=[0] * 10 + [1] * (N - 10))
    row = line({}, people=[child, adult])
    truth = truth_rows(row)
    assert len(truth) == N + (N - 10)
    first = truth[0]
    assert (first.frame, first.identity, tuple(first.box)) == (1, 1, (0.0, 80.0, 30.0, 100.0))
    assert min(r.frame for r in truth if r.identity == 2) == 11
    assert sequence(row).frames.last == N


def test_without_motmetrics_the_report_says_how_to_install_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr("sim.analysis.tracking.has_motmetrics", lambda: False)
    row = line(frames(CHILD, range(10, N)))
    assert tracking_by_family([row]) is None
    assert any(INSTALL in x for x in person_by_person_lines([row], ["rules/image"]))


def test_the_report_judges_people_tracker_lines_person_by_person(tmp_path: Path) -> None:
    rows = [
        line(frames(CHILD, range(10, N)), "fam/ok"),
        line(frames(ADULT, range(10, N)), "fam/bystander"),
        line({8: GHOST, 9: GHOST, **frames(CHILD, range(10, N))}, "fam/ghost"),
    ]
    lines = person_by_person_lines(rows, ["rules/image"])
    assert lines[0] == "## Several people: person by person"
    judged, tracked = ([c.strip() for c in x.strip("|").split("|")]
                       for x in lines if x.startswith("| fam "))  # fmt: skip
    assert judged == ["fam", "rules/image", "3", "2/3", "1/3", "-", "24 / 0 / 12 / 2", "1", "1"]
    # Every frame the ghost track is a false positive beside two perfect tracks: MOTA
    # 1 - 22/44 per run, IDF1 2 * 44 / (44 + 66).
    assert tracked == ["fam", "3", "132", "50 %", "80 %", "0.00 (0)", "100 %", "67 %"]
    assert people_lines(rows, ["rules/image"]) == []  # the foot-point section is not theirs
    out = tmp_path / "report"
    write_report(compute(rows), rows, tmp_path / "results.jsonl", out)
    text = (out / "report.md").read_text()
    assert text.count("## Several people: person by person") == 1
    triage = text.split("## Runs to look at", 1)[1].split("\n## ", 1)[0]
    assert "**warned for adult who was not on a collision course (12 frames)**" in triage
    assert "`fam/ghost` (the file's values): **warned for nobody (a phantom) (2 frames)**" in triage
    assert "`fam/ok`" not in triage


@pytest.mark.slow
def test_a_real_people_tracker_run_is_judged_and_scored(tmp_path: Path) -> None:
    from sim.runs.runner import run
    from sim.runs.sweep import expand_spec, load_spec
    from tests.sim.test_people_tracker_runs import spec_file

    (spec,) = expand_spec(load_spec(spec_file(tmp_path, 'tracker = "everyone"')))
    row = RunResult.from_json(run(spec).to_json())  # as the report reads it back
    child = [p.name for p in row.people].index("child")
    verdicts = judge_runs(row, row.pipelines["main"].decisions)
    assert set(verdicts) == set(row.tracks["main"].warned_for)
    for key, v in verdicts.items():
        warned = sum(w is not None for w in row.tracks["main"].warned_for[key])
        assert v.warned_frames == warned
        said = v.for_threat_frames + v.early_frames + v.wrong_person_frames + v.phantom_frames
        assert said == warned
        assert v.threatened and v.first_threat == child  # the child steps out
    # Somebody's warning is for the child on course: the pairing finds them.
    assert any(v.for_threat_frames for v in verdicts.values())
    s = tracking_by_family([row])[row.family]  # type: ignore[index]
    in_view = sum(sum(p.in_frame) for p in row.people)
    assert s.gt_boxes == in_view and s.gt_identities == len(row.people)
    assert 0.0 < s.idf1 <= 1.0 and s.mota <= 1.0 and s.matches > 0
