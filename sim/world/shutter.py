"""A real camera's exposure window: the scene rendered over it and read by the sensor.

Motion blur comes from sub-frame renders: the scene is put part of the way between the
last frame's state and this one (sim.world.scene.Scene.blend) at moments spread evenly
over the exposure from its start to its end (the frame's time), each drawn and the draws
averaged in linear light, so an edge smears over the whole distance it moved. How many:
enough that the largest image motion over the exposure (Scene.image_motion: every body's
centre and the near ground, seen by the camera as it moved) is sampled at least every
`blur_step_px` pixels, and one draw when it moves less than half of that, so a daylight
exposure of a fraction of a millisecond costs one render. A blur drawn from a per-pixel
motion field instead needs that field, which MuJoCo does not give: a segmentation render
and a depth read every frame, costing about what a second render costs whether anything
moves or not (bench/simulator.py's camera rows), and it smears the wrong way where a
moving body passes in front of another. The first frame of a run has no earlier state
and is drawn sharp.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from sim.sensor.exposure import ExposureState
from sim.sensor.readout import linear_light, photometric_light
from sim.sensor.sensor import Sensor
from sim.world.scene import Scene, SceneState


def subframes(blur_px: float, step_px: float, most: int) -> int:
    """Draws for an image motion of `blur_px` over the exposure: 1 below half a step,
    otherwise one more than the steps it spans, at most `most`."""
    if not blur_px >= 0.5 * step_px:
        return 1
    return min(most, math.ceil(blur_px / step_px) + 1)


class Shutter:
    """Exposes each frame of one world: `capture(render, interval)` after the world placed
    its bodies for the frame."""

    def __init__(self, sensor: Sensor, scene: Scene, photometric: bool = False) -> None:
        """`photometric`: the render is linear in light (a night lighting's), so it is read
        as it is; otherwise it is a display image, sRGB-decoded to linear light."""
        self.sensor = sensor
        self.scene = scene
        self.previous: SceneState | None = None
        self.to_light = photometric_light if photometric else linear_light

    def reset(self, seed: int) -> None:
        self.sensor.reset(seed)
        self.previous = None

    def capture(
        self, render: Callable[[], np.ndarray], interval: float
    ) -> tuple[np.ndarray, ExposureState]:
        """The frame and its exposure; `interval` is the time since the last frame (s)."""
        sensor, scene, spec = self.sensor, self.scene, self.sensor.spec
        current = scene.snapshot()
        previous, self.previous = self.previous, current
        if not sensor.metered:
            light = self.to_light(render())
            sensor.meter(light)
            return sensor.read(light, sensor.settings())
        state = sensor.settings()
        draws = 1
        if spec.motion_blur and previous is not None and interval > 0:
            share = min(state.exposure_s / interval, 1.0)
            blur = scene.image_motion(previous, current) * share
            draws = subframes(blur, spec.blur_step_px, spec.max_subframes)
        if draws == 1:
            light = self.to_light(render())
        else:
            assert previous is not None
            light = np.zeros((scene.camera.height, scene.camera.width, 3), np.float32)
            for k in range(draws):
                scene.blend(previous, current, 1.0 - share * (1.0 - k / (draws - 1)))
                light += self.to_light(render())
            scene.blend(current, current, 1.0)
            light *= np.float32(1.0 / draws)
        return sensor.read(light, replace(state, subframes=draws))
