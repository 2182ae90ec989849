"""Per-frame CSV rows, one per person seen: the authors' log columns, then ours.

The authors' columns (../shared/data/authors-testdata/README.md) let their analysis and our replay
read our runs; ours add the case, foot and ground points, per-stage milliseconds (the
frame's, on each of its rows), and who the row is about: `personId` and their box.
"""

from __future__ import annotations

import math

from monopic.pipeline import FrameResult, PersonResult
from monopic.pose.skeleton import LEFT_SHOULDER, RIGHT_SHOULDER
from monopic.predict.rules import IMAGE_DEAD_ZONE_PX_S

# The authors' log columns (their README), then ours.
AUTHORS_COLUMNS = (
    "frameNumber", "windowSize", "XYError", "timeToFuture", "time", "fps",
    "currentCenterX", "currentCenterY", "leftShoulderX", "leftShoulderY",
    "rightShoulderX", "rightShoulderY", "angleOfApproach", "XFrameSpeed", "YFrameSpeed",
    "occupiedHeights", "predictedX", "predictedY",
)  # fmt: skip
OUR_COLUMNS = (
    "case", "caseName", "phiRaw", "footX", "footY", "predictedFootX", "predictedFootY",
    "apparentHeight", "poseScore", "collision", "risk", "groundX", "groundY", "groundVx",
    "groundVy", "predictedGroundX", "predictedGroundY", "detectorRuns", "detectMs",
    "landmarksMs", "featuresMs", "predictMs", "warningMs", "totalMs",
    # Intent features (docs/intent/features.md), empty where not known.
    "phiRate", "headYaw", "headVisibility", "groundSpeed", "groundAcceleration",
    "groundHeadingRate", "pathOffset", "pathDistance", "headFacing", "headToward",
    # Who: an identity kept while they are followed, and their box (pixels).
    "personId", "boxLeft", "boxTop", "boxWidth", "boxHeight",
)  # fmt: skip
FRAME_COLUMNS = AUTHORS_COLUMNS + OUR_COLUMNS


def frame_rows(r: FrameResult, fps: float, horizon: float) -> list[list]:
    """The frame's rows: one per person whose landmarks were run and read this frame."""
    return [frame_row(r, fps, horizon, p) for p in r.people if p.features is not None]


def frame_row(
    r: FrameResult, fps: float, horizon: float, person: PersonResult | None = None
) -> list:
    """One CSV row for a person found with features: `person`, or the frame's own (the
    person whose warning is the robot's)."""
    if person is None:
        person = next(p for p in r.people if p.person_id == r.person_id)
    f, p, w = person.features, person.prediction, person.warning
    pose = person.pose
    assert f is not None and pose is not None, "rows are for people with features"
    ls, rs = pose.landmarks[LEFT_SHOULDER], pose.landmarks[RIGHT_SHOULDER]
    g = f.ground
    pg = p.ground if p is not None else None
    ms = r.stage_ms
    nan = float("nan")
    return [
        r.frame_index, 4, IMAGE_DEAD_ZONE_PX_S, horizon, f"{r.timestamp:.6f}", f"{fps:.3f}",
        f"{f.center[0]:.2f}", f"{f.center[1]:.2f}", f"{ls[0]:.2f}", f"{ls[1]:.2f}",
        f"{rs[0]:.2f}", f"{rs[1]:.2f}", f"{f.phi:.4f}", f"{f.vx:.4f}", f"{f.vy:.4f}",
        f"{f.apparent_height / r.image_size[1]:.5f}",
        f"{p.center[0]:.2f}" if p else "", f"{p.center[1]:.2f}" if p else "",
        int(p.case) if p else "", p.case.label if p else "", f"{f.phi_raw:.4f}",
        f"{f.foot[0]:.2f}", f"{f.foot[1]:.2f}",
        f"{p.foot[0]:.2f}" if p else "", f"{p.foot[1]:.2f}" if p else "",
        f"{f.apparent_height:.2f}", f"{pose.score:.4f}",
        int(w.collision) if w else "", w.risk.value if w else "",
        f"{g.position[0]:.3f}" if g else "", f"{g.position[1]:.3f}" if g else "",
        f"{g.velocity[0]:.3f}" if g else "", f"{g.velocity[1]:.3f}" if g else "",
        f"{pg[0]:.3f}" if pg else "", f"{pg[1]:.3f}" if pg else "",
        r.pose.detector_runs, f"{ms.get('detect', nan):.3f}", f"{ms.get('landmarks', nan):.3f}",
        f"{ms.get('features', nan):.3f}", f"{ms.get('predict', nan):.3f}",
        f"{ms.get('warning', nan):.3f}", f"{ms.get('total', nan):.3f}",
        _cell(f.phi_rate, 2), _cell(f.head_yaw, 2), _cell(f.head_visibility, 3),
        _cell(g.speed if g else nan, 3), _cell(g.acceleration if g else nan, 3),
        _cell(g.heading_rate if g else nan, 2), _cell(g.path_offset if g else nan, 3),
        _cell(g.path_distance if g else nan, 3), _cell(f.head_facing, 2),
        _cell(f.head_toward, 2),
        person.person_id, *(f"{v:.2f}" for v in _left_top_size(person.box)),
    ]  # fmt: skip


def _left_top_size(box: tuple[float, float, float, float]) -> tuple[float, ...]:
    x0, y0, x1, y1 = box
    return x0, y0, x1 - x0, y1 - y0


def _cell(value: float, digits: int) -> str:
    """A number with `digits` decimals; empty when not known (NaN)."""
    return f"{value:.{digits}f}" if math.isfinite(value) else ""


def authors_finite(row: list) -> bool:
    """Whether a row's authors' columns are all finite numbers, as their log reader demands.

    Not so on a track's first frame (no velocity yet): logs leave such rows out.
    """
    try:
        return all(math.isfinite(float(v)) for v in row[: len(AUTHORS_COLUMNS)])
    except ValueError:
        return False


def mot_rows(r: FrameResult, frame_number: int) -> list[list]:
    """The frame's lines of a MOTChallenge results file, one per person in view."""
    return [
        mot_row(frame_number, p.person_id, p.box, p.pose.score if p.pose is not None else 1.0)
        for p in r.people
    ]


def mot_row(
    frame_number: int, person_id: int, box: tuple[float, float, float, float], conf: float
) -> list:
    """One line of a MOTChallenge results file: frame, id, bb_left, bb_top, bb_width,
    bb_height, conf, x, y, z (the world position unknown: -1)."""
    return [
        frame_number, person_id, *(f"{v:.2f}" for v in _left_top_size(box)), f"{conf:.3f}",
        -1, -1, -1,
    ]  # fmt: skip
