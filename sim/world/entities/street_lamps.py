"""The street lamps of a night scene, and which of them the renderer lights each frame.

MuJoCo's classic renderer lights at most 8 lights, its headlight (our light from
everywhere) included; any more active lights are ignored without an error (a probe:
with the headlight on, the eighth scene light adds nothing). A night road has seven lamps
and the car two low-beam cones (sim.scenario.lamps), so not every lamp can shine at once.
Each frame, the lamps whose light covers most of the image shine: a lamp's score is the
illuminance it puts on ground points around its foot that the camera sees, each weighed
by the image area it covers (1 / distance^2). The other lamps' light is left out; what that
costs is measured in tools/night_calibration.py against the exact image (the scene drawn
in several passes, each with at most 7 lights, summed: the renderer adds lights linearly
per vertex, up to the full scale, where it clamps: docs/night/calibration.md).

Lamps cast no shadows: each shadowed light adds a render pass (a probe: 12.6 ms a frame
without, 58 ms with one shadowed light, 543 ms with eight).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from monopic.camera import CameraModel
from sim.scenario.lamps import UP, StreetLamp
from sim.world.entities.base import Entity, Moment

MAX_LIGHTS = 8  # the classic renderer's, the headlight included
MAST_RADIUS = 0.08  # m
_RING = np.array([(dx, dy) for dx in (-10, -5, 0, 5, 10) for dy in (-10, -5, 0, 5, 10)], float)


def light_value(intensity_cd: float, full_scale_lux: float) -> float:
    """A light's diffuse value for the renderer: with attenuation 1/d^2, I/d^2 lux on a
    surface facing it renders as its share of the full-scale illuminance."""
    return intensity_cd / full_scale_lux


class StreetLamps(Entity):
    """Every lamp of the scene, with its mast; each frame the ones that matter shine."""

    name = "lamps"
    kind = "lamp"

    def __init__(
        self, lamps: tuple[StreetLamp, ...], full_scale_lux: float, camera: CameraModel
    ) -> None:
        self.lamps = lamps
        self.full_scale_lux = full_scale_lux
        self.camera = camera
        self.half_fov = math.atan2(camera.width / 2, camera.fx)
        self.shining: tuple[int, ...] = ()  # indices into lamps, this frame

    def build(self, spec: mujoco.MjSpec) -> None:
        spec.add_material(name=self.prefix + "glow", rgba=[1.0, 0.95, 0.85, 1], emission=1.0)
        for k, lamp in enumerate(self.lamps):
            body = spec.worldbody.add_body(name=f"{self.prefix}{k}", pos=[lamp.x, lamp.y, 0.0])
            body.add_geom(
                name=f"{self.prefix}{k}/mast",
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                size=[MAST_RADIUS, lamp.height / 2, 0],
                pos=[0, 0, lamp.height / 2],
                rgba=[0.35, 0.36, 0.38, 1],
                contype=0,
                conaffinity=0,
            )
            body.add_geom(  # the luminaire, glowing (emission) as a lit lamp is seen
                name=f"{self.prefix}{k}/head",
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[0.3, 0.15, 0.06],
                pos=[0, 0, lamp.height + 0.06],  # above its light, which hangs at the height
                rgba=[0.2, 0.2, 0.2, 1],
                material=self.prefix + "glow" if lamp.on else "",
                contype=0,
                conaffinity=0,
            )
            if not lamp.on:
                continue
            value = light_value(lamp.intensity_cd, self.full_scale_lux)
            body.add_light(
                name=f"{self.prefix}{k}/light",
                type=mujoco.mjtLightType.mjLIGHT_SPOT,
                pos=[0, 0, lamp.height],
                dir=[0, 0, -1],
                cutoff=lamp.cutoff_deg,
                exponent=0,
                attenuation=[0, 0, 1],
                castshadow=False,
                diffuse=[value, value, value],  # white: the lux stated in every channel
                ambient=[0, 0, 0],
                specular=[0, 0, 0],
            )

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._lights = {
            k: int(model.light(f"{self.prefix}{k}/light").id)
            for k, lamp in enumerate(self.lamps)
            if lamp.on
        }
        own = set(self._lights.values())
        others = sum(1 for i in range(model.nlight) if i not in own and model.light_active[i])
        headlight = 1 if model.vis.headlight.active else 0
        self.slots = max(0, MAX_LIGHTS - headlight - others)

    def score(self, moment: Moment) -> np.ndarray:
        """How much of the image each lamp's light covers (see the module docstring)."""
        robot = moment.robot
        cam = self.camera.position
        c, s = math.cos(robot.yaw), math.sin(robot.yaw)
        cx, cy = robot.x + c * cam[0] - s * cam[1], robot.y + s * cam[0] + c * cam[1]
        scores = np.zeros(len(self.lamps))
        for k, lamp in enumerate(self.lamps):
            if not lamp.on:
                continue
            px, py = lamp.x + _RING[:, 0], lamp.y + _RING[:, 1]
            dx, dy = px - cx, py - cy
            ahead = dx * c + dy * s
            side = -dx * s + dy * c
            seen = (ahead > 1.0) & (np.abs(np.arctan2(side, ahead)) < self.half_fov + 0.1)
            if not seen.any():
                continue
            ground = np.stack([px[seen], py[seen], np.zeros(int(seen.sum()))], axis=-1)
            e = lamp.illuminance_on(ground, UP)
            scores[k] = float(np.sum(e / np.maximum(dx[seen] ** 2 + dy[seen] ** 2, 9.0)))
        return scores

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        scores = self.score(moment)
        order = [int(k) for k in np.argsort(-scores, kind="stable") if scores[k] > 0]
        self.shining = tuple(sorted(order[: self.slots]))
        for k, light in self._lights.items():
            model.light_active[light] = 1 if k in self.shining else 0
