"""How well, and how far away, does the pipeline read a head turn? Readings against truth.

The intent tree reads no cue (docs/intent/ground-tree.md): its hold-back buys near misses
with lead at a fixed rate, and a head check seen before the walker moves is the cue that
could change that rate. On rendered runs the shipped head yaw read the 40-45 deg head
checks as -2 to 19 deg. This measures why, on stills where nothing else moves: the
mannequin stands at each distance a little off the axis of the robot's camera (768x432,
65 deg vertical field of view), its body turned from facing the camera by 0-330 deg, its
head turned from the shoulders by -60..60 deg. The real tracker (its whole search
cascade, then three tracking passes on the same image, no smoothing) gives the
landmarks. Two readings:

- `shipped`: monopic.features.head.head_yaw, the angle between the ear and eye lines and
  the shoulder line in (image x, BlazePose z): depths of points across the head;
- `image`: the head's facing from the camera in the image alone
  (monopic.features.head.head_facing: atan2 of the nose's offset from the ears' midpoint
  over 10 cm and the signed eye separation over 63 mm), on every still,
  against the truth's head facing from the camera; and the head from the shoulders as
  that facing less the shoulder line's angle (as the shipped reading and phi take it).

Per distance: the slope of reading on truth (1: the turn is read in full, 0: not at all),
the residual spread, the median error, and how often a turn of 40 deg or more reads more
than half its size with the right sign. The truth is the neck's yaw set on the mannequin;
nothing of it reaches the tracker. Not a judge of the tree: a still has no motion, and a
head check is a change over time.

    MUJOCO_GL=egl .venv/bin/python -m studies.intent.head_reading [--out docs/intent]

Writes DIR/head-reading.md (the table) and DIR/head-reading.png (readings against truth,
slope against distance), each whole or not at all. About 2.5 minutes on one core.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from monopic.features.head import NOSE, head_facing, head_yaw
from monopic.pose.search import GroundBand
from monopic.pose.skeleton import LEFT_SHOULDER, RIGHT_SHOULDER
from monopic.pose.tracker import PoseTracker, TrackerConfig
from sim.world.render import GLUnavailableError, SceneRenderer
from sim.world.scene import Scene

ROOT = Path(__file__).resolve().parents[2]
DISTANCES_M = (2.0, 3.0, 4.0, 6.0, 8.0, 12.0)
BODY_DEG = tuple(float(b) for b in range(0, 360, 30))  # 0 facing the camera, 90 profile
HEAD_DEG = tuple(float(h) for h in range(-60, 61, 10))  # from the shoulders, + left
LATERAL_M = 0.3  # a little off the optical axis, as a walker near the path
TRACK_PASSES = 3  # tracking passes on the same still after acquisition
BIG_TURN_DEG = 40.0


@dataclass(frozen=True)
class Still:
    """One rendered still and what the tracker made of it."""

    distance: float
    body: float  # deg, body turned from facing the camera
    head: float  # deg, true head yaw from the shoulders, + to the person's left
    camera_facing: float  # deg, true head facing from the line to the camera, + left
    landmarks: np.ndarray | None  # (33, 3), None when nobody was found
    visibility: np.ndarray | None

    @property
    def found(self) -> bool:
        return self.landmarks is not None

    def head_px(self) -> float:
        """Head size in the image: twice the nose's distance from the shoulders' midpoint."""
        if self.landmarks is None:
            return math.nan
        lm = self.landmarks
        mid = (lm[LEFT_SHOULDER, :2] + lm[RIGHT_SHOULDER, :2]) / 2
        return 2.0 * float(np.linalg.norm(lm[NOSE, :2] - mid))


def wrap_deg(a: float) -> float:
    return (a + 180.0) % 360.0 - 180.0


def shipped_reading(still: Still) -> float:
    assert still.landmarks is not None and still.visibility is not None
    return head_yaw(still.landmarks, still.visibility).yaw


def image_facing(still: Still) -> float:
    """Head facing from the camera (deg, + left) from image x alone: the pipeline's
    head_facing, read on every still whatever BlazePose's visibility says."""
    assert still.landmarks is not None and still.visibility is not None
    return head_facing(still.landmarks, still.visibility, min_visibility=0.0)


def image_reading(still: Still) -> float:
    """The image facing less the shoulder line's angle in (x, z): head from shoulders."""
    lm = still.landmarks
    assert lm is not None
    d = lm[LEFT_SHOULDER] - lm[RIGHT_SHOULDER]
    return wrap_deg(image_facing(still) - math.degrees(math.atan2(d[2], d[0])))


def render_still(scene: Scene, renderer: SceneRenderer, tracker: PoseTracker, band: GroundBand,
                 distance: float, body: float, head: float) -> Still:  # fmt: skip
    """Render one still and track it."""
    sight = math.atan2(LATERAL_M, distance)
    scene.pedestrians[0].pose_at(
        scene.model, scene.data, distance, LATERAL_M, sight + math.pi - math.radians(body),
        head_yaw=math.radians(head),
    )  # fmt: skip
    scene.update()
    image = renderer.render()
    tracker.reset()
    result = tracker.process(image, band=band)
    for _ in range(TRACK_PASSES):
        if not result.found:
            break
        result = tracker.process(image, band=band)
    facing = wrap_deg(head - body)  # the head from the line to the camera
    if result.pose is None:
        return Still(distance, body, head, facing, None, None)
    return Still(distance, body, head, facing, result.pose.landmarks.copy(),
                 result.pose.visibility.copy())  # fmt: skip


@dataclass(frozen=True)
class Agreement:
    slope: float  # of reading on truth
    residual_deg: float
    median_error_deg: float
    big_turns_read: float  # share of |truth| >= 40 deg read past half, right sign
    n: int


