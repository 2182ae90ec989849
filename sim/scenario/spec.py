"""What a scenario is: the robot, its camera, the pedestrian's path, the scene, the horizon.

A scenario fully determines a run (with its seed). It is plain data: scenario files
(scenarios/*.toml) load into it, the eight-case placement builds it from a few
parameters, and World consumes it. Positions are in the simulator's world frame
(sim.geometry.frames: x east, y north, z up; headings in degrees counter-clockwise from east).
The robot starts at the origin heading east along the road's lane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

from monopic.camera import CameraModel
from monopic.cases import Case
from monopic.variants.zone import RobotGeometry
from sim.scenario import presets
from sim.scenario.lamps import Headlamps, StreetLamp
from sim.scenario.lighting import DAY, PRESETS, SUN_ONLY_IDENTITY, Lighting
from sim.scenario.plan import Anchor, Leg
from sim.scenario.walkers import HumanWalker, RailWalker, Walker
from sim.sensor.spec import SensorSpec

RGB = tuple[float, float, float]


@dataclass(frozen=True)
class RoadLayout:
    """Geometry of the street; lengths in metres."""

    length: float = 240.0  # along x, centred on x = 0
    lanes: int = 2
    lane_width: float = 3.5
    center_y: float = 0.0
    pavement_width: float = 3.0
    crosswalk_x: float | None = 12.0  # centre of the zebra crossing along x, None for none
    crosswalk_length: float = 4.0  # extent of the crossing along x
    stripe_width: float = 0.5  # zebra bar width (and gap) across the road
    line_width: float = 0.12
    dash_length: float = 3.0
    dash_gap: float = 6.0
    buildings: bool = True  # a row of facades behind each pavement

    def __post_init__(self) -> None:
        if self.lanes < 1 or self.lane_width <= 0 or self.length <= 0:
            raise ValueError("road needs at least one lane of positive width and length")

    @property
    def half_width(self) -> float:
        return self.lanes * self.lane_width / 2

    @property
    def edges(self) -> tuple[float, float]:
        """y of the right (south) and left (north) road edges."""
        return self.center_y - self.half_width, self.center_y + self.half_width


@dataclass(frozen=True)
class Occluder:
    """A static box on the ground (e.g. a parked car): centre x, y, heading, size (m)."""

    x: float
    y: float
    yaw: float = 0.0
    length: float = 4.5
    width: float = 1.8
    height: float = 1.45
    colour: RGB = (0.55, 0.1, 0.1)

    @classmethod
    def parked_car(
        cls, x: float, y: float, yaw: float = 0.0, colour: RGB = (0.55, 0.1, 0.1)
    ) -> Occluder:
        """A family-car-sized box."""
        return cls(x=x, y=y, yaw=yaw, colour=colour)


RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class MannequinSpec:
    """What the pedestrian looks like: stature (m) and colours (RGBA in [0, 1])."""

    height: float = 1.8
    shirt: RGBA = (0.16, 0.32, 0.62, 1.0)
    trousers: RGBA = (0.18, 0.18, 0.22, 1.0)
    skin: RGBA = (0.87, 0.68, 0.55, 1.0)
    hair: RGBA = (0.22, 0.14, 0.08, 1.0)
    shoes: RGBA = (0.12, 0.11, 0.10, 1.0)
    long_sleeves: bool = False
    shirt_pattern: str = "plain"  # "plain" or "checker" (a two-tone check of the shirt)

    def __post_init__(self) -> None:
        low, high = presets.HEIGHT_RANGE
        if not low <= self.height <= high:
            raise ValueError(f"mannequin height must be in [{low}, {high}] m, got {self.height}")
        if self.shirt_pattern not in ("plain", "checker"):
            raise ValueError(
                f"shirt_pattern must be 'plain' or 'checker', got {self.shirt_pattern}"
            )

    @classmethod
    def adult(cls, **colours: object) -> MannequinSpec:
        """A 1.8 m adult."""
        return cls(height=1.8, **colours)  # type: ignore[arg-type]

    @classmethod
    def child(cls, **colours: object) -> MannequinSpec:
        """A 1.15 m child (about six years old) in brighter clothes by default."""
        defaults: dict[str, object] = {
            "shirt": (0.85, 0.25, 0.2, 1.0),
            "trousers": (0.2, 0.3, 0.55, 1.0),
            "hair": (0.25, 0.16, 0.09, 1.0),  # light hair seen from behind passes for a face
        }
        defaults.update(colours)
        return cls(height=1.15, **defaults)  # type: ignore[arg-type]


@dataclass(frozen=True)
class CameraSpec:
    """The robot's forward camera."""

    width: int = presets.CAMERA_WIDTH
    height: int = presets.CAMERA_HEIGHT
    vertical_fov_deg: float = presets.CAMERA_FOV_DEG
    mount_height: float = presets.CAMERA_MOUNT_HEIGHT  # m above the ground
    pitch_deg: float = presets.CAMERA_PITCH_DEG  # positive looks down
    mount_forward: float = 0.0  # m ahead of the robot's reference point
    # The image sensor behind the lens (sim.sensor): None is the `ideal` camera, the
    # renderer's frames as they are; a preset's figures otherwise.
    sensor: SensorSpec | None = None

    def model(self) -> CameraModel:
        return CameraModel.from_fov(
            self.width,
            self.height,
            self.vertical_fov_deg,
            self.mount_height,
            self.pitch_deg,
            self.mount_forward,
        )


