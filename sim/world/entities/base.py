"""A body in the scene, after dm_control's Entity: one unit from its MJCF to its truth.

Each thing the camera can see (a pedestrian, the robot carrying the camera, a parked car,
the sun; later a street lamp or another vehicle) is an Entity. It

- adds its MJCF to the scene's MjSpec (`build`), every name under its own prefix;
- finds its own ids once the scene is compiled (`bind`);
- puts its motion on highway-env's road when a run starts (`reset`) and moves it each
  step, before highway-env's road steps (`before_step`) or after it (`after_step`);
- poses its MuJoCo bodies for the current moment (`place`);
- tells its own truth (`truth`).

The scene holds the list and compiles it; World composes the entities and never reads or
writes a MuJoCo array that belongs to one of them: adding a kind of body is one new module.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from monopic.camera import CameraModel
from sim.geometry.frames import Pose2D

if TYPE_CHECKING:
    from highway_env.road.road import Road


@dataclass(frozen=True)
class Moment:
    """What every entity may know when it poses itself: the time and where the robot is."""

    time: float
    robot: Pose2D


@dataclass(frozen=True)
class Sight:
    """What an entity's truth may use: the moment, the camera as it really points, where it
    is in the world, and the robot's motion (its footprint and velocity in highway-env's
    frame, for times to collision)."""

    time: float
    robot: Any  # sim.world.ground_truth.RobotState (the robot's own truth)
    camera: CameraModel  # the real camera (turned by the body's pitch)
    camera_world: np.ndarray  # (3,) the camera's centre, world frame
    robot_polygon: np.ndarray  # (5, 2) the robot's footprint, highway-env frame
    robot_velocity: np.ndarray  # (2,) highway-env frame, m/s
    horizon: float  # s, the warning horizon
    lookahead: float  # s, how far ahead times to collision are searched
    # Per geom of the scene: the kind of body that owns it (an index into
    # sim.world.ground_truth.HIDERS), for what hides whom.
    geom_kind: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))


class Entity:
    """One body in the scene. Subclasses add their MJCF (`build`) and override what else
    they have; the defaults are a static body with no motion and no truth."""

    name: str = "entity"  # its MJCF names start with `name + "/"`
    kind: str = "body"  # what it is to the truth ("person", "parked car": what hides whom)

    @property
    def prefix(self) -> str:
        return self.name + "/"

    def build(self, spec: mujoco.MjSpec) -> None:
        """Add the body's MJCF (bodies, geoms, materials, lights) to the scene's spec: every
        kind of body has its own, so a kind that forgets it fails here."""
        raise NotImplementedError(f"{type(self).__name__} adds no MJCF (Entity.build)")

    def bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Find the body's own ids in the compiled model."""

    def reset(self, road: Road, rng: np.random.Generator, seed: int) -> None:
        """A run starts: put the body's motion on highway-env's road (if it has any).
        `rng` is the run's (draw from it in build order); `seed` the run's seed."""

    def before_step(self, dt: float) -> None:
        """Move the body's own motion on by `dt` seconds, before highway-env's road steps
        (so its collision checks see the body where it now is)."""

    def after_step(self, dt: float) -> None:
        """React to highway-env's step of `dt` seconds (e.g. a body pitching as its vehicle
        brakes)."""

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, moment: Moment) -> None:
        """Pose the body's MuJoCo parts for this moment (the scene runs kinematics after)."""

    def geom_ids(self, model: mujoco.MjModel) -> np.ndarray:
        """The ids of the geoms that belong to this body (all named under its prefix)."""
        return np.array(
            [g for g in range(model.ngeom) if model.geom(g).name.startswith(self.prefix)],
            dtype=int,
        )

    def truth(self, model: mujoco.MjModel, data: mujoco.MjData, sight: Sight) -> object | None:
        """What is true about the body at this moment (None: nothing to tell)."""
        return None
