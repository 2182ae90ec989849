"""A run as a MOTChallenge sequence: gt/gt.txt, seqinfo.ini and img1/ (links to the images).

`mot/<run>/` is laid out as a MOTChallenge (MOT16/17) sequence folder, so `monopic
track-eval TRACKS --gt mot/<run>` reads it as it reads a real one (PETS09-S2L1), and
`monopic video mot/<run> --tracks TRACKS` runs the pipeline's tracker on it:

- gt/gt.txt: one line per person per frame where any of the person's body is inside the
  image, `frame,id,bb_left,bb_top,bb_width,bb_height,1,1,visibility`: frames counted from
  1, ids 1 for the scenario's scripted pedestrian then 2, 3, ... for the others in the
  scenario's order (the same person keeps their id the whole run), the box the whole
  body's image box clipped to the image (occlusion ignored, as MOT17 boxes are), conf 1
  (scored), class 1 (pedestrian), visibility the share of the body's surface the camera
  sees (sim.world.ground_truth.Visibility.visible: 0 for someone wholly hidden, who
  keeps their line, as MOTChallenge keeps occluded people);
- seqinfo.ini: name (the run id), imDir (img1), frameRate, seqLength, imWidth, imHeight,
  imExt (.jpg);
- img1/000001.jpg ...: relative symbolic links to the run's images/<run>/0000.jpg ... (the
  dataset's images are numbered from 0, a MOTChallenge sequence's from 1; the links number
  them as the gt numbers the frames, without a second copy of the images).
"""

from __future__ import annotations

import os
from pathlib import Path

from sim.geometry.box_match import clipped_box
from sim.world.ground_truth import PersonTruth

MOT = "mot"  # the dataset's folder of sequences
SEQINFO = "seqinfo.ini"
IMAGE_DIR = "img1"
PEDESTRIAN_CLASS = 1  # MOT16/17's class of a pedestrian


def gt_line(frame: int, track_id: int, person: PersonTruth, width: int, height: int) -> str | None:
    """The gt.txt line of one person at `frame` (from 1); None when no part of the body
    is inside the image (MOTChallenge has no line for someone out of view)."""
    box = clipped_box(person.box, width, height)
    if not person.in_frame or box is None:
        return None
    if person.visibility is None:
        raise ValueError(f"person {person.name!r} has no visibility (a truth without sight)")
    left, top, w, h = box
    seen = person.visibility.visible
    box_text = f"{left:.2f},{top:.2f},{w:.2f},{h:.2f}"
    return f"{frame},{track_id},{box_text},1,{PEDESTRIAN_CLASS},{seen:.4f}"


def seqinfo(name: str, fps: float, frames: int, width: int, height: int) -> str:
    """The [Sequence] section MOTChallenge's seqinfo.ini holds."""
    return (
        f"[Sequence]\nname={name}\nimDir={IMAGE_DIR}\nframeRate={fps:g}\nseqLength={frames}\n"
        f"imWidth={width}\nimHeight={height}\nimExt=.jpg\n"
    )


def link_images(sequence: Path, images: list[Path]) -> None:
    """img1/<n>.jpg in `sequence` for n = 1, 2, ...: relative links to `images` in order."""
    folder = sequence / IMAGE_DIR
    folder.mkdir(parents=True, exist_ok=True)
    for number, image in enumerate(images, start=1):
        link = folder / f"{number:06d}.jpg"
        link.symlink_to(os.path.relpath(image, folder))