@dataclass(frozen=True)
class BodyPitch:
    """How the robot's body (and the camera on it) pitches when it brakes: the nose dip.

    A damped second-order response of the pitch angle to the longitudinal acceleration:
    in steady braking at `a` m/s^2 the body settles at `gain * (-a)` degrees nose down,
    with the body's pitch mode at `frequency` Hz and relative damping `damping`. The
    rendered camera and the ground truth follow the real pitch; the pipeline keeps the
    nominal CameraModel it was given (as a real car's calibration does). Gain 0 (the
    default): a rigid body that never pitches.
    """

    gain: float = 0.0  # degrees nose down per m/s^2 of deceleration
    frequency: float = 1.5  # Hz, the body's pitch mode
    damping: float = 0.7  # relative damping of that mode

    def __post_init__(self) -> None:
        if not (self.gain >= 0 and self.frequency > 0 and self.damping > 0):
            raise ValueError("body pitch needs gain >= 0, frequency > 0 and damping > 0")


@dataclass(frozen=True)
class RobotSpec:
    """The camera-carrying robot: a highway-env vehicle of this size and speed."""

    speed: float = presets.ROBOT_SPEED  # m/s at the start (0: standing robot)
    width: float = presets.ROBOT_WIDTH  # m
    length: float = presets.ROBOT_LENGTH  # m
    camera: CameraSpec = field(default_factory=CameraSpec)
    # Limits of the longitudinal action (m/s^2) and of the speed (m/s); it never reverses.
    max_acceleration: float = 3.0
    max_deceleration: float = 8.0  # braking, as a positive number
    max_speed: float = 20.0
    pitch: BodyPitch = field(default_factory=BodyPitch)  # nose dip when braking
    headlamps: Headlamps | None = None  # its beam (sim.scenario.lamps); a night scene needs one

    def geometry(self) -> RobotGeometry:
        """The pipeline's own footprint: a robot knows its size (reference point = centre)."""
        return RobotGeometry(width=self.width, length=self.length, front=self.length / 2)


@dataclass(frozen=True)
class PedestrianSpec:
    """The mannequin (stature, clothing) and its path: start, heading, speed, then legs."""

    x: float
    y: float
    heading_deg: float
    speed: float  # m/s, 0 for standing
    looks: MannequinSpec = field(default_factory=MannequinSpec.adult)
    legs: tuple[Leg, ...] = ()
    start_delay: float = 0.0  # s standing at the start before walking
    footprint: float = presets.FOOTPRINT  # m, side of the square it occupies on the ground
    # How it walks the plan (sim.scenario.walkers; the file's [pedestrian.behaviour]).
    behaviour: Walker = field(default_factory=RailWalker)
    # Where a placement says the walker is at a time (its plan passes there then); the
    # walker is shifted to pass it exactly whatever its behaviour. None: no constraint.
    anchor: Anchor | None = None
    name: str = ""  # the person's name in the scenario ("": the scripted person, "ped")

    def heading_at(self, t: float) -> float:
        """Heading in radians at time t (turns of the legs started so far)."""
        turn = sum(leg.turn_deg for leg in self.legs if leg.at <= t)
        return math.radians(self.heading_deg + turn)


CROWD_PREFIX = "crowd"  # a crowd member's name: crowd-1, crowd-2, ...


