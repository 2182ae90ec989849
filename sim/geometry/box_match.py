"""Which simulated person a pipeline's track is, in one frame: one-to-one by box overlap.

The judge of the people tracker (sim.analysis.people) and the closed loop's "braked for"
need the same answer: the track's box against each person's true whole-body box, clipped
to the image as the MOTChallenge files of datasets are (sim.dataset.mot), paired by
scipy's linear_sum_assignment on their overlap. A pair needs an IoU of 0.3, not CLEAR
MOT's 0.5 (which tracking quality keeps, as `monopic track-eval` scores): the tracker's
box has a pedestrian's usual aspect (monopic.people.box), the truth's spans the limbs, and
near the camera a striding person's box is wider than that aspect; on a child stepping
out beside an adult, 59 of 71 track boxes paired at 0.5, 66 at 0.3 and at 0.2 alike. A
track paired with nobody is a phantom: a warning for it is for no one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.optimize import linear_sum_assignment

from monopic.pose.detector import iou

MATCH_IOU = 0.3

Box = Sequence[float | None]  # u0, v0, u1, v1 in pixels (None entries: no box)


def clipped(box: Box | None, width: int, height: int) -> tuple[float, float, float, float] | None:
    """The box clipped to the image; None when it is missing, not finite or outside it."""
    if box is None or len(box) != 4 or any(v is None for v in box):
        return None
    u0, v0, u1, v1 = (float(v) for v in box)  # type: ignore[arg-type]
    if not all(np.isfinite((u0, v0, u1, v1))):
        return None
    u0, u1 = max(u0, 0.0), min(u1, float(width))
    v0, v1 = max(v0, 0.0), min(v1, float(height))
    return (u0, v0, u1, v1) if u1 > u0 and v1 > v0 else None


def clipped_box(
    box: tuple[float, float, float, float], width: int, height: int
) -> list[float] | None:
    """[left, top, width, height] of an (u0, v0, u1, v1) box clipped to the image, to 0.01
    px, as the dataset's MOTChallenge gt.txt writes it (sim.dataset.mot) and the sweep
    report scores tracking against it; None when the box is not finite (a box wholly
    outside the image comes out empty: whether the person is in view is the caller's)."""
    u0, v0, u1, v1 = box
    if not all(math.isfinite(v) for v in (u0, v0, u1, v1)):
        return None
    x0, y0 = min(max(u0, 0.0), width), min(max(v0, 0.0), height)
    x1, y1 = min(max(u1, 0.0), width), min(max(v1, 0.0), height)
    return [round(x0, 2), round(y0, 2), round(x1 - x0, 2), round(y1 - y0, 2)]


def match_tracks(
    tracks: Sequence[Sequence[float | None]],
    people: Sequence[Box | None],
    width: int,
    height: int,
    min_iou: float = MATCH_IOU,
) -> dict[int, int]:
    """{track id: person index} for one frame.

    `tracks` are [id, u0, v0, u1, v1] rows (sim.runs.result.TrackColumns.boxes), `people`
    each person's whole-body box (None where they have none this frame)."""
    track_boxes = [(int(t[0]), clipped(t[1:5], width, height)) for t in tracks]  # type: ignore[arg-type]
    track_boxes = [(tid, b) for tid, b in track_boxes if b is not None]
    person_boxes = [(i, clipped(b, width, height)) for i, b in enumerate(people)]
    person_boxes = [(i, b) for i, b in person_boxes if b is not None]
    if not track_boxes or not person_boxes:
        return {}
    overlap = np.array([[iou(t, p) for _, p in person_boxes] for _, t in track_boxes])
    rows, cols = linear_sum_assignment(-overlap)
    return {
        track_boxes[r][0]: person_boxes[c][0]
        for r, c in zip(rows, cols, strict=True)
        if overlap[r, c] >= min_iou
    }
