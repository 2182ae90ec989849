"""Recorded walks in the ETH/UCY text format, read for replay (sim.scenario.walkers.replay).

A track file holds whitespace-separated rows `frame person x y`: positions in metres on
the ground plane, one row per person per annotated frame, consecutive frames of one person
FRAME_STEP frame numbers (STEP seconds) apart (../shared/data/eth-ucy-calibration/README.md;
`monopic tracks` writes the same). A replayed walker's motion is the file's, so the reader
is strict: a person's frames must follow each other FRAME_STEP apart, with no gap and no
repeat, or the file is refused in one line naming the file, the person and the frame
(a gap would have to be filled by a guess, which a replay must not make).

Files are read once per (path, modification time): a scenario with twenty people from one
file, and every run of a sweep, read it once.
"""

from __future__ import annotations

import functools
import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from monopic.errors import UserError

# The ETH/UCY format's clock (sim.analysis.realism has the same; this floor cannot import it).
STEP = 0.4  # s between consecutive positions of one person
FRAME_STEP = 10  # frame numbers between them
FRAME_TIME = STEP / FRAME_STEP  # s per frame number

SHARED = "shared:"  # a file name's prefix: under the shared data folder (shared_data)


@dataclass(frozen=True)
class PersonTrack:
    """One person's samples: frame numbers (FRAME_STEP apart) and positions (n, 2), m."""

    person: int
    frames: np.ndarray
    positions: np.ndarray


@dataclass(frozen=True)
class TrackFile:
    """Every person of one file, by id."""

    path: Path
    people: dict[int, PersonTrack]

    def person(self, person: int) -> PersonTrack:
        """One person's samples; a UserError naming the file and the id if the file has no
        such person."""
        found = self.people.get(person)
        if found is None:
            ids = sorted(self.people)
            shown = f"{ids[0]}..{ids[-1]}" if ids else "none"
            raise UserError(f"{self.path}: person {person}: no such person in the file "
                            f"({len(ids)} people, ids {shown})")  # fmt: skip
        return found


def shared_data() -> Path:
    """The shared data folder: $MONOPIC_SHARED_DATA, else ../shared/data beside the project
    root (real data is read where it is kept, never copied into the project)."""
    given = os.environ.get("MONOPIC_SHARED_DATA")
    if given:
        return Path(given)
    return Path(__file__).resolve().parents[2].parent / "shared" / "data"


def resolve(name: str, folder: Path) -> Path:
    """A track file's path as a scenario file names it: `shared:REL` under shared_data(),
    an absolute path as it is, anything else relative to `folder` (the scenario file's)."""
    if name.startswith(SHARED):
        return shared_data() / name.removeprefix(SHARED)
    path = Path(name)
    return path if path.is_absolute() else folder / path


def read_track_file(path: Path) -> TrackFile:
    """The file's people, checked (see the module docstring); cached per path and
    modification time. A UserError in one line when the file is missing or malformed."""
    try:
        mtime = path.stat().st_mtime_ns
    except OSError:
        raise UserError(f"{path}: no such track file") from None
    return _read(path.resolve(), mtime)


def read_rows(path: Path) -> np.ndarray:
    """A track file's rows as they are: an (n, 4) array of frame, person, x, y, at least
    one row, every value finite (else one UserError line naming the file and the row)."""
    try:
        with warnings.catch_warnings():  # an empty file: said below, in one line
            warnings.simplefilter("ignore", UserWarning)
            rows = np.loadtxt(path, ndmin=2)
    except (OSError, ValueError) as err:
        raise UserError(f"{path}: not a track file of `frame person x y` rows ({err})") from None
    if rows.size == 0:
        raise UserError(f"{path}: no rows (expected `frame person x y` rows)")
    if rows.shape[1] != 4:
        raise UserError(f"{path}: rows have {rows.shape[1]} columns, expected frame person x y")
    if not np.all(np.isfinite(rows)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(rows), axis=1))[0])
        raise UserError(f"{path}: row {bad + 1} is not finite ({' '.join(map(str, rows[bad]))})")
    return rows


@functools.lru_cache(maxsize=16)
def _read(path: Path, mtime: int) -> TrackFile:
    """The file as it was at `mtime` (the key that makes the cache see an edit)."""
    rows = read_rows(path)
    for column, what in ((0, "frame"), (1, "person id")):
        whole = rows[:, column] == np.round(rows[:, column])
        if not whole.all():
            row = int(np.flatnonzero(~whole)[0])
            raise UserError(f"{path}: row {row + 1}: the {what} {rows[row, column]:g} is not "
                            "a whole number")  # fmt: skip
    people: dict[int, PersonTrack] = {}
    for person in np.unique(rows[:, 1]):
        mine = rows[rows[:, 1] == person]
        mine = mine[np.argsort(mine[:, 0], kind="stable")]
        frames = mine[:, 0].astype(np.int64)
        steps = np.diff(frames)
        bad = np.flatnonzero(steps != FRAME_STEP)
        if len(bad):
            k = int(bad[0])
            what = "is repeated" if steps[k] == 0 else (
                f"follows frame {frames[k]} after {steps[k]} frame numbers, not {FRAME_STEP} "
                "(a gap)"
            )  # fmt: skip
            raise UserError(f"{path}: person {int(person)}: frame {frames[k + 1]} {what}")
        people[int(person)] = PersonTrack(int(person), frames, mine[:, 2:4].astype(float))
    return TrackFile(path, people)


def frame_time(frame: float, start_frame: float) -> float:
    """The run's time (s) of a file frame when `start_frame` is the run's t = 0."""
    return (frame - start_frame) * FRAME_TIME


def rotation(degrees: float) -> np.ndarray:
    """The 2x2 counter-clockwise rotation by `degrees`."""
    a = math.radians(degrees)
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
