"""Person by person: the people tracker's warnings judged against every person's truth.

A line of a sweep whose pipeline follows everyone in view (`tracker` "everyone") says,
per predictor and frame, which track's warning was the robot's (TrackColumns.warned_for)
and every track's box. Each warned frame is for the person that track is paired with
that frame (sim.geometry.box_match.match_tracks: the track boxes against the people's
whole-body boxes, IoU 0.3, one-to-one), else for nobody: a phantom. A warning is then

- for a threat: that person is on a collision course within the horizon that frame;
- for the wrong person: that person is not (whether or not someone else is);
- a phantom: the track was paired with no one.

Per run (RunVerdict), as sim.analysis.metrics judges the scripted person:
- threatened: someone is on a collision course at some frame; the first threat is the
  person first on course (the line's `first_threat`); warned 1 s ahead when the first
  frame warned for that person while they are on course comes at least LEAD_GOAL before
  their contact (their earliest frame time plus time to collision);
- missed people: every person ever on course with no frame warned for them while on
  course before their contact.

Lines of the one-pedestrian tracker are judged by sim.analysis.people (the foot point),
not here: they have no tracks.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TypeVar

from sim.analysis.metrics import LEAD_GOAL, earliest_contact, split_method
from sim.geometry.box_match import match_tracks
from sim.runs.result import RunResult
from sim.runs.run_spec import EVERYONE


@dataclass(frozen=True)
class WarnedFrame:
    """One frame whose warning (for one predictor) was some track's."""

    k: int
    track: int
    person: int | None  # the index in the line's `people`; None: a phantom


@dataclass(frozen=True)
class RunVerdict:
    """One run judged person by person for one method."""

    id: str
    family: str
    method: str
    threatened: bool  # someone is on a collision course at some frame
    first_threat: int | None  # the person first on course (index in `people`)
    lead: float | None  # first threat's contact - first frame warned for them on course
    threat_people: tuple[int, ...]  # everyone ever on course
    missed: tuple[int, ...]  # of those, never warned for on course before their contact
    warned_frames: int
    for_threat_frames: int
    wrong_person_frames: int  # for someone not on course then and never after
    phantom_frames: int
    wrong_people: tuple[int, ...]  # people warned for while not on course, in order
    # For a person who is on course later, before their course starts (the horizon does
    # not reach their contact yet): an early warning for the threat, not the wrong person.
    early_frames: int = 0

    @property
    def warned_1s_for_threat(self) -> bool:
        return self.lead is not None and self.lead >= LEAD_GOAL - 1e-9

    @property
    def near_miss(self) -> bool:
        """Nobody is ever on a collision course."""
        return not self.threatened


def is_everyone(row: RunResult) -> bool:
    """A line of the people tracker (judged here)."""
    return row.tracker == EVERYONE


def warned_frames(row: RunResult, method: str) -> list[WarnedFrame] | None:
    """The frames `method` warned on and whom for; None when the line has no tracks for
    its pipeline or no column for its predictor (it cannot be judged so)."""
    pipeline, key = split_method(method)
    tracks = row.tracks.get(pipeline)
    whom = tracks.warned_for.get(key) if tracks is not None else None
    if tracks is None or whom is None:
        return None
    cam = row.scenario.camera
    out = []
    for k, track in enumerate(whom):
        if track is None:
            continue
        boxes = tracks.boxes[k] if k < len(tracks.boxes) else []
        people = [_at(p.box, k) for p in row.people]
        pairs = match_tracks(boxes, people, cam.width, cam.height)
        out.append(WarnedFrame(k, int(track), pairs.get(int(track))))
    return out


def judge_run(row: RunResult, method: str) -> RunVerdict | None:
    """`method`'s verdict on one people-tracker line (None: not such a line, or the
    method has no columns on it)."""
    if not is_everyone(row):
        return None
    warned = warned_frames(row, method)
    if warned is None:
        return None
    return judge_warned(row, method, warned)


