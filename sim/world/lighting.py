"""A Lighting (sim.scenario.lighting) in MuJoCo: the sky and the lights it brings.

`build_sky` sets the light from everywhere (MuJoCo's headlight) and the sky box; `lights`
gives the light sources as entities: the sun (when it shines), the street lamps and the
robot's headlamps (sim.world.entities.street_lamps, .headlamps). At night every light's
value is photometric: its illuminance over the lighting's full scale.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from monopic.camera import CameraModel
from sim.scenario.lamps import Headlamps, StreetLamp
from sim.scenario.lighting import Lighting, Sun
from sim.world.entities.base import Entity, Moment
from sim.world.entities.headlamps import HeadlampLights
from sim.world.entities.street_lamps import StreetLamps

SHADOW_CENTRE_AHEAD = 12.0  # m ahead of the robot where the sun's sharp-shadow region is


def build_sky(spec: mujoco.MjSpec, lighting: Lighting) -> None:
    """The sky's light from everywhere and the sky box."""
    headlight = spec.visual.headlight
    headlight.ambient = list(lighting.sky_ambient)
    headlight.diffuse = list(lighting.sky_diffuse)
    headlight.specular = [0.0, 0.0, 0.0]
    spec.add_texture(
        name="sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=list(lighting.sky_box[0]),
        rgb2=list(lighting.sky_box[1]),
        width=512,
        height=3072,
    )


def lights(
    lighting: Lighting,
    lamps: tuple[StreetLamp, ...] = (),
    camera: CameraModel | None = None,
    headlamps: Headlamps | None = None,
    front: float = 0.0,
) -> list[Entity]:
    """The light sources, as bodies of the scene: the sun if it shines, then the robot's
    headlamps (`front` m ahead of its reference point), then the street lamps (which the
    renderer's remaining lights go to, `camera` saying which matter)."""
    out: list[Entity] = [SunLight(lighting.sun)] if lighting.sun.shines else []
    if headlamps is not None:
        out.append(HeadlampLights(headlamps, front, lighting.illuminance_lux))
    if lamps:
        if camera is None:
            raise ValueError("street lamps need the camera that decides which of them shine")
        out.append(StreetLamps(lamps, lighting.illuminance_lux, camera))
    return out


def sun_direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Unit vector the sunlight travels along (from the sun towards the ground)."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    towards_sun = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    return -towards_sun


class SunLight(Entity):
    """The sun: a directional light hung from a mocap anchor kept ahead of the robot, so the
    shadow map stays sharp where the camera looks; the anchor never rotates, so the light's
    direction stays fixed in the world."""

    name = "sun"

    def __init__(self, sun: Sun, ahead: float = SHADOW_CENTRE_AHEAD) -> None:
        self.sun = sun
        self.ahead = ahead

    def build(self, spec: mujoco.MjSpec) -> None:
        sun = self.sun
        anchor = spec.worldbody.add_body(name=self.prefix + "anchor", mocap=True)
        direction = sun_direction(sun.azimuth_deg, sun.elevation_deg)
        anchor.add_light(
            name=self.name,
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            pos=(-60.0 * direction).tolist(),
            dir=direction.tolist(),
            castshadow=sun.shadows,
            diffuse=list(sun.diffuse),
            ambient=list(sun.ambient),
            specular=list(sun.specular),
        )

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._mocap = int(model.body(self.prefix + "anchor").mocapid[0])

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        robot = moment.robot
        data.mocap_pos[self._mocap] = (
            robot.x + self.ahead * math.cos(robot.yaw),
            robot.y + self.ahead * math.sin(robot.yaw),
            0.0,
        )
