"""The results schema: one run's result line as typed records, with one JSON round trip.

A sweep appends one `RunResult` per finished run to its results file (one JSON object a
line); metrics, the report and the ground replay read them back as records, so a column
is named in one place. Per-frame quantities are columns (one list entry per processed
frame, None where there is nothing to say), rounded where they are written (RunColumns).

Growing it (one rule for every growth: the lighting, several people, the camera):
- A new field gets a default (None, an empty list, a default_factory) and is appended to
  its record; lines written before it load with the default, so SCHEMA stays. Reading
  code must accept the default (e.g. a behaviour model's head yaw: a column that is None
  on lines of walkers without one). Where the default cannot say what an old line's run
  had, a function named `_<field>_of_old_lines` says it once (the walker model, the
  lighting preset).
- A field that describes what only some runs have (several people) is written only on
  their lines (OPTIONAL, after ORDER's keys): a run without it writes the line it always
  wrote, and reads back with the default.
- Several pedestrians: `truth` stays the scripted person's; with several people `people`
  holds every person's truth columns (the scripted one first) and `first_threat` names
  the person first on a collision course. A pipeline's columns are the robot's warning
  and the decision behind it (with the one-pedestrian tracker: its one person's; with
  the people tracker, `tracker` = "everyone": each predictor's worst person's, whose
  identity is in `tracks`).
- The camera: `camera` names a real camera's sensor preset (sim.sensor.spec); lines of
  the ideal camera, as every line before the camera model, leave it out.
- A real camera (sim.sensor): `exposure` holds each frame's exposure time, gain, sub-frame
  draws and mean signal; ideal-camera lines have none.
- SCHEMA goes up when a field is renamed, removed or changes meaning or units: lines of
  another schema are then refused with one line saying how to redo them, never read as
  if they meant the new thing.
Measured times live under `timing` only, so everything else is identical whichever
machine or executor ran the run.
"""

from __future__ import annotations

import dataclasses
import json
import types
from dataclasses import dataclass, field
from typing import Any, Union, get_args, get_origin, get_type_hints

from monopic.errors import UserError
from sim.scenario.lighting import DAY, FILE_DEFAULT

SCHEMA = 1
MAIN = "main"  # the real pipeline: it finds the person itself
ABLATION = "gtcrop"  # the same pipeline fed the true crop (pose errors vs decision errors)


class ResultError(UserError):
    """A result line that does not fit the schema (where: the field's dotted path)."""


@dataclass
class TruthColumns:
    """The ground truth the metrics need, per frame."""

    t: list[float | None] = field(default_factory=list)  # s since the start
    ttc: list[float | None] = field(default_factory=list)  # s to contact, None: none ahead
    collision: list[int] = field(default_factory=list)  # 1: contact within the horizon
    contact: list[int] = field(default_factory=list)  # 1: footprints touch now
    case: list[int] = field(default_factory=list)  # the case of the next second (1-9)
    phi: list[float | None] = field(default_factory=list)  # true facing angle, degrees
    range: list[float | None] = field(default_factory=list)  # m from the robot
    forward: list[float | None] = field(default_factory=list)  # m, robot frame
    lateral: list[float | None] = field(default_factory=list)  # m, robot frame (left +)
    height: list[float | None] = field(default_factory=list)  # apparent height, px
    in_frame: list[int] = field(default_factory=list)
    visible: list[float | None] = field(default_factory=list)  # share of landmarks in view
    occluded: list[int] = field(default_factory=list)
    foot: list[list[float | None] | None] = field(default_factory=list)  # px
    future: list[list[float | None] | None] = field(default_factory=list)  # m, robot frame
    robot_speed: list[float | None] = field(default_factory=list)  # m/s
    # Where the head looks (degrees, + to the pedestrian's left): from the shoulders'
    # facing, and from the line to the camera (0: at it). Empty on lines before them.
    head_yaw: list[float | None] = field(default_factory=list)
    head_yaw_camera: list[float | None] = field(default_factory=list)
    # The intent labels (sim.world.intent): what the path does within the horizon, and the
    # case of the velocity now (the current-velocity baseline). Empty on lines before them.
    intent: list[str | None] = field(default_factory=list)
    case_now: list[int | None] = field(default_factory=list)


