"""Night frames as the pipeline saw them, beside the same moments by day
(docs/images/night.png).

    python -m tools.night_montage [--out PNG] [--policy rules/ground]

One Euro NCAP CPNA crossing at 40 km/h, impact 50 % (sim.scenario.ncap, the nominal
draw; the car does not brake, so both runs pass the same places), run by day
(cpna) and at night (cpna-night: low beams, 1 lux, the nearside night road's lamps),
through the car's camera (car.toml: imx273) and the policy's pipeline. Columns: the
moments the target stands 40, 25, 15 and 8 m ahead of the car's front; each panel is the
frame with the pipeline's overlay (its box, skeleton, case and warning zone, as
`monopic video` draws them) and a label: the distance, whether the pipeline had a track
on the target (sim.world.warned_for.target_found), the exposure and gain. The PNG is
written whole or not at all.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from monopic.output import atomic_path
from monopic.overlay import draw
from monopic.pipeline import Variant
from sim.runs.aeb import ahead_of_front
from sim.runs.closed_loop import POLICY, policy_pipeline
from sim.runs.loop import Listener, LoopFrame, OnBoard, run_loop
from sim.scenario.ncap import Draw, GridPoint, load_car, load_protocol, scenario_for
from sim.world.warned_for import target_found
from sim.world.world import World

OUT = Path("docs/images/night.png")
DISTANCES_M = (40.0, 25.0, 15.0, 8.0)  # ahead of the car's front
SCALE = 0.5  # each panel at half the camera's resolution


@dataclass
class Grab(Listener):
    """The first frame at or inside each distance, with the pipeline's overlay."""

    front: float
    fps: float
    panels: dict[float, np.ndarray] = field(default_factory=dict)

    def frame(self, frame: LoopFrame) -> None:
        ahead = ahead_of_front(frame.truth, self.front)
        for d in DISTANCES_M:
            if d in self.panels or ahead > d:
                continue
            image = frame.step.frame.image if frame.step.frame is not None else None
            result = frame.results.get(POLICY)
            assert image is not None
            shown = draw(image, result, Variant.WARNING, self.fps) if result else image.copy()
            found = target_found(result, frame.truth)
            cam = frame.truth.camera
            exposure = "" if cam is None else f", {cam.exposure_s * 1e3:.2g} ms x{cam.gain:.0f}"
            label = f"{d:g} m: {'found' if found else 'not found'}{exposure}"
            small = cv2.resize(shown, None, fx=SCALE, fy=SCALE, interpolation=cv2.INTER_AREA)
            cv2.rectangle(small, (0, 0), (small.shape[1], 22), (0, 0, 0), -1)
            cv2.putText(small, label, (6, 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255),
                        1, cv2.LINE_AA)  # fmt: skip
            self.panels[d] = small


def row(test: str, policy: str) -> list[np.ndarray]:
    protocol, car = load_protocol(), load_car()
    scenario = scenario_for(protocol, car, GridPoint(test, "AEB", 40.0, 0.5), Draw.nominal())
    grab = Grab(scenario.robot.length / 2, 1.0 / scenario.dt)
    with World(scenario) as world:
        run_loop(world, [OnBoard(POLICY, policy_pipeline(scenario, policy))], [grab],
                 frames=scenario.frames)  # fmt: skip
    return [grab.panels[d] for d in DISTANCES_M if d in grab.panels]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--policy", default="rules/ground", help="PREDICTOR/MODE")
    args = parser.parse_args(argv)
    rows = [np.hstack(row(test, args.policy)) for test in ("cpna", "cpna-night")]
    montage = cv2.cvtColor(np.vstack(rows), cv2.COLOR_RGB2BGR)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(args.out) as tmp:  # the temporary keeps the .png suffix
        if not cv2.imwrite(str(tmp), montage, [cv2.IMWRITE_PNG_COMPRESSION, 9]):
            raise OSError(f"could not write {args.out}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