def agreement(truth: list[float], reading: list[float]) -> Agreement:
    t, y = np.array(truth), np.array(reading)
    ok = np.isfinite(y)
    t, y = t[ok], y[ok]
    if len(t) < 3:
        return Agreement(math.nan, math.nan, math.nan, math.nan, len(t))
    slope, icpt = np.polyfit(t, y, 1)
    resid = float(np.std(y - (slope * t + icpt), ddof=2))
    err = np.abs([wrap_deg(a - b) for a, b in zip(y, t, strict=True)])
    big = np.abs(t) >= BIG_TURN_DEG
    read = (np.sign(y[big]) == np.sign(t[big])) & (np.abs(y[big]) > np.abs(t[big]) / 2)
    share = float(read.mean()) if big.any() else math.nan
    return Agreement(float(slope), resid, float(np.median(err)), share, len(t))


def readings(stills: list[Still]) -> dict[str, Agreement]:
    """Both readings of the head from the shoulders, and the image facing from the camera."""
    found = [s for s in stills if s.found]
    head = [s.head for s in found]
    return {
        "shipped": agreement(head, [shipped_reading(s) for s in found]),
        "image": agreement(head, [image_reading(s) for s in found]),
        "facing": agreement([s.camera_facing for s in found], [image_facing(s) for s in found]),
    }


def table(stills: list[Still]) -> str:
    lines = [
        "| distance | head in image | found | shipped: slope | residual | median error | "
        "turns >= 40 deg read | image, head from shoulders: slope | residual | median error "
        "| turns >= 40 deg read | image, facing from camera: median error |",
        "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for d in DISTANCES_M:
        at = [s for s in stills if s.distance == d]
        px = np.nanmedian([s.head_px() for s in at]) if any(s.found for s in at) else math.nan
        r = readings(at)
        a, b, f = r["shipped"], r["image"], r["facing"]
        lines.append(
            f"| {d:g} m | {px:.0f} px | {sum(s.found for s in at)}/{len(at)} | {a.slope:.2f} | "
            f"{a.residual_deg:.0f} deg | {a.median_error_deg:.0f} deg | {a.big_turns_read:.0%} | "
            f"{b.slope:.2f} | {b.residual_deg:.0f} deg | {b.median_error_deg:.0f} deg | "
            f"{b.big_turns_read:.0%} | {f.median_error_deg:.0f} deg |"
        )
    return "\n".join(lines)


def plot(stills: list[Still], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    at3 = [s for s in stills if s.distance == 3.0 and s.found]
    for ax, (name, fn) in zip(axes[:2], (("shipped", shipped_reading),
                                         ("image, head from shoulders", image_reading)),
                              strict=True):  # fmt: skip
        heads = np.array([s.head for s in at3])
        jitter = np.random.default_rng(0).uniform(-2, 2, len(heads))
        ax.scatter(heads + jitter, [fn(s) for s in at3], s=8, alpha=0.5,
                   c=[s.body for s in at3], cmap="twilight")  # fmt: skip
        ax.plot(HEAD_DEG, HEAD_DEG, "k--", lw=1, label="read in full")
        ax.set(xlabel="true head yaw from shoulders (deg)", ylabel="reading (deg)",
               title=f"{name}, 3 m, every body turn (colour)")  # fmt: skip
        ax.set_ylim(-100, 100)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    ax = axes[2]
    per_d = [readings([s for s in stills if s.distance == d]) for d in DISTANCES_M]
    for key, label in (("shipped", "shipped"), ("image", "image, head from shoulders")):
        ax.plot(DISTANCES_M, [r[key].slope for r in per_d], "o-", label=label)
    ax.axhline(1.0, color="k", ls="--", lw=1)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="distance (m)", ylabel="slope of reading on truth", ylim=(-0.1, 1.1),
           title="how much of a head turn is read")  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with tempfile.NamedTemporaryFile(dir=path.parent, suffix=".png", delete=False) as tmp:
        fig.savefig(tmp.name, dpi=90)
    os.replace(tmp.name, path)
    plt.close(fig)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "intent")
    args = ap.parse_args()
    if not args.out.is_dir():
        print(f"head_reading: --out {args.out}: no such directory", file=sys.stderr)
        return 2
    start = time.perf_counter()
    scene = Scene()
    band = GroundBand.from_camera(scene.camera)
    tracker = PoseTracker(TrackerConfig(threads=1, search_budget=0))  # stills: whole cascade
    stills: list[Still] = []
    try:
        renderer = SceneRenderer(scene)
    except GLUnavailableError as err:
        print(f"head_reading: {err}", file=sys.stderr)
        return 1
    with renderer:
        for d in DISTANCES_M:
            for b in BODY_DEG:
                stills.extend(
                    render_still(scene, renderer, tracker, band, d, b, h) for h in HEAD_DEG
                )
            print(f"{d:g} m done ({time.perf_counter() - start:.0f} s)", file=sys.stderr)
    text = table(stills)
    print(text)
    body = (
        "# Head yaw read from BlazePose landmarks, against distance (generated)\n\n"
        f"`MUJOCO_GL=egl .venv/bin/python -m studies.intent.head_reading`, "
        f"{time.strftime('%Y-%m-%d %H:%M', time.gmtime())} UTC, {len(stills)} stills "
        f"({len(BODY_DEG)} body turns x {len(HEAD_DEG)} head turns per distance). What it "
        "measures: the docstring of studies/intent/head_reading.py. Picture: "
        "[head-reading.png](head-reading.png).\n\n" + text + "\n"
    )
    plot(stills, args.out / "head-reading.png")
    with tempfile.NamedTemporaryFile("w", dir=args.out, suffix=".md", delete=False) as tmp:
        tmp.write(body)
    os.replace(tmp.name, args.out / "head-reading.md")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
