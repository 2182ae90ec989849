"""How well the people tracker followed everyone: MOTA, IDF1 and identity switches per
family, scored as `monopic track-eval` scores a MOTChallenge sequence.

Each people-tracker line is one sequence. Its ground truth is what the dataset writes in
gt/gt.txt for the run (sim.dataset.mot): one box per person per frame where the person is
in the image, the whole body's box clipped to the image, ids 1 for the scripted person
then 2, 3, ... in the scenario's order, every box scored whatever its visibility (as
MOT17 scores occluded people: a person hidden behind another is a miss unless followed).
Its tracks are the line's track boxes as the tracker gave them. Frames count from 1.
monopic.evaluation.mot scores them (motmetrics, CLEAR MOT's IoU 0.5), the runs of a
family together (motmetrics' overall: counts summed). HOTA is not computed: motmetrics
1.4 has none (monopic.evaluation.mot says why).
"""

from __future__ import annotations

from collections.abc import Sequence

from monopic.evaluation.mot import (
    PEDESTRIAN,
    Box,
    FrameRange,
    MotRow,
    MotSequence,
    PooledScores,
    has_motmetrics,
    score_sequences,
)
from sim.analysis.person_by_person import is_everyone
from sim.geometry.box_match import clipped_box
from sim.runs.result import MAIN, RunResult

INSTALL = "install .[tracking]"  # what the report says when motmetrics is absent


def truth_rows(row: RunResult) -> list[MotRow]:
    """The run's MOTChallenge ground truth (module docstring), as the dataset writes it."""
    cam = row.scenario.camera
    out = []
    for i, person in enumerate(row.people):
        for k, box in enumerate(person.box):
            seen = k < len(person.in_frame) and person.in_frame[k]
            if not seen or box is None or any(v is None for v in box):
                continue
            clipped = clipped_box(tuple(float(v) for v in box), cam.width, cam.height)  # type: ignore[arg-type]
            if clipped is not None:
                out.append(MotRow(k + 1, i + 1, Box(*clipped), 1.0, PEDESTRIAN, 0))
    return out


def track_rows(row: RunResult, pipeline: str = MAIN) -> list[MotRow]:
    """The pipeline's track boxes as MOTChallenge result rows (as `monopic video --tracks`
    writes them: not clipped)."""
    tracks = row.tracks.get(pipeline)
    out = []
    for k, frame in enumerate(tracks.boxes if tracks else []):
        for track, u0, v0, u1, v1 in frame:
            out.append(MotRow(k + 1, int(track), Box(u0, v0, u1 - u0, v1 - v0), 1.0, None, 0))
    return out


def sequence(row: RunResult, pipeline: str = MAIN) -> MotSequence:
    """One line as a sequence to score: every frame the run processed."""
    return MotSequence(
        track_rows(row, pipeline),
        truth_rows(row),
        FrameRange(1, max(row.frames, len(row.truth.t), 1)),
    )


def tracking_by_family(
    rows: Sequence[RunResult], pipeline: str = MAIN
) -> dict[str, PooledScores] | None:
    """Per family (name order), the tracker's figures over its people-tracker lines that
    hold `pipeline`'s tracks; None when motmetrics is not installed (say INSTALL)."""
    lines = [r for r in rows if is_everyone(r) and pipeline in r.tracks]
    if not lines:
        return {}
    if not has_motmetrics():
        return None
    out = {}
    for family in sorted({r.family for r in lines}):
        out[family] = score_sequences([sequence(r, pipeline) for r in lines if r.family == family])
    return out