@dataclass(frozen=True)
class Crowd:
    """People a pedestrian-dynamics model moves together (JuPedSim: sim.scenario.crowd_motion).

    `along` walk along the pavements (both sides, both ways), `across` cross the road
    within `cross_region` to the other pavement, `queue` wait at the near kerb around
    `queue_x` and cross together at `release`. Everyone starts within `region` (world x)
    at a place drawn per run; a share `groups` of them walk in groups of 2-3 (the same way
    at the same desired speed). Desired speeds are drawn from a normal law (`speed`,
    `speed_spread`). Each member shows the cues of `cues` (a human walker's head checks;
    its motion parameters are not used: the crowd model moves them). Keys, units and
    sources: scenarios/README.md.
    """

    along: int = 0
    across: int = 0
    queue: int = 0
    region: tuple[float, float] = (0.0, 30.0)  # m, world x where the crowd starts
    cross_region: tuple[float, float] = (8.0, 16.0)  # m, world x where people cross
    queue_x: float = 12.0  # m, world x of the queue's head at the near kerb
    release: float = 6.0  # s, when the queue crosses
    groups: float = 0.7  # share of the walkers in groups of 2-3 (Moussaid et al. 2010: up to 70 %)
    speed: float = 1.34  # m/s, mean desired speed
    speed_spread: float = 0.16  # m/s, its standard deviation in one street
    looks: tuple[MannequinSpec, ...] = ()  # one per member: along, across, then queue
    cues: HumanWalker = field(default_factory=HumanWalker)
    footprint: float = presets.FOOTPRINT  # m, each member's square on the ground

    def __post_init__(self) -> None:
        if min(self.along, self.across, self.queue) < 0 or len(self.looks) != self.count:
            raise ValueError("a crowd needs counts >= 0 and one look per member")

    @property
    def count(self) -> int:
        return self.along + self.across + self.queue

    def role(self, k: int) -> str:
        """Member k's part: "along", "across" or "queue"."""
        return "along" if k < self.along else "across" if k < self.along + self.across else "queue"

    def members(self) -> tuple[PedestrianSpec, ...]:
        """Each member as a person of the street: name, looks and footprint (where they
        are comes from the crowd's motion, not from this plan, which stands them at the
        region's start)."""
        x = self.region[0]
        return tuple(
            PedestrianSpec(
                x=x,
                y=0.0,
                heading_deg=0.0,
                speed=0.0,
                looks=looks,
                footprint=self.footprint,
                behaviour=self.cues,
                name=f"{CROWD_PREFIX}-{k + 1}",
            )  # fmt: skip
            for k, looks in enumerate(self.looks)
        )


@dataclass(frozen=True)
class SceneSpec:
    occluders: tuple[Occluder, ...] = ()  # e.g. Occluder.parked_car(x, y)
    lighting: Lighting = DAY  # sky and sun (sim.scenario.lighting: the presets)
    road: RoadLayout = field(default_factory=RoadLayout)  # the street (MuJoCo and highway-env)
    lamps: tuple[StreetLamp, ...] = ()  # street lamps on their masts (sim.scenario.lamps)


@dataclass(frozen=True)
class Scenario:
    """One run's complete description."""

    name: str
    pedestrian: PedestrianSpec
    robot: RobotSpec = field(default_factory=RobotSpec)
    scene: SceneSpec = field(default_factory=SceneSpec)
    family: str = ""
    case: Case | None = None  # the case the scenario is built to show, if any
    duration: float = presets.DURATION_S  # s
    dt: float = 1.0 / presets.FPS  # s per frame
    horizon: float = presets.HORIZON_S  # s, the warning horizon
    seed: int = 0
    # The other people in the street. `pedestrian` is the scripted one: in a collision
    # family the person whose path meets the robot; the warnings are judged against them.
    bystanders: tuple[PedestrianSpec, ...] = ()
    # People moved together by a crowd model, after the scripted person and bystanders.
    crowd: Crowd | None = None

    def __post_init__(self) -> None:
        for name in ("duration", "dt", "horizon"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"scenario {self.name!r}: {name} must be positive, got {value}")
        sensor = self.robot.camera.sensor
        if sensor is not None:
            sensor.check_frame_rate(self.dt)
        names = [person_name(p, k) for k, p in enumerate(self.people)]
        if len(set(names)) != len(names):
            raise ValueError(f"scenario {self.name!r}: two people share a name in {names}")

    @property
    def frames(self) -> int:
        return int(round(self.duration / self.dt))

    @property
    def people(self) -> tuple[PedestrianSpec, ...]:
        """Everyone in the street: the scripted person, the bystanders, the crowd."""
        return (*self.planned, *(self.crowd.members() if self.crowd else ()))

    @property
    def planned(self) -> tuple[PedestrianSpec, ...]:
        """The people who walk a plan of their own (their walker's Track), the scripted
        person first; the crowd's members move together instead."""
        return (self.pedestrian, *self.bystanders)


