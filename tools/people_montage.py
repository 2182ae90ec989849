"""A montage of the several-people families as the robot's camera sees them, each person
boxed and named from the ground truth.

    python -m tools.people_montage [--set people|crowd] [--out PNG]

`--set crowd` draws the crowd families instead (scenarios/families/small/crowd/: the
JuPedSim crowds and the replayed real scenes, which read the shared data) into
docs/crowd/montage.png.

One row per family, two frames each (an early one and one closer to the step out, the
hiding or the robot passing): a small collision family with four bystanders on the
pavements (scenarios/people/pavement_four.toml), then the families of
scenarios/families/small/people/ at one fixed draw each. On each frame every person's
whole-body box (the truth's, occlusion ignored) is drawn with their name and the share
of their body the camera sees; the scripted person's box is red. The PNG is written
whole or not at all.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from monopic.output import atomic_path
from sim.scenario.files import load
from sim.world.ground_truth import PersonTruth
from sim.world.world import World

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
TILE_WIDTH = 512  # px; the camera's 16:9 frame is scaled to this width
CAPTION = 22  # px of caption above each frame
TITLE = 24  # px of title above each row
FONT, FONT_SIZE = cv2.FONT_HERSHEY_SIMPLEX, 0.4
SCRIPTED = (40, 40, 230)  # BGR: red
OTHERS = (  # BGR, one per bystander in turn
    (230, 160, 30), (40, 200, 40), (220, 60, 200), (20, 200, 230), (200, 200, 200),
    (140, 90, 30),
)  # fmt: skip


@dataclass(frozen=True)
class Row:
    """One family at one draw: `params` are its dotted keys, `times` the two frames (s)."""

    title: str
    file: str  # relative to scenarios/
    times: tuple[float, float]
    params: dict[str, Any] = field(default_factory=dict)
    seed: int = 1


ROWS = (
    Row("CPNA-25 (small) with four bystanders on the pavements (people/pavement_four.toml)",
        "families/small/cpna25.toml", (0.5, 2.9),
        {"robot.speed": 2.0, "path.impact_time": 3.5, "people": "../../people/pavement_four.toml"}),
    Row("child-beside-adult: the child steps out from beside an adult who stays on the kerb",
        "families/small/people/child_beside_adult.toml", (0.5, 1.8),
        {"robot.speed": 1.5, "path.from_kerb": 0.6, "pedestrians.1.path.from_kerb": 0.2}),
    Row("far-crosser-hidden: a runner on the far side behind a nearer adult on the far kerb",
        "families/small/people/far_crosser_hidden.toml", (0.0, 1.5),
        {"robot.speed": 2.0, "pedestrians.1.path.impact_time": 4.3}),
    Row("group-step-out: the first of a group of six steps out, the others set off later (3.6 s)",
        "families/small/people/group_step_out.toml", (1.5, 3.4),
        {"robot.speed": 2.0, "people": "../../../people/group_of_6.toml"}),
    Row("nearmiss-kerb-wait: four people wait at the kerbs, nobody crosses",
        "families/small/people/nearmiss_kerb_wait.toml", (1.0, 2.6), {"robot.speed": 2.0}),
)  # fmt: skip


def finite_box(person: PersonTruth) -> tuple[int, int, int, int] | None:
    """The person's whole-body box in pixels, None when it is not in the image."""
    box = person.box
    if not person.in_frame or not all(math.isfinite(v) for v in box):
        return None
    return tuple(int(round(v)) for v in box)  # type: ignore[return-value]


