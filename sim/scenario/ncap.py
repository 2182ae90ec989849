"""The Euro NCAP 2026 pedestrian test grid at car scale, as plain data and scenarios.

`scenarios/ncap/protocol.toml` holds the protocol's figures (the load cases, car speeds,
target speeds and impact locations of the rating calculator's template; acceleration
distances, the steady-state start and the tolerances of the test protocol) and
`scenarios/ncap/car.toml` the car under test (its brake, its body's pitch, the pipelines
it runs, how many jittered runs each grid point gets). Both load into frozen records,
checked when read: a mistake names the file, the field and the value.

A grid point (test, function row, car speed, impact location) becomes one Scenario per
draw: each draw takes the car's speed, both lateral paths, the target's speed and the
impact point uniformly within the protocol's tolerances, and the families' placements
(sim.scenario.families) put the target so that, unbraked, the car's front meets it at
the drawn impact point exactly `steady_state_ttc + acquisition` seconds after the start.
Crossing targets stand on the pavement at `street.start` from the car's centre line and
walk in over their acceleration distance; a CPLA target walks ahead at its speed.

Night tests (`lighting = "night"`, the calculator's night matrices) run the same
placements in the dark: the car's low beams on (car.toml [headlamps]) and the street
lamps of the published night road the test names (protocol.toml [lamps.NAME]: along the
road from the crossing line, across from the car's path), or none.
"""

from __future__ import annotations

import hashlib
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from sim.scenario.families import (
    CAR,
    Crossing,
    Longitudinal,
    Side,
    crossing_line_x,
    mannequin,
    parked_cars_around,
    place_crossing,
    place_longitudinal,
)
from sim.scenario.lamps import HEADLAMPS, LAMP_HEIGHT, Headlamps, StreetLamp, lamp_on_road
from sim.scenario.lighting import PRESETS as LIGHTING
from sim.scenario.sensor_table import read_sensor
from sim.scenario.spec import (
    BodyPitch,
    RobotSpec,
    Scenario,
    SceneSpec,
    scenario_text,
)
from sim.scenario.toml_table import FieldError, TomlTable, read_toml
from sim.scenario.walkers import RailWalker
from sim.sensor.spec import IDEAL, SensorSpec

PROTOCOL_FILE = Path("scenarios/ncap/protocol.toml")
CAR_FILE = Path("scenarios/ncap/car.toml")
KINDS = ("crossing", "longitudinal")
FUNCTIONS = ("AEB", "FCW")
KMH = 1 / 3.6  # m/s per km/h
DOC = "scenarios/README.md"


@dataclass(frozen=True)
class Timing:
    steady_state_ttc: float  # s, the protocol's T0
    acquisition: float  # s before T0 the run starts
    after_impact: float  # s the run may go on past the nominal impact
    fps: float

    @property
    def impact_time(self) -> float:
        """s from the start to the nominal (unbraked) impact."""
        return self.steady_state_ttc + self.acquisition


@dataclass(frozen=True)
class Tolerances:
    """Each run's deviations are drawn uniformly inside these (protocol test conduct)."""

    vut_speed_kmh: tuple[float, float]  # (low, high) added to the test speed
    vut_lateral: float  # m, +-
    target_speed_kmh: float  # +-
    target_lateral: float  # m, +-
    impact_point: float  # m, +- across the car's width


@dataclass(frozen=True)
class Street:
    road_length: float
    start: float  # m from the car's centre line to a crossing target's standing point
    parked_cars_y: float
    parked_cars_gap: float


@dataclass(frozen=True)
class Row:
    """One function band of a test's matrix: its car speeds and standard-range impacts."""

    function: str  # "AEB" (judged on impact speed) or "FCW" (on the warning's TTC)
    speeds_kmh: tuple[float, ...]
    standard: tuple[float, ...]  # impact locations of the standard range
    quick_speeds_kmh: tuple[float, ...]
    quick_impacts: tuple[float, ...]


