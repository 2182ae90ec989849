"""Annotated frames like the paper's demo figures, drawn with OpenCV.

Top-left: frame rate, latency (ms) and phi, as in the paper. Skeleton with the shoulders
highlighted, the robot's zone, the predicted point and path, the case, and the risk.
With several people in view each is drawn in their own colour (by identity,
monopic.people.colour): box, skeleton, "id N" with their case, and their predicted
point; the zone takes the robot's warning (the worst person's), and the banner names that person.
"""

from __future__ import annotations

import cv2
import numpy as np

from monopic.people.colour import person_colour
from monopic.pipeline import FrameResult, PersonResult, Variant
from monopic.pose.landmarks import Pose
from monopic.pose.skeleton import CONNECTIONS, LEFT_SHOULDER, RIGHT_SHOULDER
from monopic.variants.warning import Risk

# BGR is OpenCV's order, but our frames are RGB: colours below are RGB.
RISK_COLOURS = {Risk.GREEN: (40, 200, 60), Risk.YELLOW: (240, 200, 0), Risk.RED: (230, 30, 30)}
SKELETON = (80, 220, 255)
SHOULDERS = (255, 60, 200)
PREDICTION = (255, 255, 255)
OUTLINE_PX = 2  # width of the dark edge around text


def _pt(p) -> tuple[int, int]:
    return int(round(float(p[0]))), int(round(float(p[1])))


def _finite(p) -> bool:
    return bool(np.all(np.isfinite(np.asarray(p, dtype=float))))


def draw(image: np.ndarray, result: FrameResult, variant: Variant, fps: float) -> np.ndarray:
    """A copy of the RGB frame with the pipeline's outputs drawn on it."""
    out = image.copy()
    scale = max(out.shape[0] / 432, 0.5)
    thick = max(1, int(round(2 * scale)))
    w = result.warning
    if w is not None and variant in (Variant.WARNING, Variant.PATH):
        colour = RISK_COLOURS[w.risk]
        zone = np.round(w.zone).astype(np.int32)
        overlay = out.copy()
        cv2.fillPoly(overlay, [zone], colour)
        out = cv2.addWeighted(overlay, 0.18, out, 0.82, 0)
        cv2.polylines(out, [zone], True, colour, thick, cv2.LINE_AA)
    if len(result.people) > 1:
        for person in result.people:
            _person(out, person, scale, thick)
        _text(out, f"{fps:5.1f}  {result.stage_ms.get('total', 0.0):5.1f} ms", (8, 22))
        if w is not None and w.collision and variant is Variant.WARNING:
            banner = f"COLLISION IMMINENT: id {result.person_id}"
            _text(out, banner, (8, int(50 * scale)), RISK_COLOURS[Risk.RED], 1.0)
        return out
    pose = result.pose.pose
    if pose is not None:
        _skeleton(out, pose, SKELETON, thick, 3 * thick)
        lm = pose.landmarks
        cv2.line(out, _pt(lm[LEFT_SHOULDER]), _pt(lm[RIGHT_SHOULDER]), SHOULDERS, thick)
    f, p = result.features, result.prediction
    if f is not None and p is not None and _finite(p.center):
        if variant is Variant.PATH and result.path is not None:
            path = result.path.image_path[np.all(np.isfinite(result.path.image_path), axis=1)]
            cv2.polylines(out, [np.round(path).astype(np.int32)], False, PREDICTION, thick)
            if result.path.conflict is not None:
                cv2.drawMarker(
                    out, _pt(result.path.conflict), RISK_COLOURS[Risk.RED],
                    cv2.MARKER_TILTED_CROSS, int(18 * scale), thick + 1,
                )  # fmt: skip
        else:
            cv2.arrowedLine(
                out, _pt(f.center), _pt(p.center), PREDICTION, thick, cv2.LINE_AA, tipLength=0.2
            )
        cv2.circle(out, _pt(p.center), 5 * thick, PREDICTION, thick, cv2.LINE_AA)
        label = f"case {int(p.case)}: {p.case.label}"
        _text(out, label, (_pt(f.center)[0] - 60, max(int(40 * scale), _pt(f.center)[1] - 10)))
    phi = f.phi if f is not None else float("nan")
    _text(out, f"{fps:5.1f}  {result.stage_ms.get('total', 0.0):5.1f} ms  {phi:6.1f}", (8, 22))
    if w is not None and w.collision and variant is Variant.WARNING:
        _text(out, "COLLISION IMMINENT", (8, int(50 * scale)), RISK_COLOURS[Risk.RED], 1.0)
    return out