def label(image: np.ndarray, text: str, at: tuple[int, int], colour: tuple[int, int, int]) -> None:
    """`text` with a dark outline, its baseline's left end at `at`."""
    cv2.putText(image, text, at, FONT, FONT_SIZE, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(image, text, at, FONT, FONT_SIZE, colour, 1, cv2.LINE_AA)


def free_spot(
    taken: list[tuple[int, int, int, int]], u: int, v: int, size: tuple[int, int], height: int
) -> tuple[int, int]:
    """Where a label of `size` (width, height) goes near baseline (u, v) without covering
    another label in `taken` (boxes u0, v0, u1, v1): moved up a line at a time, then down."""
    w, h = size
    for step in [*range(0, -12, -1), *range(1, 12)]:
        b = v + step * (h + 3)
        if b - h < 0 or b > height - 2:
            continue
        box = (u, b - h - 1, u + w, b + 2)
        if not any(box[0] < o[2] and o[0] < box[2] and box[1] < o[3] and o[1] < box[3]
                   for o in taken):  # fmt: skip
            taken.append(box)
            return u, b
    return u, v


def draw_people(image: np.ndarray, people: tuple[PersonTruth, ...], scale: float) -> None:
    """Each person's box, name and seen share on `image` (already scaled by `scale`);
    labels are moved off each other, the scripted person's placed first."""
    taken: list[tuple[int, int, int, int]] = []
    for k, person in enumerate(people):
        box = finite_box(person)
        if box is None:
            continue
        colour = SCRIPTED if k == 0 else OTHERS[(k - 1) % len(OTHERS)]
        u0, v0, u1, v1 = (int(round(v * scale)) for v in box)
        cv2.rectangle(image, (u0, v0), (u1, v1), colour, 1)
        seen = (
            person.visibility.visible if person.visibility is not None else person.visible_fraction
        )
        text = f"{person.name} {100 * seen:.0f}%"
        (w, h), _ = cv2.getTextSize(text, FONT, FONT_SIZE, 1)
        u = min(max(u0, 1), image.shape[1] - w - 1)
        at = free_spot(taken, u, v0 - 4, (w, h), image.shape[0])
        label(image, text, at, colour)


def tile(image_rgb: np.ndarray, people: tuple[PersonTruth, ...], caption: str) -> np.ndarray:
    """One frame scaled to TILE_WIDTH, its people drawn, a caption above."""
    scale = TILE_WIDTH / image_rgb.shape[1]
    height = int(round(image_rgb.shape[0] * scale))
    frame = cv2.resize(cv2.cvtColor(image_rgb, cv2.COLOR_RGB2BGR), (TILE_WIDTH, height),
                       interpolation=cv2.INTER_AREA)  # fmt: skip
    draw_people(frame, people, scale)
    bar = np.full((CAPTION, TILE_WIDTH, 3), 255, np.uint8)
    cv2.putText(bar, caption, (6, 15), cv2.FONT_HERSHEY_SIMPLEX, 0.42, (0, 0, 0), 1, cv2.LINE_AA)
    return np.vstack([bar, frame])


CROWD_ROWS = (
    Row("crowd-crossing: 15 people moved by JuPedSim, one crossing into the robot's path",
        "families/small/crowd/crowd_crossing.toml", (0.5, 3.0), {"robot.speed": 2.0}),
    Row("kerb-queue: one steps out from a queue of five at the near kerb, the rest wait",
        "families/small/crowd/kerb_queue.toml", (1.0, 3.5), {"crowd.queue": 5}),
    Row("replay-hotel: 17 real walkers of the ETH hotel scene on the street (their recorded walks)",
        "families/small/crowd/replay_hotel.toml", (0.5, 4.0)),
    Row("replay-zara: 18 real walkers of the UCY zara01 scene, turned to cross the road",
        "families/small/crowd/replay_zara.toml", (0.5, 3.5)),
)  # fmt: skip
SETS = {"people": (ROWS, "people"), "crowd": (CROWD_ROWS, "crowd")}


def render_row(row: Row) -> np.ndarray:
    """The row's title over its two frames side by side."""
    f = load(SCENARIOS / row.file)
    scenario = f.scenario(row.params, name=f.name, seed=row.seed)
    tiles = []
    with World(scenario, render=True) as world:
        step = world.reset()
        for t in row.times:
            while step.time + 1e-9 < t:
                step = world.step()
            if step.frame is None:
                raise RuntimeError(f"{row.file}: no frame rendered at t = {t} s")
            people = step.truth.people
            shown = sum(finite_box(p) is not None for p in people)
            caption = (
                f"{f.name}  t = {step.time:.1f} s  robot {scenario.robot.speed:g} m/s  "
                f"{len(people)} people, {shown} in view"
            )
            tiles.append(tile(step.frame.image, people, caption))
    strip = np.hstack([tiles[0], np.full((tiles[0].shape[0], 4, 3), 255, np.uint8), tiles[1]])
    title = np.full((TITLE, strip.shape[1], 3), 255, np.uint8)
    cv2.putText(title, row.title, (6, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
    return np.vstack([title, strip])


def write_png(path: Path, image: np.ndarray) -> None:
    """`image` (BGR) as a PNG at `path`, whole or not at all."""
    if path.suffix.lower() != ".png":
        raise SystemExit(f"{path}: the montage is a PNG: give a path ending in .png")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:  # the temporary keeps the .png suffix
        if not cv2.imwrite(str(tmp), image, [cv2.IMWRITE_PNG_COMPRESSION, 9]):
            raise SystemExit(f"{path}: could not write the montage")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--set", choices=tuple(SETS), default="people", help="which families")
    ap.add_argument("--out", type=Path, help="the PNG (default docs/<set>/montage.png)")
    args = ap.parse_args(argv)
    chosen, folder = SETS[args.set]
    args.out = args.out or ROOT / "docs" / folder / "montage.png"
    rows = [render_row(row) for row in chosen]
    gap = np.full((6, rows[0].shape[1], 3), 255, np.uint8)
    montage = np.vstack([part for row in rows for part in (row, gap)][:-1])
    write_png(args.out, montage)
    size = args.out.stat().st_size / 1e6
    print(f"montage: {args.out} ({montage.shape[1]}x{montage.shape[0]}, {size:.2f} MB)")


if __name__ == "__main__":
    main()
