"""Scenario files (scenarios/**/*.toml): load, validate, build Scenarios, sample sweeps.

One format serves a single scenario (the eight cases and standing still) and a family
(a base scenario plus the parameter ranges a sweep samples, in the spirit of
OpenSCENARIO's parameter value distributions). scenarios/README.md documents every key.
Everything is checked when the file is read, and again for every sampled combination:
a mistake is a UserError naming the file, the dotted field and the bad value, so a sweep
never dies hours in on a typo.
"""

from __future__ import annotations

import copy
import math
import zlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from monopic.cases import Case
from monopic.errors import UserError
from sim.scenario import presets
from sim.scenario.cases import PLACEMENT_FIELDS, CasePlacement
from sim.scenario.crowd import crowd_from_table
from sim.scenario.crowd_motion import capacity_problem
from sim.scenario.families import (
    BODIES,
    CLOTHING,
    HESITATE_SPEED,
    HESITATE_TIME,
    PAVEMENT_FROM_KERB,
    SCALES,
    Along,
    Crossing,
    Longitudinal,
    Pavement,
    PlacementError,
    Scale,
    Side,
    Then,
    TurnIn,
    crossing_line_x,
    mannequin,
    parked_cars_around,
    place_crossing,
    place_longitudinal,
    place_pavement,
    place_turn_in,
    street_bounds,
)
from sim.scenario.lamps import (
    HEADLAMPS,
    LAMP_HEIGHT,
    LAMP_INTENSITY_CD,
    Headlamps,
    StreetLamp,
    lamp_on_road,
)
from sim.scenario.lighting import FILE_DEFAULT, Lighting
from sim.scenario.lighting import PRESETS as LIGHTING
from sim.scenario.path import pedestrian_path
from sim.scenario.people import (
    parked_car_contact,
    parked_car_text,
    planned_path,
    start_overlap,
)
from sim.scenario.replays import REPLAY_KEY, expand_replay, replay_person, replay_street_problem
from sim.scenario.sensor_table import read_sensor
from sim.scenario.spec import (
    BodyPitch,
    CameraSpec,
    Leg,
    Occluder,
    PedestrianSpec,
    RoadLayout,
    RobotSpec,
    Scenario,
    SceneSpec,
    person_name,
)
from sim.scenario.toml_table import MISSING, FieldError, TomlTable, read_toml, show
from sim.scenario.walkers import ReplayWalker, Walker, walker_from_table
from sim.sensor.spec import SensorSpecError

KINDS = ("case", "collision", "near-miss")
PATH_KINDS = ("case", "crossing", "longitudinal", "turn-in", "explicit", "pavement")
SAMPLING = ("grid", "random")
MAX_GRID_RUNS = 100_000


ScenarioFileError = FieldError  # the name callers of this module know

# Top-level keys by which a scenario file and a sweep spec tell themselves apart, so that
# one given for the other is named for what it is, not for its first unknown key.
SCENARIO_FILE_KEYS = ("path", "pedestrian", "pedestrians", "people", "replay", "robot", "scene",
                      "sweep", "family", "kind", "scale", "duration", "fps", "horizon",
                      "seed")  # fmt: skip
SWEEP_SPEC_KEY = "include"


def is_scenario_file(data: Mapping[str, Any]) -> bool:
    """The data of a scenario file (it has a scenario's tables and no [[include]])."""
    return SWEEP_SPEC_KEY not in data and any(k in data for k in SCENARIO_FILE_KEYS)


def is_sweep_spec(data: Mapping[str, Any]) -> bool:
    """The data of a sweep or dataset spec (it has [[include]] and no [path])."""
    return SWEEP_SPEC_KEY in data and "path" not in data


# -- sweeps ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Values:
    """A set of values: a grid axis, or a uniform choice when sampling at random."""

    values: tuple[Any, ...]

    def grid(self) -> tuple[Any, ...]:
        return self.values

    def sample(self, rng: np.random.Generator) -> Any:
        return self.values[int(rng.integers(len(self.values)))]


@dataclass(frozen=True)
class Range:
    """A numeric range: `steps` evenly spaced values, or uniform at random without steps."""

    low: float
    high: float
    steps: int | None = None

    def grid(self) -> tuple[float, ...]:
        if self.steps is None:
            raise ValueError("a range needs steps in a grid sweep")
        return tuple(round(float(v), 6) for v in np.linspace(self.low, self.high, self.steps))

    def sample(self, rng: np.random.Generator) -> float:
        if self.steps is not None:
            grid = self.grid()
            return grid[int(rng.integers(len(grid)))]
        return round(float(rng.uniform(self.low, self.high)), 4)


Distribution = Values | Range


@dataclass(frozen=True)
class Sweep:
    """How a family is sampled: a grid over all parameters, or `runs` seeded random draws."""

    sampling: str
    parameters: dict[str, Distribution]
    runs: int = 1
    seed: int = 0


def parse_distribution(table: TomlTable, key: str, need_steps: bool = False) -> Distribution:
    """A parameter distribution: a list of values or {min, max, steps?} (steps: in a grid)."""
    value = table.raw(key)
    if isinstance(value, list):
        if not value:
            raise table.error(key, value, "needs at least one value")
        kinds = {type(v) for v in value}
        if (
            any(isinstance(v, dict | list) for v in value)
            or len(kinds - {int, float}) > 1
            or (kinds & {int, float} and kinds - {int, float})
        ):
            raise table.error(key, value, "values must be numbers, strings or booleans of one type")
        return Values(tuple(value))
    if isinstance(value, dict):
        inner = table.table(key)
        low, high = inner.number("min"), inner.number("max")
        steps = inner.integer("steps", None, low=1)
        inner.done()
        if high < low:
            raise table.error(key, value, "max must be >= min")
        if need_steps and steps is None:
            raise table.error(key, value, "a range needs steps in a grid")
        return Range(low, high, steps)
    raise table.error(key, value, "must be a list of values or a table {min, max, steps}")


def parse_parameters(table: TomlTable, need_steps: bool = False) -> dict[str, Distribution]:
    """The `parameters` sub-table: dotted keys of a scenario file, each a distribution."""
    params = table.table("parameters")
    return {key: parse_distribution(params, key, need_steps) for key in params.free_keys()}


def parse_sweep(table: TomlTable) -> Sweep:
    sampling = table.text("sampling", "grid", SAMPLING)
    runs = table.integer("runs", 1, low=1)
    seed = table.integer("seed", 0)
    parameters = parse_parameters(table, need_steps=sampling == "grid")
    table.done()
    return Sweep(sampling, parameters, runs, seed)