@dataclass
class ExposureColumns:
    """A real camera's exposure per frame (sim.sensor): what each frame was taken with."""

    exposure_ms: list[float | None] = field(default_factory=list)
    gain: list[float | None] = field(default_factory=list)
    subframes: list[int] = field(default_factory=list)  # renders averaged over the exposure
    signal: list[float | None] = field(default_factory=list)  # mean linear signal, 0-1


@dataclass
class PersonColumns:
    """One person's truth per frame, in a run with several people (TruthColumns holds the
    scripted person's in full; these are what judging every person needs)."""

    name: str
    scripted: bool = False  # the person the run's warnings are judged against
    collision: list[int] = field(default_factory=list)  # 1: contact within the horizon
    contact: list[int] = field(default_factory=list)
    ttc: list[float | None] = field(default_factory=list)  # s to contact
    case: list[int] = field(default_factory=list)
    forward: list[float | None] = field(default_factory=list)  # m, robot frame
    lateral: list[float | None] = field(default_factory=list)  # m, robot frame (left +)
    in_frame: list[int] = field(default_factory=list)
    box: list[list[float | None] | None] = field(default_factory=list)  # px, whole body
    visible_box: list[list[float | None] | None] = field(default_factory=list)  # px, seen part
    visible: list[float | None] = field(default_factory=list)  # share of the body seen
    hidden_by_people: list[float | None] = field(default_factory=list)
    hidden_by_cars: list[float | None] = field(default_factory=list)
    hidden_by_scene: list[float | None] = field(default_factory=list)
    outside_frame: list[float | None] = field(default_factory=list)


@dataclass
class DecisionColumns:
    """One predictor's decisions, per frame (None before its first decision)."""

    warn: list[int | None] = field(default_factory=list)
    case: list[int | None] = field(default_factory=list)
    foot: list[list[float | None] | None] = field(default_factory=list)  # predicted, px
    ground: list[list[float | None] | None] = field(default_factory=list)  # predicted, m
    ttc: list[float | None] = field(default_factory=list)  # predicted time to contact, s
    # The intent class a predictor states (the intent tree); empty for the others.
    intent: list[str | None] = field(default_factory=list)


@dataclass
class PipelineColumns:
    """One pipeline's outputs per frame, its predictors' decisions by key ('rules/image')."""

    found: list[int] = field(default_factory=list)
    phi: list[float | None] = field(default_factory=list)
    foot: list[list[float | None] | None] = field(default_factory=list)
    height: list[float | None] = field(default_factory=list)
    detector_runs: list[int] = field(default_factory=list)
    decisions: dict[str, DecisionColumns] = field(default_factory=dict)


@dataclass
class TrackColumns:
    """What a pipeline with the people tracker saw and whom each predictor warned for,
    per frame: the tracks' identities and boxes, and per predictor ('rules/image') the
    identity of the person whose warning was the robot's (None: no warning). Matched to
    the truth's people by sim.analysis.people, never by the pipeline."""

    # Per frame, one [id, u0, v0, u1, v1] (px) per person the tracker reported.
    boxes: list[list[list[float]]] = field(default_factory=list)
    warned_for: dict[str, list[int | None]] = field(default_factory=dict)


@dataclass
class CameraSummary:
    width: int
    height: int
    vertical_fov_deg: float
    mount_height: float
    pitch_deg: float


@dataclass
class ScenarioSummary:
    """What the report groups and prints by; the full scenario is the run's spec."""

    name: str
    case: int | None
    robot_speed: float
    robot_width: float
    robot_length: float
    horizon: float
    dt: float
    duration: float
    camera: CameraSummary
    pedestrian_height: float
    pedestrian_speed: float
    occluders: int
    behaviour: str = "rail"  # the pedestrian's walker model (lines before it: rail)
    cues: bool = False  # whether the walker shows intent cues (head checks, leads)
    # The lighting preset (sim.scenario.lighting); lines before it: _lighting_of_old_lines.
    lighting: str = ""


@dataclass
class Machine:
    host: str = "?"
    cpu: str = "?"
    cores: int | None = None


