"""Whom the robot's warning on one frame was for, by the truth: a person's name or nobody.

The pipeline names the person its robot warning is for only by its own track id
(FrameResult.person_id, the worst person's; with the one-pedestrian tracker its one
person). The truth knows who stood where: that track's box is paired with the people's
whole-body boxes (sim.geometry.box_match, one-to-one over all of the frame's tracks, so
two tracks never claim one person), giving the person's name and whether they were on a
collision course then. A track paired with nobody is a phantom: a brake on its warning is
a brake for nobody.

On a collision course means the truth's footprints meet if the robot keeps its course
(PersonTruth.time_to_collision, searched over the world's lookahead), not only within the
horizon (PersonTruth.collision): a warning may rightly lead the horizon (the Euro NCAP
FCW is timely at 1.7 s and more; the pipeline's own prediction reaches past where the
truth's horizon ends), and braking for the person the car would hit is braking for the
right person however early. The time to collision is kept, so a reader can hold a
warning to the horizon too. The closed loop names with it the person each run braked for, the
recordings the person each warning was for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from monopic.pipeline import FrameResult
from sim.geometry.box_match import match_tracks
from sim.world.ground_truth import GroundTruth

NOBODY = "nobody"  # a warning for a track that is no one (a phantom)


@dataclass(frozen=True)
class WarnedFor:
    """The person one warning was for: the track, the truth's name, on course then."""

    track: int | None  # the pipeline's person id (None: no track, the oracle's warning)
    name: str  # the truth's person (PersonTruth.name) or NOBODY
    ttc: float | None  # s until the footprints meet at constant speeds; None: they do not

    @property
    def on_course(self) -> bool:
        """That person was on a collision course (the footprints meet ahead)."""
        return self.ttc is not None

    @property
    def wrong(self) -> bool:
        """A warning for nobody, or for someone not on a collision course."""
        return self.name == NOBODY or not self.on_course

    def said(self) -> str:
        """'child (track 2, on a collision course)', 'nobody (track 4, a phantom)'."""
        track = f"track {self.track}, " if self.track is not None else ""
        if self.name == NOBODY:
            return f"{NOBODY} ({track}a phantom)"
        if self.ttc is None:
            course = "not on a collision course"
        elif math.isfinite(self.ttc):
            course = f"on a collision course, contact in {self.ttc:.2f} s"
        else:  # on course, the time not known
            course = "on a collision course"
        return f"{self.name} ({track}{course})"


def braked_wrong(name: str | None, on_course: bool | None) -> bool:
    """A brake named for nobody or for someone not on a collision course, as a run's
    outcome stores it (False when the run names no one: an older line, no brake)."""
    return name is not None and (name == NOBODY or on_course is False)


def warned_for(result: FrameResult, truth: GroundTruth) -> WarnedFor | None:
    """The person the robot warning of `result` was for (None when it names no track).

    Pairs every track of the frame with the people's boxes, so the answer is the one a
    judge of the whole frame would give the warned track."""
    if result.person_id is None:
        return None
    k = frame_pairs(result, truth).get(result.person_id)
    if k is None:
        return WarnedFor(result.person_id, NOBODY, None)
    person = truth.people[k]
    return WarnedFor(result.person_id, person.name, _ttc(person.time_to_collision))


def target_found(result: FrameResult | None, truth: GroundTruth) -> bool:
    """Whether one of the frame's tracks is the scripted person (the test's target), paired
    as the warnings are: the pipeline found the target this frame."""
    if result is None or not result.people:
        return False
    return 0 in frame_pairs(result, truth).values()


def frame_pairs(result: FrameResult, truth: GroundTruth) -> dict[int, int]:
    """{track id: person index}: every track of the frame paired with the people's boxes
    (sim.geometry.box_match, one to one)."""
    tracks = [[p.person_id, *p.box] for p in result.people]
    width, height = result.image_size
    return match_tracks(tracks, [p.box for p in truth.people], width, height)


def oracle_warned_for(truth: GroundTruth) -> WarnedFor:
    """The oracle policy's warning: the scripted person's truth (it warns on their course)."""
    return WarnedFor(None, truth.pedestrian.name, _ttc(truth.pedestrian.time_to_collision))


def _ttc(value: float | None) -> float | None:
    return None if value is None else round(float(value), 4)