def expand(sweep: Sweep | None, family: str) -> Iterator[dict[str, Any]]:
    """The parameter combinations of a sweep (grid order, or seeded random draws).

    Random draws depend only on (seed, family name, draw number), so adding a family to
    a sweep or reordering files never changes another family's runs.
    """
    if sweep is None or not sweep.parameters:
        yield {}
        return
    keys = list(sweep.parameters)
    if sweep.sampling == "grid":
        axes = [sweep.parameters[k].grid() for k in keys]
        total = math.prod(len(a) for a in axes)
        if total > MAX_GRID_RUNS:
            raise ValueError(f"a grid of {total} runs is too large (max {MAX_GRID_RUNS})")
        for combo in _product(axes):
            yield dict(zip(keys, combo, strict=True))
        return
    for k in range(sweep.runs):
        rng = np.random.default_rng([sweep.seed, _stable_hash(family), k])
        yield {key: sweep.parameters[key].sample(rng) for key in keys}


def _product(axes: list[tuple[Any, ...]]) -> Iterator[tuple[Any, ...]]:
    if not axes:
        yield ()
        return
    for head in axes[0]:
        for rest in _product(axes[1:]):
            yield (head, *rest)


def _stable_hash(text: str) -> int:
    """A process-independent 32-bit hash (Python's hash() is salted per process)."""
    return zlib.crc32(text.encode())


# -- the file -------------------------------------------------------------------------


@dataclass(frozen=True)
class ScenarioFile:
    """A loaded, validated scenario file: its base scenario and its sweep."""

    path: Path
    name: str
    family: str
    kind: str
    scale: Scale
    description: str
    data: dict[str, Any] = field(repr=False)
    sweep: Sweep | None
    base: Scenario

    def scenario(self, params: Mapping[str, Any], name: str, seed: int | None = None) -> Scenario:
        """The scenario with `params` (dotted keys) set; errors name the file and field.

        `seed` replaces the file's (or a swept) seed; None keeps it."""
        data, origins = applied(self.path, self.data, params)
        try:
            scenario = build(self.path, data, origins)
        except ScenarioFileError as err:
            if not params:
                raise
            shown = ", ".join(f"{k} = {show(v)}" for k, v in params.items())
            raise ScenarioFileError(
                err.file, err.field, err.value, f"{err.reason} (with sweep values {shown})"
            ) from None
        return replace(scenario, name=name, seed=scenario.seed if seed is None else seed)

    def with_given(self, given: Sequence[Given], name: str | None = None) -> Scenario:
        """The scenario with values given on the command line, checked as the file's own.

        An option that cannot apply to this file (given_problem) or a value the file's
        checks refuse is one line naming the options, then the file's field and reason."""
        for g in given:
            problem = given_problem(self.data, g)
            if problem is not None:
                raise UserError(f"{g.text}: {self.path}: {problem}")
        try:
            data, origins = applied(self.path, self.data, {g.key: g.value for g in given})
            scenario = build(self.path, data, origins)
        except ScenarioFileError as err:
            raise UserError(f"{' '.join(g.text for g in given)}: {err}") from None
        return replace(scenario, name=name or self.name)

    def runs(self) -> Iterator[dict[str, Any]]:
        return expand(self.sweep, self.name)


def with_values(
    data: Mapping[str, Any], params: Mapping[str, Any], file: Path | str = "<data>"
) -> dict[str, Any]:
    """A deep copy of a file's data with dotted keys set (tables created as needed).

    A person's key has their index in the file's people (`pedestrians.1.speed`; 0 is the
    scripted person, wherever the file writes them); `pedestrian.*` and `path.*` are the
    scripted person's in either form. A person the data does not hold is a FieldError
    naming `file`, the key and how many people there are."""
    out = copy.deepcopy(dict(data))
    for key, value in params.items():
        node: Any = out
        parts = located(out, key, value, file)
        for part, inner in zip(parts[:-1], parts[1:], strict=True):
            node = node[part] if isinstance(part, int) else node.setdefault(part, {})
            if not isinstance(node, list if isinstance(inner, int) else dict):
                raise ValueError(f"{key}: {part} is not a table")
        node[parts[-1]] = value
    return out


def applied(
    path: Path, data: Mapping[str, Any], params: Mapping[str, Any]
) -> tuple[dict[str, Any], dict[int, str]]:
    """A file's data with `params` set, its people files read in first (a swept `people`
    among them) so that a key can name any person; and where each added person comes
    from (resolve_people)."""
    first = {k: v for k, v in params.items() if k == PEOPLE_KEY}
    rest = {k: v for k, v in params.items() if k != PEOPLE_KEY}
    resolved, origins = resolve_people(path, with_values(data, first, path))
    return with_values(resolved, rest, path), origins


# -- people ---------------------------------------------------------------------------

# A scenario file's people: the scripted person (person 0) is [pedestrian] with [path], or
# the first [[pedestrians]] entry when the file has neither table; the [[pedestrians]]
# entries follow, then the entries of the files the top-level `people` key names.
PEOPLE_KEY = "people"
PERSON_KEY = "pedestrians"


def listed(data: Mapping[str, Any]) -> bool:
    """Whether the scripted person is the first [[pedestrians]] entry (the file has no
    [pedestrian] and no [path] table)."""
    return "pedestrian" not in data and "path" not in data and bool(entries(data))


def entries(data: Mapping[str, Any]) -> list[Any]:
    """The [[pedestrians]] entries of a file's data (none when it has no list there)."""
    value = data.get(PERSON_KEY)
    return value if isinstance(value, list) else []


def people_names(data: Mapping[str, Any]) -> list[str]:
    """Each person's name in a file's data, by index (person_name's defaults)."""
    rows = entries(data)
    if not listed(data):
        table = data.get("pedestrian")
        rows = [table if isinstance(table, dict) else {}, *rows]
    names = []
    for k, row in enumerate(rows):
        given = row.get("name") if isinstance(row, dict) else None
        names.append(given if isinstance(given, str) and given else person_name_of(k))
    return names


def person_name_of(index: int) -> str:
    """The name of an unnamed person at `index` (spec.person_name's)."""
    return person_name(PedestrianSpec(0.0, 0.0, 0.0, 0.0), index)