@dataclass
class Timing:
    """Measured times: never part of a result's identity."""

    wall_s: float = 0.0
    sim_ms: list[float] = field(default_factory=list)  # per frame: world step (+ render)
    ms: dict[str, dict[str, list[float | None]]] = field(default_factory=dict)  # pipeline-stage
    machine: Machine = field(default_factory=Machine)


@dataclass
class RunResult:
    """One run's result line."""

    id: str
    family: str
    truth: TruthColumns
    scenario: ScenarioSummary
    schema: int = SCHEMA
    sweep: str = ""
    file: str = ""
    kind: str = "case"
    scale: str = ""
    params: dict[str, Any] = field(default_factory=dict)
    seed: int = 0
    code: str | None = None  # sim.runs.code_version of the code that ran it
    frames: int = 0
    contact_time: float | None = None  # when the scripted person is first in contact
    recording: str | None = None  # the kept .rrd, relative to the recordings folder
    pipelines: dict[str, PipelineColumns] = field(default_factory=dict)  # "main", "gtcrop"
    timing: Timing = field(default_factory=Timing)
    # Runs with several people only (OPTIONAL): every person's truth, and who was first
    # on a collision course (None: nobody).
    people: list[PersonColumns] = field(default_factory=list)
    first_threat: str | None = None
    # Runs whose pipelines follow everyone in view (OPTIONAL): the tracker, "everyone"
    # ("" on lines of the one-pedestrian tracker, as every line before it), and each such
    # pipeline's tracks and whom it warned for. Their `people` are written even with one
    # person, so every warning can be matched to a person.
    tracker: str = ""
    tracks: dict[str, TrackColumns] = field(default_factory=dict)
    # Runs with a real camera (OPTIONAL): its sensor's preset name ("" on the ideal
    # camera's lines, the renderer's frames as they are, as every line before it).
    camera: str = ""
    # Runs under a real camera only (OPTIONAL): the exposure of every frame.
    exposure: ExposureColumns | None = None

    # JSON key order of a line (the fields above in the order lines have always had).
    ORDER = (
        "schema", "id", "sweep", "family", "file", "kind", "scale", "params", "seed", "code",
        "scenario", "frames", "contact_time", "recording", "truth", "pipelines", "timing",
    )  # fmt: skip

    # Keys written only on the lines of runs that have them (see "Growing it").
    OPTIONAL = ("people", "first_threat", "tracker", "tracks", "camera", "exposure")

    def to_json(self) -> dict[str, Any]:
        """The line as JSON-ready data (plain dicts and lists)."""
        plain = to_plain(self)
        line = {k: plain[k] for k in self.ORDER}
        if self.people:
            line.update({k: plain[k] for k in ("people", "first_threat")})
        if self.tracker:
            line.update({k: plain[k] for k in ("tracker", "tracks")})
        if self.camera:
            line["camera"] = self.camera
        if self.exposure is not None:
            line["exposure"] = plain["exposure"]
        return line

    def deterministic(self) -> dict[str, Any]:
        """The line without measured times: equal whichever executor or machine ran it."""
        return {k: v for k, v in self.to_json().items() if k != "timing"}

    @classmethod
    def from_json(cls, data: Any, where: str = "result") -> RunResult:
        """A record from a parsed line; ResultError (one line) when it does not fit."""
        if not isinstance(data, dict):
            raise ResultError(f"{where}: expected a JSON object, got {type(data).__name__}")
        schema = data.get("schema", SCHEMA)
        if schema != SCHEMA:
            newer = isinstance(schema, int) and schema > SCHEMA
            raise ResultError(
                f"{where}: results schema {schema!r}, this code reads {SCHEMA} "
                f"({'written by newer code: update this checkout' if newer else 'rerun the sweep'}"
                " or rerun with `monopic sweep SPEC --restart`)"
            )
        result = _current_names(from_plain(cls, data, where))
        return _lighting_of_old_lines(_behaviour_of_old_lines(result, data))

    def dumps(self) -> str:
        """One compact JSON line (no newline)."""
        return json.dumps(self.to_json(), separators=(",", ":"))


