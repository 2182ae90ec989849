"""COCO keypoint files: the two skeletons, run-length masks, and a small strict reader.

The synthetic dataset (sim.dataset.build) writes one COCO keypoints file per skeleton:
BlazePose's 33 landmarks and COCO's own 17 (a subset of BlazePose's, mapped by name).
Masks are COCO's compressed RLE (column-major runs, first run of zeros, counts written
as pycocotools' `rleToString` does: 6 bits per character, delta against the count two
back), so pycocotools reads them natively; `read_coco` decodes them without it and is
checked against pycocotools in tests/test_dataset.py when that is installed.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from monopic.errors import UserError
from monopic.pose.skeleton import CONNECTIONS, INDEX, LANDMARK_NAMES

COCO17_NAMES: tuple[str, ...] = (
    "nose", "left_eye", "right_eye", "left_ear", "right_ear", "left_shoulder",
    "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip",
    "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle",
)  # fmt: skip
# COCO's keypoint names are BlazePose names too: index into the 33 landmarks.
COCO17_FROM_BLAZEPOSE: tuple[int, ...] = tuple(INDEX[name] for name in COCO17_NAMES)
# COCO's person skeleton (1-based keypoint numbers), as in person_keypoints_*.json.
COCO17_SKELETON: tuple[tuple[int, int], ...] = (
    (16, 14), (14, 12), (17, 15), (15, 13), (12, 13), (6, 12), (7, 13), (6, 7), (6, 8),
    (7, 9), (8, 10), (9, 11), (2, 3), (1, 2), (1, 3), (2, 4), (3, 5), (4, 6), (5, 7),
)  # fmt: skip

SKELETONS = ("blazepose33", "coco17")


def category(skeleton: str) -> dict[str, Any]:
    """The one category ('person') of a keypoints file for `skeleton`."""
    if skeleton == "blazepose33":
        names, edges = LANDMARK_NAMES, [[a + 1, b + 1] for a, b in CONNECTIONS]
    elif skeleton == "coco17":
        names, edges = COCO17_NAMES, [list(e) for e in COCO17_SKELETON]
    else:
        raise ValueError(f"unknown skeleton {skeleton!r}: choose from {SKELETONS}")
    return {
        "id": 1,
        "name": "person",
        "supercategory": "person",
        "keypoints": list(names),
        "skeleton": edges,
    }


def select_keypoints(keypoints33: list[float], skeleton: str) -> list[float]:
    """Flat [x, y, v] * 33 in BlazePose order -> the same for `skeleton`."""
    if skeleton == "blazepose33":
        return list(keypoints33)
    out: list[float] = []
    for i in COCO17_FROM_BLAZEPOSE:
        out.extend(keypoints33[3 * i : 3 * i + 3])
    return out


# -- run-length encoding ----------------------------------------------------------------


def rle_counts(mask: np.ndarray) -> list[int]:
    """Runs of a boolean (H, W) mask in column-major order, starting with a run of zeros."""
    flat = np.asarray(mask, dtype=bool).reshape(-1, order="F")
    if flat.size == 0:
        return []
    change = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    bounds = np.concatenate([[0], change, [flat.size]])
    runs = np.diff(bounds).tolist()
    return [0, *runs] if flat[0] else runs


def counts_to_string(counts: list[int]) -> str:
    """pycocotools' rleToString: LEB128-like, 5 bits per character, deltas after the 3rd."""
    out = []
    for i, count in enumerate(counts):
        x = int(count) - (int(counts[i - 2]) if i > 2 else 0)
        more = True
        while more:
            c = x & 0x1F
            x >>= 5
            more = x != -1 if c & 0x10 else x != 0
            if more:
                c |= 0x20
            out.append(chr(c + 48))
    return "".join(out)


def string_to_counts(text: str) -> list[int]:
    """Inverse of counts_to_string (pycocotools' rleFrString)."""
    counts: list[int] = []
    p = 0
    while p < len(text):
        x = k = 0
        more = True
        while more:
            c = ord(text[p]) - 48
            x |= (c & 0x1F) << (5 * k)
            more = bool(c & 0x20)
            p += 1
            k += 1
            if not more and c & 0x10:
                x |= -1 << (5 * k)
        if len(counts) > 2:
            x += counts[-2]
        counts.append(x)
    return counts