@dataclass(frozen=True)
class NcapTest:
    key: str  # "cpna"
    load_case: str  # the calculator's matrix, "CPNA day"
    kind: str  # "crossing" or "longitudinal"
    side: str | None  # crossing: "near" or "far"
    body: str  # "adult" or "child"
    target_speed_kmh: float
    acceleration_distance: float
    impact_locations: tuple[float, ...]  # the matrix's columns, left to right
    rows: tuple[Row, ...]
    lighting: str = "day"  # a preset of sim.scenario.lighting ("night": the night matrices)
    lamps: str | None = None  # a [lamps.NAME] layout of the protocol file, or no lamps

    @property
    def speed_range(self) -> tuple[float, float]:
        speeds = [v for row in self.rows for v in row.speeds_kmh]
        return min(speeds), max(speeds)


@dataclass(frozen=True)
class LampLayout:
    """A night road's street lamps: along the road from the crossing line (m), across from
    the car's path (m, positive: to its left), and whether each is lit."""

    name: str
    along: tuple[float, ...]
    across: tuple[float, ...]
    on: tuple[bool, ...]
    height: float = LAMP_HEIGHT

    def lamps(self, x_line: float) -> tuple[StreetLamp, ...]:
        return tuple(
            StreetLamp(x_line + a, c, self.height, on=o)
            for a, c, o in zip(self.along, self.across, self.on, strict=True)
        )


@dataclass(frozen=True)
class NearMisses:
    files: tuple[Path, ...]
    speeds_kmh: tuple[float, ...]
    seeds: int
    quick_speeds_kmh: tuple[float, ...]
    quick_seeds: int


@dataclass(frozen=True)
class Protocol:
    path: Path
    name: str
    protocol: str  # which protocol version the figures are from
    calculator: str  # the calculator's pin ("euroncap-rating-2026==5.4.9")
    timing: Timing
    tolerances: Tolerances
    street: Street
    tests: dict[str, NcapTest]
    near_misses: NearMisses
    lamps: dict[str, LampLayout] = field(default_factory=dict)


@dataclass(frozen=True)
class CarSpec:
    """The car under test: brake, pitch, pipelines and runs per grid point (car.toml)."""

    path: Path
    name: str
    max_speed: float
    seeds: int
    quick_seeds: int
    verification_seeds: int
    primary: str
    policies: tuple[str, ...]
    brake_delay: float
    jerk: float
    deceleration: float
    latency_ms: float | None
    pitch: BodyPitch
    # The camera's sensor (sim.sensor; None: the ideal camera, the renderer's frames).
    sensor: SensorSpec | None = None
    headlamps: Headlamps | None = None  # its beam at night (sim.scenario.lamps)

    @property
    def camera_name(self) -> str:
        return IDEAL if self.sensor is None else self.sensor.name


@dataclass(frozen=True)
class GridPoint:
    """One cell of a calculator matrix: test, function row, car speed, impact location."""

    test: str
    function: str
    speed_kmh: float
    impact: float  # fraction of the car's width

    @property
    def id(self) -> str:
        return f"{self.test}/{self.function}/{self.speed_kmh:g}kmh/{round(self.impact * 100):d}"


@dataclass(frozen=True)
class Draw:
    """One run's deviations from the nominal test, inside the tolerances."""

    vut_speed_kmh: float  # added to the test speed
    vut_lateral: float  # m, + to the car's left
    target_speed_kmh: float  # added to the target's speed
    target_lateral: float  # m
    impact_point: float  # m across the width

    @classmethod
    def nominal(cls) -> Draw:
        return cls(0.0, 0.0, 0.0, 0.0, 0.0)


# -- reading the files -----------------------------------------------------------------


def _texts(t: TomlTable, key: str) -> tuple[str, ...]:
    value = t.raw(key, expected="a non-empty list of strings")
    if not (isinstance(value, list) and value and all(isinstance(v, str) for v in value)):
        raise t.error(key, value, "must be a non-empty list of strings")
    return tuple(value)


def _numbers(
    t: TomlTable, key: str, low: float, high: float, unit: str, nonempty: bool = True
) -> tuple[float, ...]:
    values = t.numbers(key, nonempty=nonempty, unit=unit)
    for v in values:
        if not low <= v <= high:
            raise t.error(key, values, f"values must lie in [{low:g}, {high:g}] {unit}")
    return tuple(float(v) for v in values)