def located(data: Mapping[str, Any], key: str, value: Any, file: Path | str) -> list[str | int]:
    """Where a dotted key lands in a file's data: its parts, a person's by their index."""
    parts: list[str | int] = list(key.split("."))
    is_listed = listed(data)
    if parts[0] != PERSON_KEY:
        if is_listed and parts[0] in ("pedestrian", "path"):  # the scripted person
            inner = parts[1:] if parts[0] == "pedestrian" else ["path", *parts[1:]]
            return [PERSON_KEY, 0, *inner]
        return parts
    names = people_names(data)
    if len(parts) < 3 or not str(parts[1]).isdigit():
        raise FieldError(
            file, key, value,
            f"a person's key is pedestrians.INDEX.KEY (e.g. pedestrians.1.speed; index 0 is "
            f"the scripted person; the file has {len(names)} "
            f"{'person' if len(names) == 1 else 'people'})",
        )  # fmt: skip
    index, inner = int(parts[1]), parts[2:]
    if index >= len(names):
        shown = ", ".join(f"{k} {n!r}" for k, n in enumerate(names))
        people = "person" if len(names) == 1 else "people"
        raise FieldError(
            file, key, value, f"no person {index}: the file has {len(names)} {people} ({shown})"
        )
    if is_listed:
        return [PERSON_KEY, index, *inner]
    if index > 0:
        return [PERSON_KEY, index - 1, *inner]
    return ["path", *inner[1:]] if inner[0] == "path" else ["pedestrian", *inner]


def field_of(data: Mapping[str, Any], key: str) -> str:
    """The dotted field a build names for a key: a person's key as their table is named
    (`pedestrian.speed` is `pedestrians.0.speed` in a file that lists its scripted
    person; `pedestrians.0.speed` is `pedestrian.speed` in one that does not)."""
    try:
        parts = located(data, key, None, "")
    except FieldError:
        return key
    if parts[0] == PERSON_KEY and len(parts) > 1 and isinstance(parts[1], int):
        parts = [PERSON_KEY, parts[1] + (0 if listed(data) else 1), *parts[2:]]
    return ".".join(str(p) for p in parts)


def people_files(path: Path, value: Any, field: str = PEOPLE_KEY) -> tuple[Path, ...]:
    """The people files a `people` value names: one file or a list of them, relative to
    the folder of `path` ("" names none); each must be there."""
    names = value if isinstance(value, list) else [value]
    if not all(isinstance(n, str) for n in names):
        raise FieldError(path, field, value, "must be a people file or a list of them "
                         "(relative to this file; \"\" for none)")  # fmt: skip
    out = []
    for name in names:
        if not name:
            continue
        found = Path(name) if Path(name).is_absolute() else Path(path).parent / name
        if not found.is_file():
            raise FieldError(path, field, value, f"no such people file ({found})")
        out.append(found)
    return tuple(out)


def read_people(path: Path) -> list[dict[str, Any]]:
    """The [[pedestrians]] entries of a people file (it holds those and a description)."""
    _, data = read_toml(path, "people file")
    top = TomlTable(path, "", data, "scenarios/README.md")
    top.text("description", "")
    value = top.raw(PERSON_KEY, MISSING, "[[pedestrians]] entries")
    if not (isinstance(value, list) and value and all(isinstance(v, dict) for v in value)):
        raise top.error(PERSON_KEY, value, "must be one or more [[pedestrians]] entries")
    top.done()
    return value


def resolve_people(path: Path, data: Mapping[str, Any]) -> tuple[dict[str, Any], dict[int, str]]:
    """A file's data with the entries of the people files its `people` key names appended
    to its [[pedestrians]] (and `people` gone), and where each added person comes from, by
    their index ("pedestrians[0] of FILE"). Data without `people` is returned as it is."""
    out = dict(data)
    if PEOPLE_KEY not in out:
        return out, {}
    files = people_files(path, out.pop(PEOPLE_KEY))
    own = out.get(PERSON_KEY, [])
    if not (isinstance(own, list) and all(isinstance(v, dict) for v in own)):
        raise FieldError(path, PERSON_KEY, own, "must be a list of tables ([[pedestrians]] "
                         "entries)")  # fmt: skip
    index = len(own) + (0 if listed(out) else 1)
    added: list[dict[str, Any]] = []
    origins: dict[int, str] = {}
    for file in files:
        for j, entry in enumerate(read_people(file)):
            origins[index + len(added)] = f"pedestrians[{j}] of {file}"
            added.append(copy.deepcopy(entry))
    out[PERSON_KEY] = [*own, *added]
    return out, origins


def load(path: Path | str) -> ScenarioFile:
    """Read and validate one scenario file (its base scenario and every sweep value)."""
    path = Path(path)
    _, data = read_toml(path, "scenario file")
    if is_sweep_spec(data):
        raise UserError(
            f"{path}: this is a sweep spec, not a scenario file (it lists scenario files "
            f"under [[include]]): run it with `monopic sweep {path}`"
        )
    top = TomlTable(path, "", data)
    sweep_table = top.table("sweep") if top.has("sweep") else None
    data.pop("sweep", None)  # the base scenario is the file without its sweep
    name = top.slug("name")
    family = top.text("family", name)
    kind = top.text("kind", "case", KINDS)
    scale = Scale(top.text("scale", "small", tuple(s.value for s in Scale)))
    description = top.text("description", "")
    base = build(path, data)
    sweep = None
    if sweep_table is not None:
        sweep = parse_sweep(sweep_table)
        _check_parameters(path, data, sweep)
    return ScenarioFile(path, name, family, kind, scale, description, data, sweep, base)


def _check_parameters(path: Path, data: dict[str, Any], sweep: Sweep) -> None:
    """Every value of every parameter must build on its own (type, range, known key)."""
    for key, dist in sweep.parameters.items():
        reason = unsweepable(key)
        if reason is not None:
            raise ScenarioFileError(path, f"sweep.parameters.{key}", MISSING, reason)
        values = dist.grid() if isinstance(dist, Values) or dist.steps else (dist.low, dist.high)
        for value in values:
            try:
                build(path, *applied(path, data, {key: value}))
            except ScenarioFileError as err:
                if err.field in (key, field_of(data, key)) or err.reason.startswith("unknown key"):
                    raise ScenarioFileError(
                        path, f"sweep.parameters.{key}", value, err.reason
                    ) from None
                # Other failures depend on the combination; the sweep checks each run.
            except ValueError as err:
                raise ScenarioFileError(path, f"sweep.parameters.{key}", value, str(err)) from None