def encode_mask(mask: np.ndarray) -> dict[str, Any]:
    """COCO compressed RLE of a boolean (H, W) mask."""
    h, w = mask.shape
    return {"size": [int(h), int(w)], "counts": counts_to_string(rle_counts(mask))}


def decode_mask(rle: dict[str, Any]) -> np.ndarray:
    """Boolean (H, W) mask of a COCO RLE (compressed string or list of counts)."""
    h, w = rle["size"]
    counts = rle["counts"]
    if isinstance(counts, str):
        counts = string_to_counts(counts)
    values = np.zeros(len(counts), dtype=bool)
    values[1::2] = True
    flat = np.repeat(values, counts)
    if flat.size != h * w:
        raise ValueError(f"RLE covers {flat.size} pixels, the mask has {h * w}")
    return flat.reshape((h, w), order="F")


def mask_box(mask: np.ndarray) -> list[float] | None:
    """COCO bbox [x, y, width, height] of the mask's pixels (None when empty)."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return None
    return [
        float(cols[0]),
        float(rows[0]),
        float(cols[-1] + 1 - cols[0]),
        float(rows[-1] + 1 - rows[0]),
    ]


# -- a small strict reader ------------------------------------------------------------------


@dataclass(frozen=True)
class CocoFile:
    """A keypoints file, read and checked."""

    path: Path
    images: dict[int, dict[str, Any]]
    annotations: list[dict[str, Any]]
    category: dict[str, Any]

    @property
    def num_keypoints(self) -> int:
        return len(self.category["keypoints"])

    def keypoints(self, ann: dict[str, Any]) -> np.ndarray:
        """(K, 3) x, y, visibility of an annotation."""
        return np.asarray(ann["keypoints"], dtype=float).reshape(-1, 3)

    def mask(self, ann: dict[str, Any]) -> np.ndarray:
        return decode_mask(ann["segmentation"])


def read_coco(path: Path) -> CocoFile:
    """Read a keypoints file written by sim.dataset.build; UserError naming what is wrong."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as err:
        raise UserError(f"{path}: cannot read COCO JSON: {err}") from None
    for key in ("images", "annotations", "categories"):
        if not isinstance(data.get(key), list):
            raise UserError(f"{path}: {key}: missing or not a list")
    if len(data["categories"]) != 1:
        raise UserError(f"{path}: categories: expected one (person), got {len(data['categories'])}")
    cat = data["categories"][0]
    k = len(cat.get("keypoints", []))
    images = {}
    for img in data["images"]:
        for key in ("id", "file_name", "width", "height"):
            if key not in img:
                raise UserError(f"{path}: images: an image has no {key!r}")
        if img["id"] in images:
            raise UserError(f"{path}: images: id {img['id']} appears twice")
        images[img["id"]] = img
    for ann in data["annotations"]:
        where = f"{path}: annotations id {ann.get('id')!r}"
        if ann.get("image_id") not in images:
            raise UserError(f"{where}: image_id {ann.get('image_id')!r} is not an image")
        if ann.get("category_id") != cat["id"]:
            raise UserError(f"{where}: category_id {ann.get('category_id')!r} is not {cat['id']}")
        kp = ann.get("keypoints", [])
        if len(kp) != 3 * k:
            raise UserError(f"{where}: keypoints: {len(kp)} values, expected {3 * k}")
        if any(v not in (0, 1, 2) for v in kp[2::3]):
            raise UserError(f"{where}: keypoints: visibility flags must be 0, 1 or 2")
        if ann.get("num_keypoints") != sum(1 for v in kp[2::3] if v > 0):
            raise UserError(f"{where}: num_keypoints {ann.get('num_keypoints')!r} is wrong")
        bbox = ann.get("bbox")
        if not (isinstance(bbox, list) and len(bbox) == 4 and bbox[2] >= 0 and bbox[3] >= 0):
            raise UserError(f"{where}: bbox {bbox!r} is not [x, y, width, height]")
        img = images[ann["image_id"]]
        seg = ann.get("segmentation")
        if not (isinstance(seg, dict) and seg.get("size") == [img["height"], img["width"]]):
            raise UserError(f"{where}: segmentation must be an RLE of the image's size")
    return CocoFile(path, images, list(data["annotations"]), cat)