# Predictor names that results written by older code use, and the registry's name for each
# (the ID3 tree called itself "id3-tree" until the registry's "tree" became the one name).
OLD_PREDICTOR_NAMES = {"id3-tree": "tree"}


def values_said(params: dict[str, Any]) -> str:
    """A run's given or swept values in words, 'robot.speed = 2, duration = 2', or "the
    file's values" (reports and `monopic rerun` name runs so)."""
    if not params:
        return "the file's values"
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in params.items())  # fmt: skip


def current_key(key: str) -> str:
    """A decision key ("id3-tree/image") in today's vocabulary ("tree/image")."""
    name, slash, mode = key.partition("/")
    return f"{OLD_PREDICTOR_NAMES.get(name, name)}{slash}{mode}"


def _behaviour_of_old_lines(result: RunResult, data: dict[str, Any]) -> RunResult:
    """Lines written before the scenario summary named its walker model: the model the
    sweep set (its params), when it set one, rather than the default "rail", so an older
    human-walker sweep is not reported as rail targets. Cues are not inferred: those
    lines predate them."""
    summary = data.get("scenario")
    if isinstance(summary, dict) and "behaviour" not in summary:
        model = result.params.get("pedestrian.behaviour.model")
        if isinstance(model, str):
            result.scenario.behaviour = model
    return result


def _lighting_of_old_lines(result: RunResult) -> RunResult:
    """Lines written before results named their lighting: the preset the sweep set (its
    params), else the one their scenario had: a file's default when the run came from a
    file, the code's sun when it was built in code. (A family file that chose a lighting
    without sweeping it would be misread as noon; none of the shipped ones does.)"""
    if not result.scenario.lighting:
        swept = result.params.get("scene.lighting")
        if isinstance(swept, str):
            result.scenario.lighting = swept
        else:
            result.scenario.lighting = FILE_DEFAULT if result.file else DAY.name
    return result


def _current_names(result: RunResult) -> RunResult:
    """Old lines read in today's predictor names, so a report never shows both."""
    for columns in result.pipelines.values():
        columns.decisions = {current_key(k): v for k, v in columns.decisions.items()}
    return result


# -- the generic round trip -------------------------------------------------------------


def to_plain(value: Any) -> Any:
    """Records as dicts (field order), tuples as lists, everything else as is."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {k: to_plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_plain(v) for v in value]
    return value


def from_plain(cls: type, data: Any, where: str) -> Any:
    """The record `cls` from plain data, recursively; missing fields take their defaults."""
    if not isinstance(data, dict):
        raise ResultError(f"{where}: expected an object, got {type(data).__name__}")
    hints = get_type_hints(cls)
    kwargs: dict[str, Any] = {}
    for f in dataclasses.fields(cls):
        if f.name in data:
            kwargs[f.name] = _convert(hints[f.name], data[f.name], f"{where}.{f.name}")
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ResultError(f"{where}.{f.name}: missing")
    return cls(**kwargs)


def _holds_record(tp: Any) -> bool:
    if dataclasses.is_dataclass(tp):
        return True
    return any(_holds_record(a) for a in get_args(tp))


def _convert(tp: Any, value: Any, where: str) -> Any:
    if not _holds_record(tp):  # plain data (numbers, strings, lists of them): as read
        return value
    if dataclasses.is_dataclass(tp):
        return from_plain(tp, value, where)
    origin = get_origin(tp)
    if origin in (Union, types.UnionType):
        if value is None:
            return None
        (inner,) = [a for a in get_args(tp) if a is not type(None)]
        return _convert(inner, value, where)
    if origin is dict:
        if not isinstance(value, dict):
            raise ResultError(f"{where}: expected an object, got {type(value).__name__}")
        _, item = get_args(tp)
        return {k: _convert(item, v, f"{where}.{k}") for k, v in value.items()}
    if origin is list:
        if not isinstance(value, list):
            raise ResultError(f"{where}: expected a list, got {type(value).__name__}")
        (item,) = get_args(tp)
        return [_convert(item, v, f"{where}[{i}]") for i, v in enumerate(value)]
    raise TypeError(f"{where}: no conversion for {tp!r}")