def _row(t: TomlTable, impacts: tuple[float, ...]) -> Row:
    function = t.text("function", choices=FUNCTIONS)
    speeds = _numbers(t, "speeds_kmh", 5.0, 130.0, "km/h")
    standard = _numbers(t, "standard", 0.0, 1.0, "")
    # The quick grid may leave a row out (empty lists).
    quick_speeds = _numbers(t, "quick_speeds_kmh", 5.0, 130.0, "km/h", nonempty=False)
    quick_impacts = _numbers(t, "quick_impacts", 0.0, 1.0, "", nonempty=False)
    for key, values, allowed in (
        ("standard", standard, impacts),
        ("quick_impacts", quick_impacts, standard),
        ("quick_speeds_kmh", quick_speeds, speeds),
    ):
        if not set(values) <= set(allowed):
            raise t.error(key, list(values), f"must be among {list(allowed)}")
    t.done()
    return Row(function, speeds, standard, quick_speeds, quick_impacts)


def _test(key: str, t: TomlTable, layouts: dict[str, LampLayout]) -> NcapTest:
    kind = t.text("kind", choices=KINDS)
    lighting = t.text("lighting", "day", tuple(LIGHTING))
    lamps = t.text("lamps", None, tuple(layouts)) if layouts else t.text("lamps", None)
    if lamps is not None and lamps not in layouts:
        raise t.error("lamps", lamps, "the protocol file has no [lamps] layouts")
    if lamps is not None and not LIGHTING[lighting].night:
        raise t.error("lamps", lamps, f"street lamps light a night test (lighting = {lighting!r})")
    side = t.text("side", choices=tuple(s.value for s in Side)) if kind == "crossing" else None
    impacts = _numbers(t, "impact_locations", 0.0, 1.0, "")
    rows = tuple(_row(r, impacts) for r in t.tables("rows"))
    if not rows:
        raise t.error("rows", [], "a test needs at least one [[rows]] table")
    test = NcapTest(
        key=key,
        load_case=t.text("load_case"),
        kind=kind,
        side=side,
        body=t.text("body", choices=("adult", "child")),
        target_speed_kmh=t.number("target_speed_kmh", positive=True, high=30.0, unit="km/h"),
        acceleration_distance=t.number("acceleration_distance", low=0.0, high=10.0, unit="m"),
        impact_locations=impacts,
        rows=rows,
        lighting=lighting,
        lamps=lamps,
    )
    t.done()
    return test


def _layouts(top: TomlTable, half_width: float) -> dict[str, LampLayout]:
    """[lamps]: the night roads' lamp layouts, each mast beside the road."""
    if not top.has("lamps"):
        return {}
    t = top.table("lamps")
    height = t.number("height", LAMP_HEIGHT, low=2.0, high=20.0, unit="m")
    out = {}
    for name in t.free_keys():
        if name == "height":
            continue
        lt = t.table(name)
        along = _numbers(lt, "along", -500.0, 500.0, "m")
        across = _numbers(lt, "across", -50.0, 50.0, "m")
        on = lt.raw("on", [True] * len(along), "a list of true/false")
        if not (isinstance(on, list) and all(isinstance(v, bool) for v in on)):
            raise lt.error("on", on, "must be a list of true/false")
        for key, values in (("across", across), ("on", on)):
            if len(values) != len(along):
                raise lt.error(key, values, f"needs one value per lamp ({len(along)}, as along)")
        for k, y in enumerate(across):
            if lamp_on_road(StreetLamp(0.0, y), (-half_width, half_width)):
                raise lt.error(
                    "across", list(across), f"lamp {k} at {y:g} m would stand on the road "
                    f"(its edges at +-{half_width:g} m from the car's path)"
                )  # fmt: skip
        lt.done()
        out[name] = LampLayout(name, along, across, tuple(on), height)
    t.done()
    return out