def judge_warned(row: RunResult, method: str, warned: Sequence[WarnedFrame]) -> RunVerdict:
    """The verdict on a line's warned frames, however they were attributed (the people
    tracker's by its tracks; a one-pedestrian line's can be by its foot point,
    sim.analysis.people.warned_people, for a before-and-after on the same rules)."""
    times = row.truth.t
    people = row.people
    on_course = [[bool(_at(p.collision, k)) for k in range(len(times))] for p in people]
    threats = tuple(i for i, course in enumerate(on_course) if any(course))
    contacts = {i: earliest_contact(times, _padded(people[i].ttc, len(times))) for i in threats}
    first = _first_threat(row, on_course)
    for_threat = early = wrong = phantom = 0
    wrong_people: list[int] = []
    warned_on_course: dict[int, list[int]] = {i: [] for i in threats}
    course_from = {i: on_course[i].index(True) for i in threats}
    for w in warned:
        if w.person is None:
            phantom += 1
        elif on_course[w.person][w.k]:
            for_threat += 1
            warned_on_course[w.person].append(w.k)
        elif w.person in course_from and w.k < course_from[w.person]:
            early += 1  # for the threat before the horizon reaches their contact
        else:
            wrong += 1
            if w.person not in wrong_people:
                wrong_people.append(w.person)
    lead = None
    if first is not None and warned_on_course[first] and contacts[first] is not None:
        onset = times[warned_on_course[first][0]]
        lead = None if onset is None else float(contacts[first]) - float(onset)  # type: ignore[arg-type]
    missed = tuple(
        i for i in threats if not _warned_before(warned_on_course[i], times, contacts[i])
    )
    return RunVerdict(
        id=row.id,
        family=row.family,
        method=method,
        threatened=bool(threats),
        first_threat=first,
        lead=lead,
        threat_people=threats,
        missed=missed,
        warned_frames=len(warned),
        for_threat_frames=for_threat,
        early_frames=early,
        wrong_person_frames=wrong,
        phantom_frames=phantom,
        wrong_people=tuple(wrong_people),
    )


def judge_runs(row: RunResult, methods: Iterable[str]) -> dict[str, RunVerdict]:
    """Every method's verdict on one line (methods it cannot judge left out): the paired
    with/without-bystanders comparison and the list of runs to look at read this."""
    out = {}
    for method in methods:
        verdict = judge_run(row, method)
        if verdict is not None:
            out[method] = verdict
    return out


@dataclass(frozen=True)
class PersonByPersonSummary:
    """One method's verdicts over people-tracker runs."""

    runs: int
    threat_runs: int
    warned_1s: int  # threat runs warned LEAD_GOAL ahead for their first threat
    threat_people: int  # people ever on course, over the runs
    missed_people: int
    near_misses: int  # runs where nobody is ever on course
    near_misses_warned: int
    warned_frames: int
    for_threat: int
    wrong_person: int
    phantom: int
    runs_wrong_person: int  # runs with a wrong-person warning frame
    runs_phantom: int  # runs with a phantom warning frame
    early: int = 0  # warned frames for a threat before their course starts

    @property
    def recall_1s(self) -> float:
        return self.warned_1s / self.threat_runs if self.threat_runs else math.nan


def summarise(verdicts: Sequence[RunVerdict]) -> PersonByPersonSummary:
    """One method's verdicts counted."""
    return PersonByPersonSummary(
        runs=len(verdicts),
        threat_runs=sum(v.threatened for v in verdicts),
        warned_1s=sum(v.threatened and v.warned_1s_for_threat for v in verdicts),
        threat_people=sum(len(v.threat_people) for v in verdicts),
        missed_people=sum(len(v.missed) for v in verdicts),
        near_misses=sum(v.near_miss for v in verdicts),
        near_misses_warned=sum(v.near_miss and v.warned_frames > 0 for v in verdicts),
        warned_frames=sum(v.warned_frames for v in verdicts),
        for_threat=sum(v.for_threat_frames for v in verdicts),
        early=sum(v.early_frames for v in verdicts),
        wrong_person=sum(v.wrong_person_frames for v in verdicts),
        phantom=sum(v.phantom_frames for v in verdicts),
        runs_wrong_person=sum(v.wrong_person_frames > 0 for v in verdicts),
        runs_phantom=sum(v.phantom_frames > 0 for v in verdicts),
    )


def summarise_rows(rows: Sequence[RunResult], method: str) -> PersonByPersonSummary:
    """`method`'s verdicts over the people-tracker lines among `rows`."""
    verdicts = [judge_run(r, method) for r in rows]
    return summarise([v for v in verdicts if v is not None])


def _first_threat(row: RunResult, on_course: Sequence[Sequence[bool]]) -> int | None:
    """The line's `first_threat` as an index when that person is ever on course, else by
    the recorder's rule from the columns (the first frame anyone is on course, the first
    of them in the scenario's order); None when nobody is."""
    names = [p.name for p in row.people]
    if row.first_threat in names and any(on_course[names.index(row.first_threat)]):
        return names.index(row.first_threat)
    for k in range(len(row.truth.t)):
        for i, course in enumerate(on_course):
            if course[k]:
                return i
    return None


def _warned_before(
    frames: Sequence[int], times: Sequence[float | None], contact: float | None
) -> bool:
    """Whether any of `frames` (warned for the person on course) comes before contact."""
    if contact is None:
        return bool(frames)
    return any(times[k] is not None and float(times[k]) < contact for k in frames)  # type: ignore[arg-type]


T = TypeVar("T")


def _at(column: Sequence[T], k: int) -> T | None:
    """A column's frame k; None past its end (a column shorter than the run)."""
    return column[k] if k < len(column) else None


def _padded(column: Sequence[float | None], n: int) -> list[float | None]:
    return [*column[:n], *([None] * (n - len(column)))]
