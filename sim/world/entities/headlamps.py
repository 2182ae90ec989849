"""The car's headlamps: its beam's cones (sim.scenario.lamps) as spot lights riding with it.

A mocap body kept at the robot's pose each frame carries the cones at the front centre,
at the beam's height; the body's pitch while braking is not followed (the beam dips
with the nose on a real car: about 1-2 degrees at full braking, sim.scenario.spec
BodyPitch). No shadows (sim.world.entities.street_lamps: each shadowed light is a pass).
"""

from __future__ import annotations

import mujoco

from sim.geometry.frames import yaw_quat
from sim.scenario.lamps import Headlamps
from sim.world.entities.base import Entity, Moment
from sim.world.entities.street_lamps import light_value


class HeadlampLights(Entity):
    """The beam of the robot's headlamps, `front` metres ahead of its reference point."""

    name = "headlamps"
    kind = "lamp"

    def __init__(self, beam: Headlamps, front: float, full_scale_lux: float) -> None:
        self.beam = beam
        self.front = front
        self.full_scale_lux = full_scale_lux

    def build(self, spec: mujoco.MjSpec) -> None:
        body = spec.worldbody.add_body(name=self.prefix + "anchor", mocap=True)
        for k, spot in enumerate(self.beam.spots):
            value = light_value(spot.intensity_cd, self.full_scale_lux)
            body.add_light(
                name=f"{self.prefix}{k}",
                type=mujoco.mjtLightType.mjLIGHT_SPOT,
                pos=[self.front, 0.0, self.beam.height],
                dir=list(spot.direction()),
                cutoff=spot.cutoff_deg,
                exponent=0,
                attenuation=[0, 0, 1],
                castshadow=False,
                diffuse=[value, value, value],
                ambient=[0, 0, 0],
                specular=[0, 0, 0],
            )

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._mocap = int(model.body(self.prefix + "anchor").mocapid[0])

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        robot = moment.robot
        data.mocap_pos[self._mocap] = (robot.x, robot.y, 0.0)
        data.mocap_quat[self._mocap] = yaw_quat(robot.yaw)