# Keys that label a file's runs rather than describe its scenario: the runs keep the
# file's own (its results, its report row, its run ids), so a sweep cannot vary them.
LABEL_KEYS = ("name", "family", "kind", "description", "sweep")


def unsweepable(key: str) -> str | None:
    """Why a dotted key cannot be swept; None when every run applies it to its scenario.

    The one rule for a scenario file's [sweep.parameters] and a sweep spec's
    [include.parameters]."""
    top = key.split(".")[0]
    if top not in LABEL_KEYS:
        return None
    if top == "sweep":
        return "cannot be swept: [sweep] says how the file is swept, it is not a scenario value"
    return (
        f"cannot be swept: the file's {top} labels all its runs (their results and the "
        f"report keep it); to vary it, write one scenario file per {top}"
    )


# -- values given on the command line -------------------------------------------------


@dataclass(frozen=True)
class Given:
    """A value given on the command line for a key of a scenario file (record's --robot-speed
    for robot.speed, closed-loop's --robot-speeds ...): applied as the file's own value would be."""

    option: str  # as typed, e.g. "--robot-speed"
    key: str  # the file's dotted key, e.g. "robot.speed"
    value: Any

    @property
    def text(self) -> str:
        """The option and its value as a refusal names them, e.g. `--robot-speed 10`."""
        shown = f"{self.value:g}" if isinstance(self.value, float) else str(self.value)
        return f"{self.option} {shown}"


def given_problem(data: Mapping[str, Any], g: Given) -> str | None:
    """Why a value given on the command line cannot apply to the scenario of `data` (None:
    it applies): a case placement's keys need a case path, a standing person has no speed."""
    scripted = entries(data)[0] if listed(data) else data
    scripted = scripted if isinstance(scripted, dict) else {}
    path = scripted.get("path") if isinstance(scripted.get("path"), dict) else {}
    kind = path.get("kind")
    if g.key.startswith("path.") and kind != "case":
        return (
            f"{g.key} is a case placement's (path.kind = 'case'); this file's path.kind is "
            f"{show(kind)}, which has no {g.key.removeprefix('path.')}"
        )
    if g.key == "pedestrian.speed" and kind == "case" and path.get("case") == int(Case.STILL):
        return "case 9 (still) stands: it has no walking speed"
    return None


def scene_data(scene: SceneSpec) -> dict[str, Any]:
    """[scene] of a scenario file that builds `scene` (its occluders aside)."""
    road = scene.road
    return {
        "lighting": scene.lighting.name,
        "sun_azimuth_deg": scene.lighting.sun.azimuth_deg,
        "sun_elevation_deg": scene.lighting.sun.elevation_deg,
        "road": {
            "length": road.length,
            "lanes": road.lanes,
            "lane_width": road.lane_width,
            "center_y": road.center_y,
            "pavement_width": road.pavement_width,
            "crosswalk": road.crosswalk_x is not None,
            **({} if road.crosswalk_x is None else {"crosswalk_x": road.crosswalk_x}),
            "buildings": road.buildings,
        },
    }


# The street of a case placed on the command line: SceneSpec's, the one every placement
# (CasePlacement.scenario) stands in, with the robot on the road's centre line; the robot,
# its camera, its max_speed and the horizon are the small scale's.
PLACED_SCENE = SceneSpec()
PLACED_FILE = Path("<command line>")


def placed_case(
    case: Case,
    given: Sequence[Given],
    fixed: Mapping[str, Any] | None = None,
    name: str | None = None,
    where: str = "",
) -> Scenario:
    """A case placed on the command line, built as the small-scale scenario file with
    path.kind = "case" and these values would be: the same checks, the same Scenario.

    `fixed` are the command's own values (dotted keys), `given` the user's. A refusal is
    one line naming the option that set the field (`--robot-speed 10: must be <= 3 m/s
    ...`); for a check of the values together (the street, the road's end) every option
    given; otherwise the options given, `where` (e.g. "case 5: ") and the field."""
    data: dict[str, Any] = {
        "name": name or f"case{int(case)}-{case.label.replace(' ', '-')}",
        "family": "cases",
        "scale": Scale.SMALL.value,
        "scene": scene_data(PLACED_SCENE),
        "path": {"kind": "case", "case": int(case)},
    }
    data = with_values(data, {**(fixed or {}), **{g.key: g.value for g in given}})
    for g in given:
        problem = given_problem(data, g)
        if problem is not None:
            raise UserError(f"{g.text}: {where}{problem}")
    try:
        return build(PLACED_FILE, data)
    except StreetError as err:  # the values together: name them all, and where it happens
        at = f"; at {show(err.value)}" if err.field == "path" else ""
        line = f"{where}{err.reason}{at}"
        raise UserError(f"{' '.join(g.text for g in given)}: {line}" if given else line) from None
    except ScenarioFileError as err:
        for g in given:
            if g.key == err.field:
                raise UserError(f"{g.text}: {where}{err.reason}") from None
        value = f" = {show(err.value)}" if err.value is not MISSING else ""
        line = f"{where}{err.field}{value}: {err.reason}"
        raise UserError(f"{' '.join(g.text for g in given)}: {line}" if given else line) from None


# -- building a Scenario from a file's data -------------------------------------------


