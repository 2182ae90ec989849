"""Whose warning: a run's warnings set against every person's truth, in runs with several.

Today's simulated runs give the pipeline one pedestrian to follow (the one-pedestrian
tracker); with several people in the street it may follow the wrong one. A warning frame
is attributed to the person the pipeline was looking at: the person whose whole-body box
holds the pipeline's foot point (the smallest such box: the nearest person stands in front),
else the person whose box's bottom centre is nearest to it. A warning is then

- for a threat: that person is on a collision course within the horizon;
- for the wrong person: that person is not, whether or not someone else is;
- unattributed: the pipeline had no foot point that frame (it warned from memory).

Runs with one person have no per-person columns; their warnings are the scripted
person's by construction and are not counted here. Lines of the people tracker (`tracker`
"everyone") name the track each warning was for: the report judges them by that track
(sim.analysis.person_by_person), not by the foot point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from sim.analysis.metrics import LEAD_GOAL, earliest_contact, split_method
from sim.runs.result import PersonColumns, RunResult


@dataclass(frozen=True)
class PeopleSummary:
    """One method's warnings over runs with several people."""

    runs: int
    threat_runs: int  # runs where someone is on a collision course at some frame
    warned_1s: int  # of those, runs warned LEAD_GOAL s or more before the first threat's contact
    near_misses: int  # runs where nobody is ever on a collision course
    near_misses_warned: int
    warned_frames: int
    for_threat: int  # warned frames attributed to a person on a collision course
    wrong_person: int  # warned frames attributed to a person who is not
    unattributed: int
    runs_wrong_person: int  # runs with at least one wrong-person warning frame

    @property
    def wrong_share(self) -> float:
        said = self.for_threat + self.wrong_person
        return self.wrong_person / said if said else math.nan


def person_at(people: Sequence[PersonColumns], k: int, foot: Sequence[float | None]) -> int | None:
    """Index of the person the foot point (u, v) at frame k belongs to (module docstring)."""
    if foot is None or any(v is None for v in foot):
        return None
    u, v = float(foot[0]), float(foot[1])  # type: ignore[arg-type]
    holding, nearest, best = [], None, math.inf
    for i, p in enumerate(people):
        box = p.box[k] if k < len(p.box) else None
        if box is None or any(b is None for b in box):
            continue
        u0, v0, u1, v1 = (float(b) for b in box)  # type: ignore[arg-type]
        if u0 <= u <= u1 and v0 <= v <= v1:
            holding.append(((u1 - u0) * (v1 - v0), i))
        d = math.hypot(u - (u0 + u1) / 2, v - v1)
        if d < best:
            nearest, best = i, d
    return min(holding)[1] if holding else nearest


def warned_people(row: RunResult, method: str) -> list[int | None]:
    """Per frame: the index of the person a warning was for (None: no warning or no foot)."""
    pipeline, key = split_method(method)
    columns = row.pipelines.get(pipeline)
    decisions = columns.decisions.get(key) if columns else None
    if decisions is None or columns is None:
        return [None] * len(row.truth.t)
    out: list[int | None] = []
    for k, warn in enumerate(decisions.warn):
        foot = columns.foot[k] if k < len(columns.foot) else None
        out.append(person_at(row.people, k, foot) if warn else None)  # type: ignore[arg-type]
    return out


def summarise_people(rows: Sequence[RunResult], method: str) -> PeopleSummary:
    """`method`'s warnings over the runs with several people among `rows`."""
    runs = [r for r in rows if r.people]
    threat_runs = warned_1s = near = near_warned = 0
    warned = for_threat = wrong = unattributed = runs_wrong = 0
    for row in runs:
        pipeline, key = split_method(method)
        columns = row.pipelines.get(pipeline)
        decisions = columns.decisions.get(key) if columns else None
        warn = [bool(w) for w in decisions.warn] if decisions else []
        whose = warned_people(row, method)
        threats = [any(p.collision[k] for p in row.people) for k in range(len(row.truth.t))]
        if any(threats):
            threat_runs += 1
            first = next(k for k, t in enumerate(threats) if t)
            contact = _first_contact(row)
            onset = next((row.truth.t[k] for k in range(first, len(warn)) if warn[k]), None)
            if onset is not None and contact is not None and contact - onset >= LEAD_GOAL - 1e-9:
                warned_1s += 1
        else:
            near += 1
            near_warned += int(any(warn))
        wrong_here = 0
        for k, w in enumerate(warn):
            if not w:
                continue
            warned += 1
            i = whose[k]
            if i is None:
                unattributed += 1
            elif row.people[i].collision[k]:
                for_threat += 1
            else:
                wrong_here += 1
        wrong += wrong_here
        runs_wrong += int(wrong_here > 0)
    return PeopleSummary(len(runs), threat_runs, warned_1s, near, near_warned, warned,
                         for_threat, wrong, unattributed, runs_wrong)  # fmt: skip


def _first_contact(row: RunResult) -> float | None:
    """When the first threat's footprint meets the robot's, by the truth (as
    sim.analysis.metrics.contact_time says it for the scripted person): the earliest frame
    time plus time to collision over the people who are ever on a collision course."""
    ends = [earliest_contact(row.truth.t, p.ttc) for p in row.people if any(p.collision)]
    found = [t for t in ends if t is not None]
    return min(found) if found else None