def load_protocol(path: Path | str = PROTOCOL_FILE) -> Protocol:
    """Read and check the protocol grid file."""
    path = Path(path)
    _, data = read_toml(path, "NCAP protocol file")
    top = TomlTable(path, "", data, DOC)
    tim = top.table("timing")
    timing = Timing(
        steady_state_ttc=tim.number("steady_state_ttc", positive=True, high=10.0, unit="s"),
        acquisition=tim.number("acquisition", low=0.0, high=5.0, unit="s"),
        after_impact=tim.number("after_impact", positive=True, high=5.0, unit="s"),
        fps=tim.number("fps", low=5.0, high=60.0, unit="frames/s"),
    )
    tim.done()
    tol = top.table("tolerances")
    vut = _numbers(tol, "vut_speed_kmh", -5.0, 5.0, "km/h")
    if len(vut) != 2 or vut[0] > vut[1]:
        raise tol.error("vut_speed_kmh", list(vut), "must be [low, high] with low <= high")
    tolerances = Tolerances(
        vut_speed_kmh=(vut[0], vut[1]),
        vut_lateral=tol.number("vut_lateral", low=0.0, high=0.5, unit="m"),
        target_speed_kmh=tol.number("target_speed_kmh", low=0.0, high=2.0, unit="km/h"),
        target_lateral=tol.number("target_lateral", low=0.0, high=0.5, unit="m"),
        impact_point=tol.number("impact_point", low=0.0, high=0.5, unit="m"),
    )
    tol.done()
    st = top.table("street")
    street = Street(
        road_length=st.number("road_length", low=100.0, high=2000.0, unit="m"),
        start=st.number("start", positive=True, high=15.0, unit="m"),
        parked_cars_y=st.number("parked_cars_y", low=-10.0, high=10.0, unit="m"),
        parked_cars_gap=st.number("parked_cars_gap", positive=True, high=5.0, unit="m"),
    )
    st.done()
    layouts = _layouts(top, CAR.road.half_width)
    tests_table = top.table("tests")
    tests = {key: _test(key, tests_table.table(key), layouts) for key in tests_table.free_keys()}
    if not tests:
        raise top.error("tests", {}, "needs at least one [tests.NAME] table")
    nm = top.table("near_misses")
    files = []
    for name in _texts(nm, "files") if nm.has("files") else []:
        file = (path.parent / name).resolve()
        if not file.is_file():
            raise nm.error("files", name, "no such scenario file")
        files.append(file)
    near = NearMisses(
        files=tuple(files),
        speeds_kmh=_numbers(nm, "speeds_kmh", 5.0, 130.0, "km/h") if files else (),
        seeds=nm.integer("seeds", 1, low=1, high=100),
        quick_speeds_kmh=_numbers(nm, "quick_speeds_kmh", 5.0, 130.0, "km/h") if files else (),
        quick_seeds=nm.integer("quick_seeds", 1, low=1, high=100),
    )
    nm.done()
    protocol = Protocol(
        path=path,
        name=top.slug("name"),
        protocol=top.text("protocol"),
        calculator=top.text("calculator"),
        timing=timing,
        tolerances=tolerances,
        street=street,
        tests=tests,
        near_misses=near,
        lamps=layouts,
    )
    top.done()
    return protocol


def load_car(path: Path | str = CAR_FILE) -> CarSpec:
    """Read and check the car file."""
    path = Path(path)
    _, data = read_toml(path, "NCAP car file")
    top = TomlTable(path, "", data, DOC)
    aeb, pitch, camera = top.table("aeb"), top.table("pitch"), top.table("camera")
    policies = _texts(top, "policies")
    primary = top.text("primary")
    for policy in (primary, *policies):
        if policy.count("/") != 1:
            raise top.error("policies", policy, "a policy is PREDICTOR/MODE, e.g. rules/ground")
    if primary not in policies:
        raise top.error("primary", primary, "must be one of the policies")
    car = CarSpec(
        path=path,
        name=top.slug("name"),
        max_speed=top.number("max_speed", positive=True, high=40.0, unit="m/s"),
        seeds=top.integer("seeds", low=1, high=100),
        quick_seeds=top.integer("quick_seeds", low=1, high=100),
        verification_seeds=top.integer("verification_seeds", 1, low=0, high=10),
        primary=primary,
        policies=policies,
        brake_delay=aeb.number("brake_delay", low=0.0, high=2.0, unit="s"),
        jerk=aeb.number("jerk", positive=True, high=200.0, unit="m/s^3"),
        deceleration=aeb.number("deceleration", positive=True, high=15.0, unit="m/s^2"),
        latency_ms=aeb.number("latency_ms", None, low=0.0, high=2000.0, unit="ms"),
        pitch=BodyPitch(
            gain=pitch.number("gain", low=0.0, high=2.0, unit="deg per m/s^2"),
            frequency=pitch.number("frequency", low=0.2, high=10.0, unit="Hz"),
            damping=pitch.number("damping", low=0.05, high=5.0),
        ),
        sensor=read_sensor(camera, None),
        headlamps=_car_headlamps(top),
    )
    aeb.done()
    pitch.done()
    camera.done()
    top.done()
    return car


