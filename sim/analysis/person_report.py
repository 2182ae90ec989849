"""The sweep report's section "Several people: person by person": the people tracker's
warnings judged against each person (sim.analysis.person_by_person) and how well it
followed them (sim.analysis.tracking), per family. Nothing for lines of the one-pedestrian
tracker (their section is "Several people: whose warning")."""

from __future__ import annotations

from collections.abc import Sequence

from sim.analysis.markdown import num, pct, table
from sim.analysis.metrics import LEAD_GOAL
from sim.analysis.person_by_person import is_everyone, judge_run, summarise
from sim.analysis.tracking import INSTALL, tracking_by_family
from sim.geometry.box_match import MATCH_IOU
from sim.runs.result import MAIN, RunResult


def _runs(n: int) -> str:
    return f"{n} run" if n == 1 else f"{n} runs"


def person_by_person_lines(rows: Sequence[RunResult], methods: Sequence[str]) -> list[str]:
    """The section's lines; [] when no line is the people tracker's."""
    everyone = [r for r in rows if is_everyone(r)]
    if not everyone:
        return []
    body = []
    for family in sorted({r.family for r in everyone}):
        mine = [r for r in everyone if r.family == family]
        for method in methods:
            verdicts = [v for v in (judge_run(r, method) for r in mine) if v is not None]
            if not verdicts:
                continue
            s = summarise(verdicts)
            said = s.for_threat + s.early + s.wrong_person + s.phantom
            body.append([
                family, method, str(s.runs),
                f"{s.warned_1s}/{s.threat_runs}" if s.threat_runs else "-",
                f"{s.missed_people}/{s.threat_people}" if s.threat_people else "-",
                f"{s.near_misses_warned}/{s.near_misses}" if s.near_misses else "-",
                f"{s.for_threat} / {s.early} / {s.wrong_person} / {s.phantom}" if said else "-",
                str(s.runs_wrong_person), str(s.runs_phantom),
            ])  # fmt: skip
    return [
        "## Several people: person by person",
        "",
        f"{_runs(len(everyone))} whose pipeline follows everyone in view (the people tracker).",
        "Each warned frame is for the person its track is paired with that frame (the track's",
        f"box against each person's whole-body box, IoU >= {MATCH_IOU:g}, one to one;",
        "sim/analysis/person_by_person.py), else for nobody (a phantom). Warned "
        f"{LEAD_GOAL:g} s ahead:",
        "runs where someone is on a collision course whose first frame warned for the first",
        f"person on course, while on course, is at least {LEAD_GOAL:g} s before that person's "
        "contact.",
        "Missed people: people ever on a collision course never warned for while on course",
        "before their contact (people, not runs). Warned frames: for a person on course / for",
        "a person on course later, before their course starts (early) / for a person on course",
        "neither then nor later (the wrong person) / for nobody.",
        "",
        *table(
            [
                "family",
                "method",
                "runs",
                f"warned {LEAD_GOAL:g} s ahead for the threat",
                "missed people",
                "near misses warned",
                "warned frames: threat / early / wrong / phantom",
                "runs with a wrong-person warning",
                "runs with a phantom",
            ],
            body,
        ),  # fmt: skip
        "",
        *_tracking_lines(everyone),
    ]


def _tracking_lines(rows: Sequence[RunResult]) -> list[str]:
    """Per family, the tracker's figures: the main pipeline's tracks (the robot's)."""
    scores = tracking_by_family(rows, MAIN)
    head = [
        "Tracking quality per family, as `monopic track-eval` scores a MOTChallenge sequence",
        "(motmetrics; a match needs IoU >= 0.5): each run's tracks against the dataset's ground",
        "truth for it (sim/dataset/mot.py: every person in the image, the whole body's box",
        "clipped to the image, occluded people included), the runs of a family summed.",
        "Switches per 100 person-frames (ground-truth boxes). HOTA is not given: motmetrics",
        "1.4 has none.",
        "",
    ]
    if scores is None:
        return [*head, f"Not scored: motmetrics is not installed ({INSTALL}).", ""]
    body = [
        [
            family,
            str(s.sequences),
            str(s.gt_boxes),
            pct(s.mota),
            pct(s.idf1),
            f"{num(s.switches_per_100)} ({s.switches})",
            pct(s.recall),
            pct(s.precision),
        ]
        for family, s in scores.items()
    ]
    columns = ["family", "runs", "person-frames", "MOTA", "IDF1", "switches / 100 (all)"]
    return [*head, *table([*columns, "recall", "precision"], body), ""]
