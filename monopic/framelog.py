"""Per-frame CSV rows: the authors' log columns, then ours.

The authors' columns (../shared/data/authors-testdata/README.md) let their analysis and our replay
read our runs; ours add the case, foot and ground points and per-stage milliseconds.
"""

from __future__ import annotations

import math

from monopic.pipeline import FrameResult
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
)  # fmt: skip
FRAME_COLUMNS = AUTHORS_COLUMNS + OUR_COLUMNS


def frame_row(r: FrameResult, fps: float, horizon: float) -> list:
    """One CSV row for a frame whose pedestrian was found (features present)."""
    f, p, w = r.features, r.prediction, r.warning
    pose = r.pose.pose
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
    ]  # fmt: skip


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
