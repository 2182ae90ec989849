"""Share of rendered frames in which the real pose tracker finds the mannequin.

Renders short clips through World.step for each of the paper's eight cases plus a person
standing with their back to the camera ("still, facing away"), at a range of distances,
with the robot standing so the distance sets the apparent size. Every frame goes through
monopic's PoseTracker with its default config (detector on the whole frame and on tiles
to acquire, then landmark tracking; no ground-truth crop), one tracker per clip. A frame
counts as found when the tracker returns a pose whose landmark box centre lies inside
the mannequin's true box; a pose elsewhere counts as a false find. Only frames with the
whole body inside the image are counted. Buckets are the true apparent height (box
height) over the frame height. Prints the tables; studies/detection/README.md says where
its answers are kept.

    .venv/bin/python -m studies.detection.found_share [--frames 12] [--distances 2.4 3 4 ...]
        [--width 768 --height 432] [--montage recordings/found_share_cases.png]
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import cv2
import numpy as np

from monopic.cases import Case
from monopic.pose.tracker import PoseTracker, TrackerConfig
from sim.runs.loop import Listener, LoopFrame, StepTimes, run_loop
from sim.scenario.cases import CasePlacement
from sim.scenario.spec import CameraSpec, RobotSpec, Scenario
from sim.world.world import World

BUCKETS = (
    (0.0, 1 / 8),
    (1 / 8, 1 / 6),
    (1 / 6, 1 / 4),
    (1 / 4, 1 / 3),
    (1 / 3, 1 / 2),
    (1 / 2, 9.0),
)
BUCKET_NAMES = ("<1/8", "1/8-1/6", "1/6-1/4", "1/4-1/3", "1/3-1/2", ">1/2")
DISTANCES = (2.4, 3.0, 4.0, 5.0, 6.0, 7.5, 9.0, 11.0, 13.5)
BAR = 0.9  # the bar: found in >= 90 % of frames with the body >= 1/4 of the frame


@dataclass(frozen=True)
class Config:
    """One row of the by-case table: a case and, for still, which way the person faces."""

    name: str
    case: Case
    facing_deg: float = 180.0


CONFIGS = (
    *(Config(f"{int(c)} {c.label}", c) for c in Case if c is not Case.STILL),
    Config("9 still, facing away", Case.STILL, facing_deg=0.0),
)


@dataclass
class Tally:
    frames: int = 0
    found: int = 0
    false: int = 0

    def share(self) -> str:
        return f"{100 * self.found / self.frames:.1f} %" if self.frames else "-"


def big_of(tallies: list[Tally]) -> Tally:
    """The buckets where the body spans at least 1/4 of the frame, summed (as the table)."""
    big = Tally()
    for t in tallies[3:]:
        big.frames += t.frames
        big.found += t.found
        big.false += t.false
    return big


def meets_bar(tallies: list[Tally]) -> bool:
    big = big_of(tallies)
    return bool(big.frames and big.found >= BAR * big.frames)


@dataclass
class FoundCounter(Listener):
    """Runs the tracker on each frame of one clip and counts finds in the true box."""

    tracker: PoseTracker
    width: int
    height: int
    by_bucket: list[Tally]
    by_case: list[Tally]
    skipped: int = 0
    thumb_at: int = -1  # frame to keep a montage thumbnail of
    thumb_label: str = ""
    thumbs: list[np.ndarray] = field(default_factory=list)

    def frame(self, frame: LoopFrame) -> None:
        assert frame.step.frame is not None
        image, truth = frame.step.frame.image, frame.truth
        result = self.tracker.process(image)
        u0, v0, u1, v1 = truth.pedestrian.box
        if not (u0 >= 0 and v0 >= 0 and u1 <= self.width and v1 <= self.height):
            self.skipped += 1
            return
        found = false = False
        if result.pose is not None:
            bx0, by0, bx1, by1 = result.pose.box
            cx, cy = (bx0 + bx1) / 2, (by0 + by1) / 2
            found = u0 <= cx <= u1 and v0 <= cy <= v1
            false = not found
        b = bucket_of(truth.pedestrian.apparent_height / self.height)
        for tally in (self.by_bucket[b], self.by_case[b]):
            tally.frames += 1
            tally.found += found
            tally.false += false
        if frame.index == self.thumb_at:
            self.thumbs.append(annotate(image, self.thumb_label, truth.pedestrian.box, result))


def bucket_of(ratio: float) -> int:
    return next(k for k, (lo, hi) in enumerate(BUCKETS) if lo <= ratio < hi)


def clip(config: Config, distance: float, frames: int, camera: CameraSpec) -> Scenario:
    duration = frames / 15.0
    sc = CasePlacement(
        config.case,
        distance=distance,
        robot_speed=0.0,
        pedestrian_speed=1.4,
        facing_deg=config.facing_deg,
        duration=duration,
        meet_time=duration / 2,
        seed=int(distance * 10),
    ).scenario(robot=RobotSpec(camera=camera))
    return replace(sc, name=f"{config.name} @ {distance} m")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=12, help="frames per clip (15 fps)")
    ap.add_argument("--distances", type=float, nargs="+", default=list(DISTANCES))
    ap.add_argument("--width", type=int, default=768)
    ap.add_argument("--height", type=int, default=432)
    ap.add_argument("--montage", type=Path, default=None, help="save a mid frame of each case")
    ap.add_argument("--montage-distance", type=float, default=6.0)
    args = ap.parse_args()
    camera = CameraSpec(width=args.width, height=args.height)

    tracker = PoseTracker(TrackerConfig())
    by_bucket = [Tally() for _ in BUCKETS]
    by_case = {c.name: [Tally() for _ in BUCKETS] for c in CONFIGS}
    times = StepTimes()
    thumbs: list[np.ndarray] = []
    montage_distance = min(args.distances, key=lambda d: abs(d - args.montage_distance))
    t_start = time.perf_counter()
    skipped = 0
    for config in CONFIGS:
        for distance in args.distances:
            tracker.reset()
            counter = FoundCounter(
                tracker, args.width, args.height, by_bucket, by_case[config.name]
            )
            if args.montage and distance == montage_distance:
                counter.thumb_at, counter.thumb_label = args.frames // 2, config.name
            with World(clip(config, distance, args.frames, camera)) as world:
                run_loop(world, (), [times, counter], frames=args.frames, stop_at_contact=False)
            skipped += counter.skipped
            thumbs += counter.thumbs
    step_ms = times.ms
    elapsed = time.perf_counter() - t_start

    total = sum(t.frames for t in by_bucket)
    lines = [
        f"{len(CONFIGS)} configurations x {len(args.distances)} distances "
        f"({', '.join(f'{d:g}' for d in args.distances)} m) x {args.frames} frames, "
        f"{args.width}x{args.height}, 65 deg vertical FOV, camera 1.2 m; robot standing, "
        f"adult 1.8 m walking 1.4 m/s; PoseTracker default config (1 onnxruntime thread). "
        f"{total} frames counted, {skipped} with the body cut by the image border left out. "
        f"World.step (render + truth) median {np.median(step_ms):.1f} ms; "
        f"{elapsed:.0f} s in all. nproc {len(os.sched_getaffinity(0))}, "
        f"uname -m {os.uname().machine}.",
        "",
        "By apparent height (true box height / frame height), all cases:",
        "",
        "| apparent height | frames | found | false finds | found share |",
        "|---|---:|---:|---:|---:|",
    ]
    for name, t in zip(BUCKET_NAMES, by_bucket, strict=True):
        lines.append(f"| {name} | {t.frames} | {t.found} | {t.false} | {t.share()} |")
    lines += [
        "",
        "By case (share of frames found; the bar: >= 90 % where the body spans >= 1/4):",
        "",
        "| case | " + " | ".join(BUCKET_NAMES) + " | >= 1/4 | meets bar |",
        "|---|" + "---:|" * (len(BUCKET_NAMES) + 2),
    ]
    for config in CONFIGS:
        tallies = by_case[config.name]
        big = big_of(tallies)
        ok = "yes" if meets_bar(tallies) else "no"
        cells = " | ".join(t.share() for t in tallies)
        lines.append(f"| {config.name} | {cells} | {big.share()} ({big.frames}) | {ok} |")
    print("\n".join(lines))

    if args.montage and thumbs:
        args.montage.parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(args.montage), cv2.cvtColor(montage(thumbs), cv2.COLOR_RGB2BGR))
        print(f"montage of one frame per case -> {args.montage}")


def annotate(image: np.ndarray, label: str, box: tuple, result: object) -> np.ndarray:
    """The frame with the true box (green), the found landmarks (red) and the case name."""
    out = image.copy()
    u0, v0, u1, v1 = (int(round(x)) for x in box)
    cv2.rectangle(out, (u0, v0), (u1, v1), (0, 255, 0), 1)
    pose = getattr(result, "pose", None)
    if pose is not None:
        for x, y in pose.landmarks[:, :2]:
            cv2.circle(out, (int(x), int(y)), 2, (255, 0, 0), -1)
    cv2.putText(out, label, (8, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 2)
    return out


def montage(images: list[np.ndarray], cols: int = 3) -> np.ndarray:
    h, w = images[0].shape[:2]
    rows = (len(images) + cols - 1) // cols
    sheet = np.zeros((rows * h, cols * w, 3), dtype=np.uint8)
    for k, img in enumerate(images):
        r, c = divmod(k, cols)
        sheet[r * h : (r + 1) * h, c * w : (c + 1) * w] = img
    return sheet


if __name__ == "__main__":
    main()