def build(
    path: Path, data: Mapping[str, Any], origins: Mapping[int, str] | None = None
) -> Scenario:
    """Validate a file's data (without its sweep) and build the Scenario it describes.

    Its `people` files are read in (resolve_people) unless `data` comes without them,
    `origins` then saying where its added people come from."""
    if PEOPLE_KEY in data:
        data, origins = resolve_people(path, data)
    origins = origins or {}
    if REPLAY_KEY in data:  # recorded people (sim.scenario.replays), after the file's own
        given = data.get("duration", presets.DURATION_S)
        data, origins = expand_replay(path, data, origins, _seconds(given))
    top = TomlTable(path, "", data)
    name = top.text("name")
    family = top.text("family", name)
    top.text("kind", "case", KINDS)
    top.text("description", "")
    scale = Scale(top.text("scale", "small", tuple(s.value for s in Scale)))
    preset = SCALES[scale]
    horizon = top.number(
        "horizon", preset.horizon, positive=True, high=presets.MAX_HORIZON_S, unit="s"
    )
    duration = top.number(
        "duration", presets.DURATION_S, positive=True, high=presets.MAX_DURATION_S, unit="s"
    )
    fps_low, fps_high = presets.FPS_RANGE
    fps = top.number("fps", presets.FPS, low=fps_low, high=fps_high, unit="frames/s")
    seed = top.integer("seed", 0, high=2**31 - 1)
    robot = _robot(top.table("robot"), preset.robot)
    _check_frame_rate(top, robot, fps)
    road, lighting = _scene(top.table("scene"), preset.road)
    lamps = _lamps(top.table("scene"), road)
    if lighting.night and robot.headlamps is None:
        raise top.table("robot").error(
            "headlamps", "none", f"a night scene needs the robot's headlamps on ([scene] "
            f"lighting = {lighting.name!r}): headlamps = {' or '.join(map(repr, HEADLAMPS))}"
        )  # fmt: skip
    tables = _people_tables(top)
    people: list[PedestrianSpec] = []
    case: Case | None = None
    x_line: float | None = None
    for k, (person_table, path_table) in enumerate(tables):
        try:
            person, case_k, x_line_k = _person(person_table, path_table, robot, road, duration)
        except FieldError as err:
            if k not in origins:
                raise
            reason = f"{err.reason} (person {k} is {origins[k]})"
            raise FieldError(err.file, err.field, err.value, reason) from None
        if k == 0:  # the scripted person: the scenario's case and crossing line
            case, x_line = case_k, x_line_k
        people.append(person)
    occluders = _parked_cars(top.table("scene").table("parked_cars"), x_line, robot, road)
    crowd = crowd_from_table(top.table("crowd"), road)
    top.done()
    _check_names(people, [t for t, _ in tables])
    scene = SceneSpec(occluders=occluders, road=road, lighting=lighting, lamps=lamps)
    scenario = Scenario(
        name=name,
        pedestrian=people[0],
        robot=robot,
        scene=scene,
        family=family,
        case=case,
        duration=duration,
        dt=1.0 / fps,
        horizon=horizon,
        seed=seed,
        bystanders=tuple(people[1:]),
        crowd=crowd,
    )
    if crowd is not None:
        _check_crowd(path, scenario)
    paths = [t.prefix for _, t in tables]
    labels = [person_label(scenario, k, origins.get(k, "")) for k in range(len(people))]
    replayed = replay_street_problem(scenario, [t.prefix for t, _ in tables], labels)
    if replayed is not None:
        raise StreetError(path, replayed.field, replayed.value, replayed.reason)
    _check_on_street(path, scenario, paths, labels)
    _check_people(path, scenario, paths, labels)
    return scenario


def _check_crowd(path: Path, s: Scenario) -> None:
    """The crowd fits the street where it starts (one line naming the part too large)."""
    assert s.crowd is not None
    problem = capacity_problem(s.crowd, s)
    if problem is not None:
        key, value, reason = problem
        raise StreetError(path, f"crowd.{key}", value, reason)


def _seconds(value: Any) -> float:
    """A duration as given, or the default when it is not one (build then refuses it)."""
    number = isinstance(value, int | float) and not isinstance(value, bool)
    return float(value) if number and math.isfinite(value) else presets.DURATION_S


def _people_tables(top: TomlTable) -> list[tuple[TomlTable, TomlTable]]:
    """Each person's table and their path's, the scripted person first: [pedestrian] and
    [path] (as a file without [[pedestrians]] always had it), or the first [[pedestrians]]
    entry of a file with neither table; then the [[pedestrians]] entries, named by their
    index among the people (pedestrians.1, ...)."""
    is_listed = listed(top.data)
    value = top.raw(PERSON_KEY, [])
    if not (isinstance(value, list) and all(isinstance(v, dict) for v in value)):
        raise top.error(PERSON_KEY, value, "must be a list of tables ([[pedestrians]] entries)")
    tables = [] if is_listed else [(top.table("pedestrian"), top.table("path"))]
    first = len(tables)
    for j, entry in enumerate(value):
        t = TomlTable(top.file, f"{PERSON_KEY}.{first + j}", entry, top.doc)
        tables.append((t, t.table("path")))
    return tables


def _person(
    t: TomlTable, path_table: TomlTable, robot: RobotSpec, road: RoadLayout, duration: float
) -> tuple[PedestrianSpec, Case | None, float | None]:
    """One person: their table's looks, speed and walker, and their path (_path)."""
    name = t.slug("name") if t.has("name") else ""
    body = t.text("body", "adult", BODIES)
    clothing = t.text("clothing", "default", tuple(CLOTHING))
    height_low, height_high = presets.HEIGHT_RANGE
    height = t.number("height", None, low=height_low, high=height_high, unit="m")
    speed = t.number(
        "speed", presets.PEDESTRIAN_SPEED, low=0.0, high=presets.MAX_PEDESTRIAN_SPEED, unit="m/s"
    )
    footprint = t.number("footprint", presets.FOOTPRINT, positive=True, high=2.0, unit="m")
    behaviour = walker_from_table(t.table("behaviour"))  # scenarios/README.md
    t.done()
    looks = mannequin(body, clothing, height)
    if isinstance(behaviour, ReplayWalker):  # the file is the path (sim.scenario.replays)
        person = replay_person(t, path_table, behaviour, looks, footprint, duration)
        return (replace(person, name=name) if name else person), None, None
    person, case, x_line = _path(
        path_table, robot, road, speed, looks, footprint, duration, behaviour, t.prefix
    )
    return (replace(person, name=name) if name else person), case, x_line


def _robot(t: TomlTable, preset: RobotSpec) -> RobotSpec:
    max_speed = t.number("max_speed", preset.max_speed, positive=True, high=40.0, unit="m/s")
    speed = t.number("speed", preset.speed, low=0.0, unit="m/s")
    if speed > max_speed:
        raise t.error("speed", speed, f"must be <= {max_speed:g} m/s (robot.max_speed)")
    robot = RobotSpec(
        speed=speed,
        width=t.number("width", preset.width, positive=True, high=3.0, unit="m"),
        length=t.number("length", preset.length, positive=True, high=12.0, unit="m"),
        camera=_camera(t.table("camera"), preset.camera),
        max_acceleration=t.number(
            "max_acceleration", preset.max_acceleration, positive=True, high=15.0, unit="m/s^2"
        ),
        max_deceleration=t.number(
            "max_deceleration", preset.max_deceleration, positive=True, high=15.0, unit="m/s^2"
        ),
        max_speed=max_speed,
        pitch=_pitch(t.table("pitch"), preset.pitch),
        headlamps=_headlamps(t, preset.headlamps),
    )
    t.done()
    return robot


