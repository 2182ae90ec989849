"""The frames both pipelines see in the reference comparison, decoded or rendered once.

Two sources, all 768x432 RGB: the shipped clip (tests/data/walk_clip.mp4, decoded, with
its truth CSV) and short World clips of a few cases at several distances (robot standing,
so the distance holds). They are stored as one uint8 array (N, H, W, 3) in a .npy file
that workers memory-map (no copy per process), and a .npz with the truth: landmark pixels
(N, 33, 2), a visibility mask (N, 33) (in the image and, for rendered frames, not
occluded; the clip's CSV has no occlusion, so there it is "in the image"), sequence
number and timestamp per frame. A sequence is a run of consecutive frames: trackers are
reset at each sequence start.

Other recipes (`Recipe`) build other sets the same way, each cached under its own
digest: `LARGE` (at least 500 frames, on which an int8 landmark model must keep the
float model's error) and `CALIBRATION` (other seeds and distances, the frames an int8
model is calibrated on, so that it is never judged on them).

    .venv/bin/python -m bench.frameset [--out recordings/bench/frames] [--recipe default]
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CLIP = ROOT / "tests" / "data" / "walk_clip.mp4"
CLIP_TRUTH = ROOT / "tests" / "data" / "walk_clip_truth.csv"
DEFAULT_DIR = ROOT / "recordings" / "bench"
NUM_LANDMARKS = 33
# Rendered clips: (case number, distance in m); frames per clip at 15 fps.
RENDERED_CASES = (5, 7, 3, 9)
RENDERED_DISTANCES = (3.0, 6.0, 10.0)
RENDERED_FRAMES = 16


@dataclass(frozen=True)
class Recipe:
    """Which frames a set holds: the clip (all of it, or its first `clip_frames`) and one
    rendered World clip per (case, distance), seeded by distance, case and `seed`."""

    name: str
    cases: tuple[int, ...] = RENDERED_CASES
    distances: tuple[float, ...] = RENDERED_DISTANCES
    frames: int = RENDERED_FRAMES
    seed: int = 0
    clip_frames: int | None = None  # None: the whole clip

    def digest_parts(self) -> list:
        """What the cache digest covers; the default recipe keeps its original digest."""
        parts: list = [CLIP.stat().st_size, self.cases, self.distances, self.frames, 1]
        if (self.seed, self.clip_frames) != (0, None):
            parts += [self.seed, self.clip_frames]
        return parts


DEFAULT = Recipe("default")
# 600 frames: the clip and all nine cases at 3, 5 and 8 m, 20 frames each.
LARGE = Recipe("large", cases=tuple(range(1, 10)), distances=(3.0, 5.0, 8.0), frames=20, seed=1)
# 30 clip frames and eight cases at 4 and 7 m with other seeds: the int8 calibration set.
CALIBRATION = Recipe(
    "calibration", cases=tuple(range(1, 9)), distances=(4.0, 7.0), frames=10, seed=2, clip_frames=30
)
# Nine cases at six distances out to 12.5 m, 10 frames each, other seeds: the set the
# search's faint-candidate zoom (monopic.pose.search.SearchSteps) was tuned on, so that
# the comparison's frames never chose it.
SEARCH = Recipe(
    "search",
    cases=tuple(range(1, 10)),
    distances=(4.0, 6.5, 8.0, 9.5, 11.0, 12.5),
    frames=10,
    seed=3,
    clip_frames=10,
)
RECIPES = {r.name: r for r in (DEFAULT, LARGE, CALIBRATION, SEARCH)}


@dataclass(frozen=True)
class FrameSet:
    """Memory-mapped frames plus their truth; `sequences[k]` names sequence k."""

    images: np.ndarray  # (N, H, W, 3) uint8, memory-mapped read-only
    landmarks: np.ndarray  # (N, 33, 2) true pixels, NaN where unknown
    visible: np.ndarray  # (N, 33) bool
    sequence: np.ndarray  # (N,) int
    timestamp: np.ndarray  # (N,) s
    sequences: list[str]
    distance: np.ndarray  # (N,) m to the pedestrian's path crossing; NaN for the clip

    def __len__(self) -> int:
        return len(self.sequence)


def spec_digest(recipe: Recipe = DEFAULT) -> str:
    """Changes when the frame recipe changes, so a stale cache is rebuilt."""
    return hashlib.sha1(json.dumps(recipe.digest_parts()).encode()).hexdigest()[:10]


def paths(directory: Path, recipe: Recipe = DEFAULT) -> tuple[Path, Path]:
    d = spec_digest(recipe)
    return directory / f"frames-{d}.npy", directory / f"frames-{d}.npz"


def _clip_frames() -> tuple[list[np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    from monopic.video import VideoSource

    frames = list(VideoSource(str(CLIP)))
    with CLIP_TRUTH.open() as fh:
        rows = list(csv.DictReader(fh))
    if len(rows) != len(frames):
        raise RuntimeError(f"{CLIP_TRUTH}: {len(rows)} rows for {len(frames)} frames")
    lm = np.array(
        [[[float(r[f"lm{i}_u"]), float(r[f"lm{i}_v"])] for i in range(NUM_LANDMARKS)] for r in rows]
    )
    h, w = frames[0].image.shape[:2]
    vis = (lm[..., 0] >= 0) & (lm[..., 0] < w) & (lm[..., 1] >= 0) & (lm[..., 1] < h)
    return [f.image for f in frames], lm, vis, np.array([f.timestamp for f in frames])


def _rendered(case: int, distance: float, frames: int, seed: int = 0):
    """One World clip: images, true pixels, visibility mask, timestamps."""
    from dataclasses import replace

    from monopic.cases import Case
    from sim.scenario.cases import CasePlacement
    from sim.scenario.presets import FPS
    from sim.world.ground_truth import in_image
    from sim.world.world import World

    duration = frames / FPS  # the placement's frame rate: `frames` frames
    sc = CasePlacement(
        Case(case),
        distance=distance,
        robot_speed=0.0,
        duration=duration,
        meet_time=duration / 2,
        seed=int(distance * 10) + case + 1000 * seed,
    ).scenario()
    sc = replace(sc, name=f"case{case}@{distance:g}m")
    images, lms, vis, ts = [], [], [], []
    with World(sc) as world:
        for step in world.run():
            assert step.frame is not None
            images.append(step.frame.image)
            px = step.truth.pedestrian.landmarks_px
            lms.append(px)
            vis.append(in_image(world.camera, px) & ~step.truth.pedestrian.landmarks_occluded)
            ts.append(step.time)
    return images, np.array(lms), np.array(vis), np.array(ts), sc.name


def build(directory: Path = DEFAULT_DIR, recipe: Recipe = DEFAULT) -> tuple[Path, Path]:
    """Decode and render the frame set unless the cache already has it; return its paths."""
    npy, npz = paths(directory, recipe)
    if npy.is_file() and npz.is_file():
        return npy, npz
    directory.mkdir(parents=True, exist_ok=True)
    images, lms, vis, seq, ts, dist, names = [], [], [], [], [], [], []
    im, lm, v, t = _clip_frames()
    if recipe.clip_frames is not None:
        k = recipe.clip_frames
        im, lm, v, t = im[:k], lm[:k], v[:k], t[:k]
    images += im
    lms.append(lm)
    vis.append(v)
    ts.append(t)
    seq += [0] * len(im)
    dist += [float("nan")] * len(im)
    names.append("walk_clip")
    for case in recipe.cases:
        for distance in recipe.distances:
            im, lm, v, t, name = _rendered(case, distance, recipe.frames, recipe.seed)
            images += im
            lms.append(lm)
            vis.append(v)
            ts.append(t)
            seq += [len(names)] * len(im)
            dist += [distance] * len(im)
            names.append(name)
            print(f"rendered {name}", file=sys.stderr)
    tmp = npy.with_suffix(".tmp.npy")
    np.save(tmp, np.stack(images))
    np.savez(
        npz,
        landmarks=np.concatenate(lms),
        visible=np.concatenate(vis),
        sequence=np.array(seq),
        timestamp=np.concatenate(ts),
        distance=np.array(dist),
        names=np.array(names),
    )
    tmp.rename(npy)
    return npy, npz


def load(npy: Path, npz: Path) -> FrameSet:
    """Memory-map the images (shared page cache between processes) and read the truth."""
    images = np.load(npy, mmap_mode="r")
    with np.load(npz) as z:
        return FrameSet(
            images=images,
            landmarks=z["landmarks"],
            visible=z["visible"].astype(bool),
            sequence=z["sequence"],
            timestamp=z["timestamp"],
            sequences=[str(n) for n in z["names"]],
            distance=z["distance"],
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=DEFAULT_DIR)
    ap.add_argument("--recipe", choices=list(RECIPES), default=DEFAULT.name)
    args = ap.parse_args()
    npy, npz = build(args.out, RECIPES[args.recipe])
    fs = load(npy, npz)
    print(f"{npy}: {len(fs)} frames, {len(fs.sequences)} sequences, {fs.images.shape}")


if __name__ == "__main__":
    main()