def _person(out: np.ndarray, person: PersonResult, scale: float, thick: int) -> None:
    """One of several people, in their own colour: box, skeleton, id and case, prediction."""
    colour = person_colour(person.person_id)
    x0, y0, x1, y1 = person.box
    if not _finite(person.box):
        return
    cv2.rectangle(out, _pt((x0, y0)), _pt((x1, y1)), colour, max(1, thick // 2), cv2.LINE_AA)
    if person.pose is not None:
        _skeleton(out, person.pose, colour, thick, 2 * thick)
    label = f"id {person.person_id}"
    p = person.prediction
    if p is not None and _finite(p.center):
        label += f" case {int(p.case)}"
        centre = ((x0 + x1) / 2, (y0 + y1) / 2)
        cv2.arrowedLine(out, _pt(centre), _pt(p.center), colour, thick, cv2.LINE_AA, tipLength=0.2)
        cv2.circle(out, _pt(p.center), 4 * thick, colour, thick, cv2.LINE_AA)
    _text(out, label, (_pt((x0, y0))[0], max(int(16 * scale), _pt((x0, y0))[1] - 4)), colour, 0.45)


def _skeleton(out: np.ndarray, pose: Pose, colour, thick: int, shoulder_radius: int) -> None:
    """The pose's visible bones in `colour`, its shoulders marked (phi is read from them)."""
    lm = pose.landmarks
    for a, b in CONNECTIONS:
        if pose.visibility[a] > 0.3 and pose.visibility[b] > 0.3:
            cv2.line(out, _pt(lm[a]), _pt(lm[b]), colour, thick, cv2.LINE_AA)
    for i in (LEFT_SHOULDER, RIGHT_SHOULDER):
        cv2.circle(out, _pt(lm[i]), shoulder_radius, SHOULDERS, -1, cv2.LINE_AA)


def _text(img, text, org, colour=(255, 255, 255), size: float = 0.6) -> None:
    """Text with a dark outline, drawn in place.

    The outline is the text's own mask grown by OUTLINE_PX, not the text drawn again
    thicker: under OpenCV 5 a thicker stroke also widens every character's advance, so a
    thick black copy ran ahead of the text on it ("perpendicular rightt")."""
    scale = max(img.shape[0] / 432, 0.5) * size
    thick = max(1, round(2 * scale))
    font = cv2.FONT_HERSHEY_SIMPLEX
    (w, h), base = cv2.getTextSize(text, font, scale, thick)
    pad = OUTLINE_PX + thick
    x0, y0 = max(org[0] - pad, 0), max(org[1] - h - pad, 0)
    x1, y1 = min(org[0] + w + pad, img.shape[1]), min(org[1] + base + pad, img.shape[0])
    if x1 <= x0 or y1 <= y0:
        return  # entirely outside the image
    mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
    cv2.putText(mask, text, (org[0] - x0, org[1] - y0), font, scale, 255, thick, cv2.LINE_AA)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * OUTLINE_PX + 1,) * 2)
    outline = cv2.dilate(mask, kernel)
    region = img[y0:y1, x0:x1].astype(np.float32)
    a_out = (outline.astype(np.float32) / 255.0)[..., None]
    a_text = (mask.astype(np.float32) / 255.0)[..., None]
    region *= 1.0 - a_out  # black outline
    region = region * (1.0 - a_text) + np.asarray(colour, np.float32) * a_text
    img[y0:y1, x0:x1] = np.clip(np.rint(region), 0, 255).astype(img.dtype)
