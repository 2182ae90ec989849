"""A montage of the human walker's intent cues, frame by frame, as the robot's camera sees them.

    .venv/bin/python -m tools.cue_montage [--out docs/images/cues-montage.png]

Three rows, each a scenario of a family with a `human` walker and the robot standing, so
the walker stays in view: a head check before stepping off (wait-then-cross), the head
then the shoulders leading a turn into the road (along-then-turn), and the slowing before
a kerb stop (kerb-stop). Each row shows frames around the cue, cropped around the
pedestrian, labelled with the time, the speed and the true head and shoulder turns.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from monopic.output import atomic_path
from sim.scenario.files import load
from sim.world.world import World

ROOT = Path(__file__).resolve().parents[1]
FAMILIES = ROOT / "scenarios" / "families" / "small"
TILE = 220  # px per frame in the montage


@dataclass(frozen=True)
class Row:
    title: str
    file: str
    params: dict
    seed: int
    cue: str  # which event to centre the frames on: "check", "turn" or "stop"


ROWS = (
    Row("head check toward the traffic before stepping off (wait-then-cross)",
        "wait_then_cross.toml", {"path.from_kerb": 0.3, "path.impact_time": 5.0,
                                 "pedestrian.behaviour.head_check_probability": 1.0}, 3, "check"),
    Row("head, then shoulders, lead the turn into the road (along-then-turn)",
        "along_then_turn.toml", {"path.direction": "toward", "path.impact_time": 4.5}, 2, "turn"),
    Row("slowing over the last steps before a kerb stop (kerb-stop)",
        "nearmiss_kerb_stop.toml", {"pedestrian.behaviour.model": "human",
                                    "pedestrian.speed": 1.39, "path.approach": 4.6,
                                    "path.impact_time": 4.5}, 4, "stop"),
)  # fmt: skip


def cue_times(world: World, cue: str, duration: float) -> list[float]:
    """Six times around the row's cue, from the walker's own track."""
    track = world.pedestrian.path  # type: ignore[union-attr]
    times = np.arange(0.0, duration, 0.02)
    states = [track.state(float(t)) for t in times]
    if cue == "check":  # the check while it still stands, before it steps off
        head = np.array([abs(s.head_yaw + s.torso_yaw) if s.speed < 0.05 else 0.0 for s in states])
        centre = float(times[int(np.argmax(head))])
        span = 1.6
    elif cue == "turn":
        yaw = np.unwrap([s.footprint_yaw for s in states])
        rate = np.abs(np.gradient(yaw, times))
        centre = float(times[int(np.argmax(rate))])
        span = 1.6
    else:
        speed = np.array([s.speed for s in states])
        moving = np.flatnonzero(speed > 0.05)
        stop = float(times[moving[-1]]) if len(moving) else duration / 2
        centre = stop - 0.9
        span = 2.4
    start = max(0.0, centre - span / 2)
    return [min(start + k * span / 5, duration - 0.07) for k in range(6)]


def crop(image: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    u0, v0, u1, v1 = box
    h = max(v1 - v0, 40.0) * 1.3
    cu, cv = (u0 + u1) / 2, (v0 + v1) / 2
    x0, y0 = int(max(cu - h / 2, 0)), int(max(cv - h / 2, 0))
    x1, y1 = int(min(cu + h / 2, image.shape[1])), int(min(cv + h / 2, image.shape[0]))
    patch = image[y0:y1, x0:x1]
    return cv2.resize(patch, (TILE, TILE), interpolation=cv2.INTER_AREA)


def render_row(row: Row) -> np.ndarray:
    f = load(FAMILIES / row.file)
    params = {**row.params, "robot.speed": 0.0}
    scenario = f.scenario(params, name=f.name, seed=row.seed)
    tiles = []
    with World(scenario, render=True) as world:
        world.reset()
        wanted = cue_times(world, row.cue, scenario.duration)
        step = world.last
        for t in wanted:
            while step is not None and step.time + 1e-9 < t:
                step = world.step()
            assert step is not None and step.frame is not None
            state = world.pedestrian.state  # type: ignore[union-attr]
            tile = crop(
                cv2.cvtColor(step.frame.image, cv2.COLOR_RGB2BGR), step.truth.pedestrian.box
            )
            label = (
                f"t {step.time:.2f} s  v {state.speed:.2f}",
                f"head {math.degrees(step.truth.pedestrian.head_yaw_shoulders):+.0f}  "
                f"shoulders {math.degrees(state.torso_yaw):+.0f} deg",
            )
            for k, text in enumerate(label):
                y = TILE - 26 + 14 * k
                cv2.putText(tile, text, (5, y), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 3)
                cv2.putText(tile, text, (5, y), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 255), 1)
            tiles.append(tile)
    strip = np.hstack(tiles)
    title = np.full((24, strip.shape[1], 3), 255, np.uint8)
    cv2.putText(title, row.title, (6, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 0), 1)
    return np.vstack([title, strip])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "cues-montage.png")
    args = ap.parse_args()
    montage = np.vstack([render_row(row) for row in ROWS])
    with atomic_path(args.out) as tmp:
        if not cv2.imwrite(str(tmp.with_suffix(".png")), montage):
            raise SystemExit(f"{args.out}: could not write the montage")
        tmp.with_suffix(".png").rename(tmp)
    print(f"montage: {args.out} ({montage.shape[1]}x{montage.shape[0]})")


if __name__ == "__main__":
    main()
