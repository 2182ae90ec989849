"""The dataset card (README.md): what the dataset holds, how it was made, counts, licence."""

from __future__ import annotations

import os
import platform
from pathlib import Path
from typing import Any

from monopic.cases import Case
from sim.dataset.spec import JPEG_QUALITY, DatasetSpec
from sim.runs.sweep import Include, SweepSpec
from sim.scenario.files import Values
from sim.sensor.spec import IDEAL


def readme(spec: DatasetSpec, counts: dict[str, Any]) -> str:
    """The dataset card."""
    import mujoco

    what, image_format, runs = _sweep_card(spec, spec.source, counts)
    cases = ", ".join(f"{Case(c).label} ({c}): {n}" for c, n in counts["cases"].items())
    copied = " (the spec is copied to `spec.toml`"
    copied += ", the scenario files it includes to `scenarios/`)" if spec.scenario_files else ")"
    keypoints = " / ".join(
        str(counts[k]) for k in ("keypoints_visible", "keypoints_occluded", "keypoints_outside")
    )
    people = counts.get("people") or [1]
    per_run = str(people[0]) if len(people) == 1 else f"{people[0]} to {people[-1]}"
    return f"""# {spec.name}: a synthetic pedestrian dataset from the MonoPIC test bed

{spec.description}

## What

{what}

| | |
| --- | --- |
| runs | {counts["runs"]} |
| images | {counts["images"]} ({image_format}) |
| people per run | {per_run} |
| person annotations (one per person per image where any pixel shows) | {counts["annotations"]} |
| keypoints in view / occluded / outside the image | {keypoints} |
| frames where the pipeline found the pose | {counts["pose_found"]} |
| pipeline feature rows | {counts["feature_rows"]} |
| runs ending in contact (the run stops there) | {counts["contacts"]} |
| size (images, masks, truth, features) | {counts["bytes"] / 1e6:.1f} MB |

Frames per ground-truth case (the case of the next second of true motion): {cases}.

## How it was made

`monopic dataset {spec.path.name} --out DIR`{copied}, with
monopic's simulator (sim/), MuJoCo {mujoco.__version__} rendering headless (EGL), on
{platform.machine()} / Python {platform.python_version()}. {runs}

Deterministic: the same spec gives the same images, masks, annotations and truth on the
same software; the features' measured-time columns (`detectMs` … `totalMs`) differ
between invocations. Resumable: finished runs (`runs/<run>.json`) are skipped.

## Files

- `images/<run>/<frame>.jpg`, `masks/<run>/<frame>.png` (0 background, 255 the
  scenario's scripted pedestrian, from MuJoCo's segmentation rendering; other objects
  and people hide it as in the image); with several people in a run, each other person's
  mask beside it, `masks/<run>/<frame>-<id>.png` (id as in `gt.txt` below);
- `annotations/blazepose33.json`, `annotations/coco17.json`: COCO keypoint files (one
  category, `person`; `file_name` relative to this folder). Every person in the scene is
  annotated: one annotation per person per image where any pixel of that person shows
  (someone wholly hidden or outside the image has none), each from that person's own
  mask: `bbox` the box of the visible pixels, `area` their count, `segmentation` as COCO
  compressed RLE; keypoints `[x, y, v]` in pixels with v = 0 outside the image, 1 hidden
  by another object or person (a MuJoCo ray test), 2 in view (the body hiding itself is
  not marked), `num_keypoints` those with v > 0; `amodal_bbox` the whole body's box
  clipped to the image. `iscrowd` is always 0: COCO sets 1 only on one region covering
  a crowd annotated as a whole, and here each person is annotated apart, however they
  overlap. When any run holds several people every annotation also names its person:
  `person` (the name in the scenario, `ped` for the scripted pedestrian), `track_id`
  (their id in `gt.txt`) and `mask_file`; COCO tools ignore these fields. Annotation
  ids: the image's id for the scripted pedestrian, plus (track_id - 1) x 10^10 for the
  others. COCO-17 keypoints are BlazePose's landmarks of the same names;
- `mot/<run>/`: the run as a MOTChallenge sequence folder (`monopic track-eval TRACKS
  --gt mot/<run>` reads it, `monopic video mot/<run>` plays it): `gt/gt.txt`, one line
  per person per frame where any of the body is inside the image,
  `frame,id,bb_left,bb_top,bb_width,bb_height,1,1,visibility` (frames from 1; id 1 the
  scripted pedestrian, then 2, 3, ... for the others, the same all run; the whole body's
  box clipped to the image, occlusion ignored; conf 1, class 1 pedestrian; visibility
  the share of the body's surface the camera sees, 0 for someone wholly hidden, who
  keeps their line as MOTChallenge keeps occluded people); `seqinfo.ini` (name,
  imDir, frameRate, seqLength, imWidth, imHeight, imExt); `img1/000001.jpg` ...:
  relative links to `images/<run>/0000.jpg` ..., numbered from 1 as the gt counts frames;
- `truth/<run>.jsonl`: per frame, the simulator's ground truth (`sim.world.ground_truth.
  GroundTruth.to_dict()`: the scripted pedestrian's positions in the world and the robot
  frame, velocities, case, true phi, time to collision, collision, contact, landmark
  pixels, occlusion, and the labels `case_now` (the case of the velocity now) and
  `intent` (keep going, stop, turn away or start crossing within the horizon;
  `intent_time` s until it happens); with several people, `people` holds each person's
  the same way, with their name, footprint and visibility);
- `frames.csv`: one row per image with the scripted pedestrian's main truth columns and
  those labels (every person's truth is in `truth/<run>.jsonl`, under `people`, when a
  run holds several);
- `features/<run>.csv`: the pipeline's own output per frame with a pose, in the MonoPIC
  authors' log columns then ours (as `monopic video --csv` writes), leaving out rows
  without a velocity yet (a track's first frame); `monopic tree train` and `monopic
  replay` read these files (their reader takes `occupiedHeights` as a fraction of a
  432 px high frame);
- `runs.csv`: the parameters of every run.

## Licence

{spec.licence}. Everything in the images is generated by the test bed (procedural
textures, the mannequin, the street); no third-party data is included.
"""