def _car_headlamps(top: TomlTable) -> Headlamps | None:
    """[headlamps] beam = "low-beam" (sim.scenario.lamps) or "none"; height in m."""
    if not top.has("headlamps"):
        return None
    t = top.table("headlamps")
    name = t.text("beam", choices=("none", *HEADLAMPS))
    height = t.number("height", 0.65, low=0.3, high=1.5, unit="m")
    t.done()
    return None if name == "none" else replace(HEADLAMPS[name], height=height)


# -- the grid --------------------------------------------------------------------------


def grid(
    protocol: Protocol, tests: list[str], quick: bool = False, speeds: list[float] | None = None
) -> list[GridPoint]:
    """The grid points of `tests`, standard range, in matrix order (`speeds`: only those)."""
    points = []
    for key in tests:
        test = protocol.tests[key]
        for row in test.rows:
            row_speeds = row.quick_speeds_kmh if quick else row.speeds_kmh
            impacts = row.quick_impacts if quick else row.standard
            for v in row_speeds:
                if speeds is not None and v not in speeds:
                    continue
                points.extend(GridPoint(key, row.function, v, p) for p in impacts)
    return points


def draw(tolerances: Tolerances, rng: np.random.Generator) -> Draw:
    """One run's deviations, uniform within the tolerances."""
    t = tolerances
    return Draw(
        vut_speed_kmh=float(rng.uniform(*t.vut_speed_kmh)),
        vut_lateral=float(rng.uniform(-t.vut_lateral, t.vut_lateral)),
        target_speed_kmh=float(rng.uniform(-t.target_speed_kmh, t.target_speed_kmh)),
        target_lateral=float(rng.uniform(-t.target_lateral, t.target_lateral)),
        impact_point=float(rng.uniform(-t.impact_point, t.impact_point)),
    )


def draw_for(tolerances: Tolerances, point_id: str, index: int) -> Draw:
    """The `index`-th draw of a grid point: the same point and index, the same run."""
    rng = np.random.default_rng([zlib.crc32(point_id.encode()), index])
    return draw(tolerances, rng)


def car_robot(car: CarSpec, speed: float) -> RobotSpec:
    """The car scale's robot at `speed` m/s with this car's limits and pitch."""
    if not 0 <= speed <= car.max_speed:
        raise ValueError(f"car speed {speed:.2f} m/s beyond the car's {car.max_speed:g} m/s")
    return replace(
        CAR.robot,
        speed=speed,
        max_speed=car.max_speed,
        max_deceleration=car.deceleration,
        pitch=car.pitch,
        camera=replace(CAR.robot.camera, sensor=car.sensor),
    )