def _headlamps(t: TomlTable, preset: Headlamps | None) -> Headlamps | None:
    """`headlamps = "low-beam"` (sim.scenario.lamps HEADLAMPS) or "none"."""
    default = "none" if preset is None else preset.name
    name = t.text("headlamps", default, ("none", *HEADLAMPS))
    return None if name == "none" else HEADLAMPS[name]


def _lamps(t: TomlTable, road: RoadLayout) -> tuple[StreetLamp, ...]:
    """[[scene.lamps]]: street lamps on masts, each beside the road (never on it)."""
    lamps = []
    for k, lt in enumerate(t.tables("lamps")):
        lamp = StreetLamp(
            x=lt.number("x", unit="m", low=-road.length / 2, high=road.length / 2),
            y=lt.number("y", unit="m", low=-50.0, high=50.0),
            height=lt.number("height", LAMP_HEIGHT, low=2.0, high=20.0, unit="m"),
            intensity_cd=lt.number(
                "intensity_cd", LAMP_INTENSITY_CD, positive=True, high=1e5, unit="cd"
            ),
            on=lt.flag("on", True),
        )
        if lamp_on_road(lamp, road.edges):
            south, north = road.edges
            raise lt.error(
                "y", lamp.y, f"lamp {k} would stand on the road (its edges: y = {south:g} "
                f"and {north:g} m): a mast stands beside the road"
            )  # fmt: skip
        lt.done()
        lamps.append(lamp)
    return tuple(lamps)


def _check_frame_rate(top: TomlTable, robot: RobotSpec, fps: float) -> None:
    """A real camera keeps the file's frame rate and exposes within its frame interval."""
    sensor = robot.camera.sensor
    if sensor is None:
        return
    try:
        sensor.check_frame_rate(1.0 / fps)
    except SensorSpecError as err:
        if err.field == "fps":
            raise top.error("fps", fps, err.why) from None
        camera = top.table("robot").table("camera")
        raise camera.error(err.field, err.value, err.why) from None


def _pitch(t: TomlTable, preset: BodyPitch) -> BodyPitch:
    """[robot.pitch]: the body's nose dip when braking (sim.scenario.spec.BodyPitch)."""
    pitch = BodyPitch(
        gain=t.number("gain", preset.gain, low=0.0, high=2.0, unit="deg per m/s^2"),
        frequency=t.number("frequency", preset.frequency, low=0.2, high=10.0, unit="Hz"),
        damping=t.number("damping", preset.damping, low=0.05, high=5.0),
    )
    t.done()
    return pitch


def _camera(t: TomlTable, preset: CameraSpec) -> CameraSpec:
    camera = CameraSpec(
        width=t.integer("width", preset.width, low=64, high=4096),
        height=t.integer("height", preset.height, low=64, high=4096),
        vertical_fov_deg=t.number(
            "vertical_fov_deg", preset.vertical_fov_deg, low=10.0, high=120.0, unit="degrees"
        ),
        mount_height=t.number("mount_height", preset.mount_height, low=0.2, high=4.0, unit="m"),
        pitch_deg=t.number("pitch_deg", preset.pitch_deg, low=-30.0, high=45.0, unit="degrees"),
        mount_forward=t.number("mount_forward", preset.mount_forward, low=-5.0, high=5.0, unit="m"),
        sensor=read_sensor(t, preset.sensor),
    )
    t.done()
    return camera


def _scene(t: TomlTable, preset: RoadLayout) -> tuple[RoadLayout, Lighting]:
    light = LIGHTING[t.text("lighting", FILE_DEFAULT, tuple(LIGHTING))]
    azimuth = t.number(
        "sun_azimuth_deg", light.sun.azimuth_deg, low=-360.0, high=360.0, unit="degrees"
    )
    elevation = t.number(
        "sun_elevation_deg", light.sun.elevation_deg, low=2.0, high=90.0, unit="degrees"
    )
    r = t.table("road")
    crosswalk = r.flag("crosswalk", preset.crosswalk_x is not None)
    crosswalk_x = r.number("crosswalk_x", preset.crosswalk_x or 12.0, unit="m")
    road = RoadLayout(
        length=r.number("length", preset.length, low=20.0, high=2000.0, unit="m"),
        lanes=r.integer("lanes", preset.lanes, low=1, high=6),
        lane_width=r.number("lane_width", preset.lane_width, low=1.5, high=6.0, unit="m"),
        center_y=r.number("center_y", preset.center_y, low=-20.0, high=20.0, unit="m"),
        pavement_width=r.number(
            "pavement_width", preset.pavement_width, low=0.5, high=10.0, unit="m"
        ),
        crosswalk_x=crosswalk_x if crosswalk else None,
        buildings=r.flag("buildings", preset.buildings),
    )
    if crosswalk and abs(crosswalk_x) > road.length / 2:
        raise r.error(
            "crosswalk_x",
            crosswalk_x,
            f"the crosswalk would lie off the road (x in [{-road.length / 2:g}, "
            f"{road.length / 2:g}] m)",
        )
    r.done()
    t.seen.add("parked_cars")  # read by _parked_cars once the path is known
    t.seen.add("lamps")  # read by _lamps once the road is known
    t.done()
    return road, light.with_sun(azimuth, elevation)