def _sweep_card(
    spec: DatasetSpec, sweep: SweepSpec, counts: dict[str, Any]
) -> tuple[str, str, str]:
    """The card's parts for a sweep spec: what, the image formats, how the runs were made."""
    what = """Images from the forward camera of a robot (small robot or car, as each scenario
file says) driving a MuJoCo street while a mannequin pedestrian crosses, walks along
or stops as the scenario families of a sweep spec (Euro NCAP-style collisions, near
misses, the paper's motion cases) describe, with ground truth from the simulator."""
    sizes = ", ".join(f"{w}x{h}" for w, h in counts["image_sizes"]) or "none"
    image_format = f"{sizes}, JPEG quality {JPEG_QUALITY}"
    includes = "\n".join(f"- {_include_text(spec.path.parent, i)};" for i in sweep.includes)
    families = ", ".join(f"{name}: {n}" for name, n in counts["families"].items())
    runs = f"""The runs are those of the sweep
spec, exactly as `monopic sweep` expands it (the same scenarios and seeds, and the same
run ids, `<scenario name>/<draw>-<digest of the scenario>`, so run folders nest). It
includes:

{includes}

Runs per family: {families}.

Each run lasts as its scenario file says (a run stops at contact), with that file's
frame rate, horizon, camera, road, lighting and pedestrian; the pipeline is the paper's
image mode (rule cascade) on one onnxruntime thread."""
    if sweep.camera is not None:
        how = (
            "the renderer's frames as they are" if sweep.camera == IDEAL
            else "the rendered light through its sensor: exposure, motion blur, noise, digitiser"
        )  # fmt: skip
        runs += f"""

Every run's camera is the spec's `camera`, {sweep.camera} ({how}), whatever its
scenario file names; the run ids and seeds are those of the files' own scenarios."""
    return what, image_format, runs


def _include_text(folder: Path, include: Include) -> str:
    """One [[include]] entry as the card lists it."""
    files = ", ".join(f"`{os.path.relpath(f, folder)}`" for f in include.files)
    how = [f"sampling {include.sampling}"]
    if include.runs is not None:
        how.append(f"{include.runs} run{'s' if include.runs != 1 else ''} per file")
    if include.seed is not None:
        how.append(f"seed {include.seed}")
    for key, dist in include.parameters.items():
        if isinstance(dist, Values):
            how.append(f"{key} in {list(dist.values)}")
        else:
            steps = f" in {dist.steps} steps" if dist.steps else ""
            how.append(f"{key} from {dist.low:g} to {dist.high:g}{steps}")
    return f"{files}: {', '.join(how)}"