def scenario_for(
    protocol: Protocol, car: CarSpec, point: GridPoint, d: Draw, seed: int = 0
) -> Scenario:
    """The run of `point` with deviations `d` (see the module docstring)."""
    test = protocol.tests[point.test]
    robot = car_robot(car, (point.speed_kmh + d.vut_speed_kmh) * KMH)
    road = replace(CAR.road, length=protocol.street.road_length, crosswalk_x=None)
    speed = (test.target_speed_kmh + d.target_speed_kmh) * KMH
    looks = mannequin(test.body, "default")
    behaviour = RailWalker(acceleration_distance=test.acceleration_distance)
    timing = protocol.timing
    impact_time = timing.impact_time
    # The car's own lateral deviation moves the target the other way relative to it.
    across = (d.impact_point - d.vut_lateral) / robot.width
    occluders: tuple = ()
    if test.kind == "crossing":
        side = Side(test.side)
        impact = point.impact + across * (1.0 if side is Side.NEAR else -1.0)
        entering = robot.width / 2
        y_impact_from_edge = impact * robot.width  # from the entering edge, inward
        approach = protocol.street.start - entering + y_impact_from_edge
        c = Crossing(side=side, impact_point=impact, impact_time=impact_time, approach=approach)
        pedestrian = place_crossing(c, robot, road, speed, looks, behaviour=behaviour)
        # The target's deviation from its path is along the car's axis for a crossing.
        pedestrian = replace(pedestrian, x=pedestrian.x + d.target_lateral)
        if pedestrian.anchor is not None:
            a = pedestrian.anchor
            pedestrian = replace(pedestrian, anchor=replace(a, x=a.x + d.target_lateral))
        if test.body == "child" and test.side == "near":
            x_line = crossing_line_x(robot, pedestrian.footprint, impact_time, 4.0)
            occluders = parked_cars_around(
                x_line, protocol.street.parked_cars_y, protocol.street.parked_cars_gap
            )
    else:
        impact = point.impact + across + d.target_lateral / robot.width
        c2 = Longitudinal(impact_point=impact, impact_time=impact_time)
        pedestrian = place_longitudinal(c2, robot, speed, looks, behaviour=behaviour)
    scene = SceneSpec(occluders=occluders, road=road)
    if test.lighting != "day":
        robot, scene = _lit(protocol, car, test, robot, scene, pedestrian.anchor)
    scenario = Scenario(
        name=point.id,
        pedestrian=pedestrian,
        robot=robot,
        scene=scene,
        family=f"ncap-{point.test}",
        duration=impact_time + timing.after_impact,
        dt=1.0 / timing.fps,
        horizon=CAR.horizon,
        seed=seed,
    )
    _check_road(protocol, scenario)
    return scenario


def _lit(
    protocol: Protocol,
    car: CarSpec,
    test: NcapTest,
    robot: RobotSpec,
    scene: SceneSpec,
    anchor: Any,
) -> tuple[RobotSpec, SceneSpec]:
    """A test's lighting: its preset, the car's headlamps at night, its road's lamps."""
    lighting = LIGHTING[test.lighting]
    scene = replace(scene, lighting=lighting)
    if lighting.night:
        if car.headlamps is None:
            raise FieldError(
                car.path, "headlamps.beam", "none",
                f"the night test {test.key} needs the car's headlamps: beam = "
                f"{' or '.join(map(repr, HEADLAMPS))}",
            )  # fmt: skip
        robot = replace(robot, headlamps=car.headlamps)
    if test.lamps is not None:
        if anchor is None:
            why = "lamps are laid out from a crossing's line: a crossing test only"
            raise FieldError(protocol.path, f"tests.{test.key}.lamps", test.lamps, why)
        scene = replace(scene, lamps=protocol.lamps[test.lamps].lamps(anchor.x))
    return robot, scene


def _check_road(protocol: Protocol, s: Scenario) -> None:
    end = s.robot.speed * s.duration + s.robot.length / 2
    if end > s.scene.road.length / 2:
        raise FieldError(
            protocol.path,
            "street.road_length",
            protocol.street.road_length,
            f"the car at {s.robot.speed * 3.6:.0f} km/h would drive off the road's end",
        )


def scenario_digest(s: Scenario) -> str:
    """8 hex digits of the complete scenario (a run's identity, as sweeps use)."""
    return hashlib.sha1(scenario_text(replace(s, name="", seed=0)).encode()).hexdigest()[:8]


def describe(protocol: Protocol, car: CarSpec) -> dict[str, Any]:
    """The figures a report states: protocol version, tolerances, timing, AEB, pitch."""
    return {
        "protocol": protocol.protocol,
        "calculator": protocol.calculator,
        "timing": protocol.timing,
        "tolerances": protocol.tolerances,
        "car": car,
    }