SCRIPTED = "ped"  # the scripted person's name when the scenario gives none


def person_name(person: PedestrianSpec, index: int) -> str:
    """A person's name: the scenario's, else "ped" for the scripted person (index 0) and
    "ped{index}" for the others."""
    return person.name or (SCRIPTED if index == 0 else f"{SCRIPTED}{index}")


def scenario_text(s: Scenario) -> str:
    """The text a scenario's identity digests: sweep run ids (and so their seeds), Euro NCAP
    and closed-loop run ids. Its repr, the walker written as its identity (Walker.identity)
    and the scene as its own (scene_identity): any change of the scenario is another run,
    and a new layout of the records is not."""
    written: dict[str, object] = {
        "robot": _Written(robot_identity(s.robot)),
        "pedestrian": _Written(person_identity(s.pedestrian)),
        "bystanders": tuple(_Written(person_identity(p)) for p in s.bystanders),
        "scene": _Written(scene_identity(s.scene)),
    }
    unset = {"bystanders": not s.bystanders, "crowd": s.crowd is None}
    parts = [f"{f.name}={written.get(f.name, getattr(s, f.name))!r}" for f in fields(s)
             if not unset.get(f.name, False)]  # fmt: skip
    # (A field added since identities were first written shows only when it is set, so a
    # scenario that does not use it keeps its identity.)
    return f"Scenario({', '.join(parts)})"


def person_identity(person: PedestrianSpec) -> str:
    """A person as identities have always written them: the walker as its identity, the
    name (added since) only when it is set."""
    text = repr(replace(person, behaviour=_Written(person.behaviour.identity())))
    return text.removesuffix(", name='')") + ")" if not person.name else text


def robot_identity(robot: RobotSpec) -> str:
    """The robot as identities have always written it: its camera's sensor (added since)
    only when it is a real one, so an ideal camera's runs keep their ids."""
    camera = repr(robot.camera)
    if robot.camera.sensor is None:
        camera = camera.removesuffix(", sensor=None)") + ")"
    text = repr(replace(robot, camera=_Written(camera)))
    return text.removesuffix(", headlamps=None)") + ")" if robot.headlamps is None else text


def scene_identity(scene: SceneSpec) -> str:
    """The scene as run identities have always written it: the sun's azimuth, elevation and
    shadows where a Lighting now stands, for every lighting that is a preset with its sun
    (perhaps moved); any other lighting in full."""
    light = scene.lighting
    preset = PRESETS.get(light.name)
    sun = light.sun
    if (
        preset is None
        or light.name not in SUN_ONLY_IDENTITY
        or light != preset.with_sun(sun.azimuth_deg, sun.elevation_deg)
    ):
        text = repr(replace(scene, lighting=_Written(lighting_identity(light))))
        return text.removesuffix(", lamps=())") + ")" if not scene.lamps else text
    lamps = f", lamps={scene.lamps!r}" if scene.lamps else ""
    return (
        f"SceneSpec(occluders={scene.occluders!r}, sun_azimuth_deg={sun.azimuth_deg!r}, "
        f"sun_elevation_deg={sun.elevation_deg!r}, shadows={sun.shadows!r}, road={scene.road!r}"
        f"{lamps})"
    )


def lighting_identity(light: Lighting) -> str:
    """A lighting as identities have always written it: its sky box and night flag (added
    since) only when they are not a day's."""
    default = Lighting(light.name, light.sun)
    text = repr(light)
    suffix = f", sky_box={default.sky_box!r}, night=False)"
    return text.removesuffix(suffix) + ")" if text.endswith(suffix) else text


@dataclass(frozen=True)
class _Written:
    """A text that reprs as itself (a walker's identity inside the scenario's repr)."""

    text: str

    def __repr__(self) -> str:
        return self.text
