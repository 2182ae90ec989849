"""The `replay` walker: a real recorded walk (ETH/UCY track file) put on the street.

The person's samples (sim.scenario.track_file: `frame person x y`, 0.4 s apart) are turned
by `rotate_deg` about the file's origin, then moved by `offset` into the street's world
frame; file frame `start_frame` is the run's t = 0. The Track's vertices are the samples
themselves, joined by straight pieces: linear interpolation between samples is what the
file means, so the footprint is exactly on the file's point at every sample time and on
the line between two samples in between. Before its first sample the person stands at its
first point (the world cannot make a body appear), after its last it stands at its last.

What a file does not record is made from what it does, the same for every run (no seed):

- the footprint faces the heading of each 0.4 s piece (held while slower than HOLD_SPEED,
  so a person standing and jittering a centimetre does not spin on the spot);
- the body faces that heading smoothed over about a second (a Gaussian of SMOOTH seconds
  over the pieces' displacements, each piece weighing its length), turning in YAW_STEP
  steps between pieces, so a 0.4 s zig-zag of the annotation does not spin the mannequin;
- the gait phase advances with the distance walked, one stride per two step lengths at the
  piece's speed (sim.scenario.stride), so the legs follow the file's speed. The mannequin's
  pelvis then does not sway on its own (the Track sets the phase: sim.world.pedestrian).

It shows no intent cues (cues False): a replayed person's head is not in the file, and a
check made up from its speed would be this walker's guess, not the recording.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import ClassVar

import numpy as np

from monopic.errors import UserError
from sim.scenario.plan import Plan
from sim.scenario.stride import step_length
from sim.scenario.toml_table import TomlTable
from sim.scenario.track import Track
from sim.scenario.track_file import FRAME_TIME, read_track_file, resolve, rotation

HOLD_SPEED = 0.2  # m/s: slower pieces keep the heading before them
SMOOTH = 0.4  # s, the standard deviation of the body's heading smoothing
YAW_STEP = 0.1  # s: the body turns in steps this long between the pieces' headings
OFFSET_LIMIT = 1000.0  # m, the largest shift a file may be given


@dataclass(frozen=True)
class Samples:
    """A replayed person's samples in the run: file frames, run times (s), world points."""

    frames: np.ndarray
    times: np.ndarray
    positions: np.ndarray


@dataclass(frozen=True)
class ReplayWalker:
    """One person of a track file, replayed (scenarios/README.md: keys, units, ranges)."""

    model: ClassVar[str] = "replay"
    source: str  # the file as the scenario file names it (its identity on every machine)
    person: int  # the person's id in the file
    rotate_deg: float = 0.0  # CCW about the file's origin, applied first
    offset: tuple[float, float] = (0.0, 0.0)  # m, then added (world x, y)
    start_frame: float = 0.0  # the file's frame number at the run's t = 0
    # The file itself (source resolved against the scenario file's folder or the shared
    # data folder): where it is on this machine, so not part of the identity.
    file: Path = field(default=Path(), repr=False)

    @property
    def cues(self) -> bool:
        return False

    @property
    def start_distance(self) -> float:
        return 0.0  # the file says where it is at every time: no placement times it

    def placed(self, acceleration_distance: float) -> ReplayWalker:
        return self

    def samples(self) -> Samples:
        """The person's samples, transformed into the world and timed in the run."""
        track = read_track_file(self.file).person(self.person)
        xy = track.positions @ rotation(self.rotate_deg).T + np.asarray(self.offset, dtype=float)
        return Samples(track.frames, (track.frames - self.start_frame) * FRAME_TIME, xy)

    def track(self, plan: Plan, t_end: float, seed: int) -> Track:
        """The samples from t = 0 on (all of them: the track is short), standing before the
        first and after the last; the plan gives only the body's stature. No seed."""
        return replay_track(self.samples(), plan.looks.height)

    def identity(self) -> str:
        return repr(self)

    @classmethod
    def from_table(cls, t: TomlTable) -> ReplayWalker:
        person = t.integer("person", low=0)
        walker = read_transform(t)
        t.done()
        try:
            read_track_file(walker.file).person(person)
        except UserError as err:
            raise t.error("person", person, str(err)) from None
        return replace(walker, person=person)