def _path(
    t: TomlTable,
    robot: RobotSpec,
    road: RoadLayout,
    speed: float,
    looks: Any,
    footprint: float,
    duration: float,
    behaviour: Walker,
    person: str = "pedestrian",
) -> tuple[PedestrianSpec, Case | None, float | None]:
    """The pedestrian's path; also its case and (crossings) the crossing line's x.

    `person` is the dotted name of their table (a placement's refusal of their speed
    names it)."""
    kind = t.text("kind", choices=PATH_KINDS)
    x_line = None
    try:
        if kind == "case":
            pedestrian, case = _case_path(t, robot, speed, looks, footprint, duration, behaviour)
        elif kind == "crossing":
            c = Crossing(
                side=Side(t.text("side", choices=tuple(s.value for s in Side))),
                impact_point=t.number("impact_point", low=-5.0, high=6.0),
                impact_time=t.number("impact_time", positive=True, high=duration, unit="s"),
                approach=t.number("approach", 4.0, positive=True, high=30.0, unit="m"),
                then=Then(t.text("then", "walk", tuple(x.value for x in Then))),
                standstill_distance=t.number(
                    "standstill_distance", 4.0, low=0.0, high=200.0, unit="m"
                ),
                from_kerb=t.number("from_kerb", None, low=0.0, high=10.0, unit="m"),
                hesitate_speed=t.number(
                    "hesitate_speed", HESITATE_SPEED, positive=True, high=2.0, unit="m/s"
                ),
                hesitate_time=t.number(
                    "hesitate_time", HESITATE_TIME, positive=True, high=10.0, unit="s"
                ),
            )
            pedestrian = place_crossing(c, robot, road, speed, looks, footprint, behaviour)
            case = Case.PERPENDICULAR_LEFT if c.side is Side.NEAR else Case.PERPENDICULAR_RIGHT
            x_line = crossing_line_x(robot, footprint, c.impact_time, c.standstill_distance)
        elif kind == "turn-in":
            c3 = TurnIn(
                side=Side(t.text("side", choices=tuple(s.value for s in Side))),
                impact_point=t.number("impact_point", low=-5.0, high=6.0),
                impact_time=t.number("impact_time", positive=True, high=duration, unit="s"),
                toward=t.text("direction", "away", ("away", "toward")) == "toward",
                standstill_distance=t.number(
                    "standstill_distance", 4.0, low=0.0, high=200.0, unit="m"
                ),
            )
            pedestrian = place_turn_in(c3, robot, road, speed, looks, footprint, behaviour)
            case = Case.PERPENDICULAR_LEFT if c3.side is Side.NEAR else Case.PERPENDICULAR_RIGHT
            x_line = crossing_line_x(robot, footprint, c3.impact_time, c3.standstill_distance)
        elif kind == "longitudinal":
            direction = t.text("direction", "away", ("away", "toward"))
            c2 = Longitudinal(
                impact_point=t.number("impact_point", low=-5.0, high=6.0),
                impact_time=t.number("impact_time", positive=True, high=duration, unit="s"),
                toward=direction == "toward",
                standstill_distance=t.number(
                    "standstill_distance", 4.0, low=0.0, high=200.0, unit="m"
                ),
            )
            if not speed > 0:
                raise PlacementError("pedestrian.speed", speed, "a walking pedestrian needs > 0")
            pedestrian = place_longitudinal(c2, robot, speed, looks, footprint, behaviour)
            case = Case.TOWARD if c2.toward else Case.AWAY
        elif kind == "pavement":
            along = t.text("direction", None, tuple(a.value for a in Along))
            c4 = Pavement(
                side=Side(t.text("side", choices=tuple(s.value for s in Side))),
                x=t.number("x", unit="m"),
                from_kerb=t.number("from_kerb", PAVEMENT_FROM_KERB, low=0.0, high=10.0, unit="m"),
                along=None if along is None else Along(along),
            )
            pedestrian = place_pavement(c4, road, speed, looks, footprint, behaviour)
            case = None
        else:
            leg_tables = t.tables("legs")
            legs = tuple(
                Leg(
                    at=leg.number("at", low=0.0, high=duration, unit="s"),
                    speed=leg.number(
                        "speed", low=0.0, high=presets.MAX_PEDESTRIAN_SPEED, unit="m/s"
                    ),
                    turn_deg=leg.number("turn_deg", 0.0, low=-360.0, high=360.0, unit="degrees"),
                )
                for leg in leg_tables
            )
            for leg_table in leg_tables:
                leg_table.done()
            pedestrian = PedestrianSpec(
                x=t.number("x", unit="m"),
                y=t.number("y", unit="m"),
                heading_deg=t.number("heading_deg", low=-360.0, high=360.0, unit="degrees"),
                speed=speed,
                looks=looks,
                legs=legs,
                start_delay=t.number("start_delay", 0.0, low=0.0, high=duration, unit="s"),
                footprint=footprint,
                behaviour=behaviour,
            )
            case = None
    except PlacementError as err:
        field = _placement_field(err.field, person, t.prefix)
        raise ScenarioFileError(t.file, field, err.value, err.reason) from None
    t.done()
    return pedestrian, case, x_line


def _placement_field(field: str, person: str, path: str) -> str:
    """A placement's field (`pedestrian.speed`, `path.approach`) as this person's tables
    are named (`pedestrians.1.speed`, `pedestrians.1.path.approach`)."""
    head, _, rest = field.partition(".")
    if head == "pedestrian":
        return f"{person}.{rest}"
    if head == "path":
        return f"{path}.{rest}" if rest else path
    return field


# Where a CasePlacement parameter is set in a scenario file.
PLACEMENT_KEYS = {"pedestrian_speed": "pedestrian.speed", "robot_speed": "robot.speed",
                  "duration": "duration", "horizon": "horizon", "dt": "fps"}  # fmt: skip
PATH_PLACEMENT = ("distance", "lateral_offset", "angle_deg", "meet_time", "facing_deg")


def _case_path(
    t: TomlTable, robot: RobotSpec, speed: float, looks: Any, footprint: float, duration: float,
    behaviour: Walker,
) -> tuple[PedestrianSpec, Case]:  # fmt: skip
    """sim.scenario.cases.CasePlacement: the path passes (distance, offset) at meet_time."""
    case = Case(t.integer("case", low=1, high=9))
    values: dict[str, Any] = {}
    for name in PATH_PLACEMENT:
        meta, default = PLACEMENT_FIELDS[name].metadata, PLACEMENT_FIELDS[name].default
        if name == "angle_deg":  # its range holds for the obliques only: CasePlacement checks
            values[name] = t.number(name, default, unit=meta["unit"])
            continue
        high = duration if name == "meet_time" else meta["high"]
        default = duration / 2 if default is None else default
        values[name] = t.number(name, default, low=meta["low"], high=high, unit=meta["unit"])
    try:
        placement = CasePlacement(
            case, pedestrian_speed=speed, robot_speed=robot.speed, duration=duration, **values
        )
    except PlacementError as err:
        key = PLACEMENT_KEYS.get(err.field, f"path.{err.field}")
        raise PlacementError(key, err.value, err.reason) from None
    scenario = placement.scenario(looks=looks, robot=robot, behaviour=behaviour)
    return replace(scenario.pedestrian, footprint=footprint), case


