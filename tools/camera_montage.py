"""The same moment through the ideal camera and the imx273 camera: what the sensor model
does to a frame, in a picture (docs/images/camera.png).

    python -m tools.camera_montage [--out PNG]

Four panels of one car-scale CPNA-style crossing at 40 km/h (the Euro NCAP grid's
placement of an adult crossing from the near side, sim.scenario.ncap), cropped unscaled
around the pedestrian at the kerb: the ideal camera (the renderer's frames); imx273 under a
clear sky (32,000 lux: a 0.2 ms exposure, no visible blur, little noise); imx273 under
the overcast preset (1,000 lux: a longer exposure and its smear); and imx273 at 30 lux,
dusk, where the auto-exposure runs out of time at the sensor's 30 ms and turns to gain
(noise, and the whole scene smeared by the car's own motion). Each panel is labelled with
the exposure and gain the camera chose. The PNG is written whole or not at all.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from monopic.output import atomic_path
from sim.scenario.lighting import PRESETS
from sim.scenario.ncap import GridPoint, draw_for, load_car, load_protocol, scenario_for
from sim.scenario.spec import Scenario
from sim.sensor.spec import IMX273
from sim.world.world import World

OUT = Path("docs/images/camera.png")
FRAME = 36  # the frame shown: the pedestrian at the kerb, about 15 m ahead
CROP = (384, 216)  # px of the full-resolution frame around the pedestrian, unscaled
POINT = GridPoint("cpna", "AEB", 40.0, 0.5)


def panel_scenarios(base: Scenario) -> list[tuple[str, Scenario]]:
    def camera(s: Scenario, sensor: object, lighting: object = None) -> Scenario:
        cam = replace(s.robot.camera, sensor=sensor)
        scene = s.scene if lighting is None else replace(s.scene, lighting=lighting)
        return replace(s, robot=replace(s.robot, camera=cam), scene=scene)

    overcast = PRESETS["overcast"]
    dusk = replace(overcast, name="dusk", illuminance_lux=30.0)
    return [
        ("ideal camera", camera(base, None)),
        ("imx273, sun", camera(base, IMX273)),
        ("imx273, overcast", camera(base, IMX273, overcast)),
        ("imx273, dusk (30 lux)", camera(base, IMX273, dusk)),
    ]


def frame_of(scenario: Scenario) -> tuple[np.ndarray, str]:
    """The frame's crop around the pedestrian (the truth's box centre) and what the camera
    chose for it."""
    with World(scenario) as world:
        for k, step in enumerate(world.run()):
            if k == FRAME:
                assert step.frame is not None
                box = step.truth.pedestrian.box
                h, w = step.frame.image.shape[:2]
                cx = w // 2 if box is None else int((box[0] + box[2]) / 2)
                x0 = min(max(cx - CROP[0] // 2, 0), w - CROP[0])
                y0 = min(max(h // 2 - CROP[1] // 2, 0), h - CROP[1])
                crop = step.frame.image[y0 : y0 + CROP[1], x0 : x0 + CROP[0]]
                state = step.truth.camera
                said = (
                    ""
                    if state is None
                    else f"{1000 * state.exposure_s:.2f} ms, gain {state.gain:.1f}, "
                    f"{state.subframes} draws"
                )
                return crop, said
    raise RuntimeError(f"the scenario ended before frame {FRAME}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=OUT, help="PNG to write (default %(default)s)")
    args = ap.parse_args()
    protocol, car = load_protocol(), load_car()
    base = scenario_for(protocol, car, POINT, draw_for(protocol.tolerances, POINT.id, 0), seed=0)
    panels = []
    for label, scenario in panel_scenarios(base):
        image, said = frame_of(scenario)
        bgr = np.ascontiguousarray(image[..., ::-1])
        for k, text in enumerate((label, said)):
            if text:
                cv2.putText(bgr, text, (8, 20 + 18 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.5,
                            (255, 255, 255), 1, cv2.LINE_AA)  # fmt: skip
        panels.append(bgr)
    top, bottom = np.hstack(panels[:2]), np.hstack(panels[2:])
    with atomic_path(args.out) as tmp:  # the temporary keeps the .png suffix
        if not cv2.imwrite(str(tmp), np.vstack([top, bottom]), [cv2.IMWRITE_PNG_COMPRESSION, 9]):
            raise RuntimeError(f"could not write {args.out}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