def read_transform(t: TomlTable) -> ReplayWalker:
    """The keys naming a file and placing it (file, rotate_deg, offset, start_frame) of a
    table, checked, the file read (a FieldError on `file` naming its problem); person 0
    (the caller sets the person)."""
    source = t.text("file", nonempty=True)
    rotate = t.number("rotate_deg", 0.0, low=-360.0, high=360.0, unit="degrees")
    offset = t.numbers("offset", [0.0, 0.0], low=-OFFSET_LIMIT, high=OFFSET_LIMIT, unit="m")
    if len(offset) != 2:
        raise t.error("offset", list(offset), "must be [x, y] (two numbers, m)")
    start = t.number("start_frame", 0.0, unit="frame numbers")
    file = resolve(source, Path(t.file).parent)
    try:
        read_track_file(file)
    except UserError as err:
        raise t.error("file", source, str(err)) from None
    return ReplayWalker(source, 0, rotate, (offset[0], offset[1]), start, file)


def replay_track(samples: Samples, height: float) -> Track:
    """The Track of a person's samples (see the module docstring), for a body `height` m
    tall (its step length)."""
    times, xy = samples.times, samples.positions
    if times[-1] <= 0:  # gone before the run starts: standing where it was last
        vt, vp = np.zeros(1), xy[-1:].copy()
    else:
        k = int(np.searchsorted(times, 0.0, side="right"))  # the first sample after t = 0
        if k == 0:
            start = xy[0]
        else:  # on the line between the samples around t = 0
            u = (0.0 - times[k - 1]) / (times[k] - times[k - 1])
            start = xy[k - 1] + u * (xy[k] - xy[k - 1])
        vt = np.concatenate([[0.0], times[k:]])
        vp = np.vstack([start, xy[k:]])
    if len(vt) == 1:
        return Track.from_vertices(vt, vp, np.zeros(1), np.zeros(2), phases=np.zeros(1))
    steps = np.diff(vp, axis=0)
    durations = np.diff(vt)
    speeds = np.hypot(steps[:, 0], steps[:, 1]) / durations
    moving = speeds > HOLD_SPEED
    raw = _held(np.arctan2(steps[:, 1], steps[:, 0]), moving)
    body = _held(_smoothed(vt, steps, moving), moving)
    # Each piece in YAW_STEP sub-pieces (on the same line: the positions stay exact), the
    # body's heading interpolated between the pieces' middles.
    counts = np.maximum(1, np.ceil(durations / YAW_STEP - 1e-9).astype(int))
    sub_t = [np.linspace(vt[j], vt[j + 1], counts[j], endpoint=False) for j in range(len(steps))]
    parent = np.repeat(np.arange(len(steps)), counts)
    times = np.concatenate([*sub_t, vt[-1:]])
    positions = vp[parent] + (np.concatenate(sub_t) - vt[parent])[:, None] * (
        steps[parent] / durations[parent, None]
    )
    positions = np.vstack([positions, vp[-1:]])
    middles = (vt[:-1] + vt[1:]) / 2
    sub_middles = (times[:-1] + times[1:]) / 2
    yaws = np.interp(sub_middles, middles, np.unwrap(body))
    yaws = np.concatenate([yaws, yaws[-1:]])
    footprint = np.concatenate([raw[parent], raw[-1:]])
    lengths = np.array([step_length(float(v), height) for v in speeds])[parent]
    walked = np.hypot(*np.diff(positions, axis=0).T)
    with np.errstate(divide="ignore", invalid="ignore"):
        strides = np.where(lengths > 0, walked / (2 * lengths), 0.0)
    phases = np.concatenate([[0.0], np.cumsum(strides)])
    return Track.from_vertices(times, positions, yaws, np.zeros(2), footprint_yaws=footprint,
                               phases=phases)  # fmt: skip


def _held(headings: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """Each piece's heading, a piece that is not moving keeping the one before it (the
    pieces before the first moving one take its heading; none moving: east)."""
    if not moving.any():
        return np.zeros(len(headings))
    out = headings.copy()
    first = int(np.flatnonzero(moving)[0])
    out[:first] = headings[first]
    for j in range(first + 1, len(out)):
        if not moving[j]:
            out[j] = out[j - 1]
    return out


def _smoothed(times: np.ndarray, steps: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """Each piece's heading smoothed: the direction of the moving pieces' displacements
    summed with Gaussian weights (SMOOTH s) on the time between the pieces' middles."""
    middles = (times[:-1] + times[1:]) / 2
    weights = np.exp(-0.5 * ((middles[:, None] - middles[None, :]) / SMOOTH) ** 2)
    summed = (weights * moving[None, :]) @ steps
    out = np.arctan2(summed[:, 1], summed[:, 0])
    tiny = np.hypot(summed[:, 0], summed[:, 1]) < 1e-9
    return np.where(tiny, np.arctan2(steps[:, 1], steps[:, 0]), out)