def _parked_cars(
    t: TomlTable, x_line: float | None, robot: RobotSpec, road: RoadLayout
) -> tuple[Occluder, ...]:
    if not t.data:
        return ()
    placement = t.text("placement", choices=("crossing", "fixed"))
    y = t.number("y", unit="m")
    if placement == "crossing":
        gap = t.number("gap", 1.0, positive=True, high=10.0, unit="m")
        if x_line is None:
            raise t.error("placement", placement, "needs path.kind = 'crossing'")
        cars: tuple[Occluder, ...] = parked_cars_around(x_line, y, gap)
    else:
        xs = t.numbers("x", nonempty=True, unit="m")
        cars = tuple(Occluder.parked_car(x, y) for x in xs)
    t.done()
    clearance = abs(y) - max(c.width for c in cars) / 2 - robot.width / 2
    if clearance < 0.1:
        raise t.error("y", y, "the parked cars would stand in the robot's path")
    x0, x1, y0, y1 = street_bounds(road)
    if not y0 <= y <= y1:
        raise t.error("y", y, f"the parked cars would stand off the street (y in [{y0:.2f}, "
                      f"{y1:.2f}] m)")  # fmt: skip
    for car in cars:
        if not x0 <= car.x <= x1:
            key = "x" if placement == "fixed" else "placement"
            raise t.error(key, t.data.get(key), f"a parked car would stand off the road "
                          f"(x = {car.x:g} m, the road spans [{x0:g}, {x1:g}] m)")  # fmt: skip
    return cars


class StreetError(ScenarioFileError):
    """A check of the whole scenario (street_problem): no single value is to blame."""


def _check_on_street(
    path: Path, s: Scenario, paths: Sequence[str] | None = None,
    labels: Sequence[str] | None = None,
) -> None:  # fmt: skip
    """The robot stays on its road and everyone on the street for the whole run."""
    problem = street_problem(s, paths, labels)
    if problem is not None:
        raise StreetError(path, problem.field, problem.value, problem.reason)


def person_label(s: Scenario, index: int, origin: str = "") -> str:
    """A person as an error names them: "the pedestrian" when they are alone, else by
    index and name (and where an added person comes from)."""
    if len(s.people) == 1:
        return "the pedestrian"
    where = f", {origin}" if origin else ""
    return f"person {index} ({person_name(s.people[index], index)!r}{where})"


def person_paths(s: Scenario) -> list[str]:
    """Each person's path as a file with [pedestrian] and [path] names it."""
    return ["path", *(f"{PERSON_KEY}.{k}.path" for k in range(1, len(s.people)))]


def street_problem(
    s: Scenario, paths: Sequence[str] | None = None, labels: Sequence[str] | None = None
) -> PlacementError | None:
    """Why the scenario leaves its street (robot off its road or past its end, a person
    off the street, robot faster than its own limit), None when it does not.

    The whole-scenario checks of a scenario file, shared with scenarios made on the
    command line (record, closed-loop --cases) so that both accept the same values.
    `paths` name each person's path (default person_paths), `labels` each person
    (default person_label)."""
    road = s.scene.road
    y_right, y_left = road.edges
    if s.robot.speed > s.robot.max_speed:
        return PlacementError(
            "robot.speed", s.robot.speed, f"must be <= {s.robot.max_speed:g} m/s (its max_speed)"
        )
    if not (y_right <= -s.robot.width / 2 and s.robot.width / 2 <= y_left):
        return PlacementError(
            "scene.road.center_y", road.center_y, "the robot (at y = 0) is not on the road"
        )
    end = s.robot.speed * s.duration + s.robot.length / 2
    if end > road.length / 2:
        return PlacementError(
            "robot.speed",
            s.robot.speed,
            f"the robot would drive off the end of the road within the run "
            f"({end:.1f} m > {road.length / 2:.1f} m): lower the speed or the duration",
        )
    paths = person_paths(s) if paths is None else paths
    labels = [person_label(s, k) for k in range(len(s.people))] if labels is None else labels
    x0, x1, y0, y1 = street_bounds(road)
    for k, person in enumerate(s.planned):  # the crowd keeps to its street itself
        ped = pedestrian_path(person, s.duration, s.seed)
        # Every vertex at once: a human walker's track has one every 10 ms.
        times = np.array([0.0, *ped.breakpoints_between(0.0, s.duration), s.duration])
        xy = ped.positions_at(times)
        off = np.flatnonzero(
            ~((x0 <= xy[:, 0]) & (xy[:, 0] <= x1) & (y0 <= xy[:, 1]) & (xy[:, 1] <= y1))
        )
        if len(off):
            t, (x, y) = float(times[off[0]]), xy[off[0]]
            whose = "the pedestrian's path" if len(s.people) == 1 else f"the path of {labels[k]}"
            return PlacementError(
                paths[k],
                {"t": round(t, 3), "x": round(float(x), 2), "y": round(float(y), 2)},
                f"{whose} leaves the street (x in [{x0:g}, {x1:g}] m, y in [{y0:.2f}, {y1:.2f}] m)",
            )
    return None


def _check_names(people: Sequence[PedestrianSpec], tables: Sequence[TomlTable]) -> None:
    """Each person has a name of their own (the Scenario refuses two with one): the one
    who wrote a name is blamed, the other named."""
    seen: dict[str, int] = {}
    for k, person in enumerate(people):
        name = person_name(person, k)
        if name in seen:
            j = seen[name]
            blamed, other = (k, j) if person.name else (j, k)
            how = "" if people[other].name else f" (the name an unnamed person {other} gets)"
            raise tables[blamed].error(
                "name", name, f"person {other} is called {name!r} too{how}: each person needs "
                "a name of their own",
            )  # fmt: skip
        seen[name] = k


def _check_people(path: Path, s: Scenario, paths: Sequence[str], labels: Sequence[str]) -> None:
    """Nobody starts inside another person, and nobody meets a parked car during the run."""
    overlap = start_overlap(s)
    if overlap is not None:
        j, k = overlap
        start = planned_path(s.people[k], s).state(0.0).position
        raise StreetError(
            path, paths[k], {"x": round(float(start[0]), 2), "y": round(float(start[1]), 2)},
            f"{labels[k]} starts inside {labels[j]}: their footprints overlap at t = 0",
        )  # fmt: skip
    contact = parked_car_contact(s)
    if contact is not None:
        k = contact.person
        x, y = contact.xy
        raise StreetError(
            path, paths[k], {"t": round(contact.t, 3), "x": round(x, 2), "y": round(y, 2)},
            f"{labels[k]} walks into {parked_car_text(s.scene.occluders[contact.car])} (their "
            "footprints meet): a person's path must go around the parked cars",
        )  # fmt: skip
