"""Reader for the authors' per-frame CSV logs, strict about every cell.

Format (shared/data/authors-testdata/README.md): a header line, then one row per
processed frame with the columns in COLUMNS (extra columns are allowed and ignored).
Every cell of those columns must be a finite number, time must increase from row to row,
occupiedHeights must be positive, and a log needs at least MIN_ROWS rows. Values no
camera or clock produces are rejected too: image coordinates beyond +-MAX_IMAGE_PX, a
window or a horizon of 0 or below, a frame rate below 0 (0 only on the first row, which
the authors' logs use for "no rate yet") and times outside [0, MAX_TIME_S]. Anything
else is a UserError naming the file, the line (1-based line of the file; the header is
line 1) and the column.

A `monopic video` CSV of several people (a `personId` column, several people in one
frame) holds one track per person, interleaved: one of them is read (`person`), never the
mix.
"""

from __future__ import annotations

import csv
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from monopic.errors import UserError

COLUMNS = (
    "frameNumber",
    "windowSize",
    "XYError",
    "timeToFuture",
    "time",
    "fps",
    "currentCenterX",
    "currentCenterY",
    "leftShoulderX",
    "leftShoulderY",
    "rightShoulderX",
    "rightShoulderY",
    "angleOfApproach",
    "XFrameSpeed",
    "YFrameSpeed",
    "occupiedHeights",
    "predictedX",
    "predictedY",
)
MIN_ROWS = 2
# Far outside any frame (a 768x432 log's own predictions reach -400 and 1400 px).
MAX_IMAGE_PX = 1e5
PIXEL_COLUMNS = (
    "currentCenterX",
    "currentCenterY",
    "leftShoulderX",
    "leftShoulderY",
    "rightShoulderX",
    "rightShoulderY",
    "predictedX",
    "predictedY",
)
# Seconds: Unix time until the year 2286, or over 300 years of video; a log in
# milliseconds is beyond it too.
MAX_TIME_S = 1e10
# occupiedHeights is the landmarks' vertical extent divided by the 432 px frame height.
FRAME_HEIGHT_PX = 432.0


@dataclass(frozen=True)
class AuthorsLog:
    """One log, column by column (arrays of equal length, one entry per data row)."""

    path: Path
    sha256: str
    time: np.ndarray
    center_x: np.ndarray
    center_y: np.ndarray
    phi: np.ndarray
    occupied: np.ndarray
    predicted_x: np.ndarray
    predicted_y: np.ndarray

    @property
    def name(self) -> str:
        return self.path.name

    def __len__(self) -> int:
        return int(self.time.size)

    @property
    def apparent_height(self) -> np.ndarray:
        """Apparent height in pixels."""
        return self.occupied * FRAME_HEIGHT_PX


PERSON_COLUMN = "personId"


def read_log(path: Path, person: int | None = None) -> AuthorsLog:
    """Parse and validate one log, or `person`'s rows of a log of several people;
    UserError on any defect, and on a log of several people without `person`."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise UserError(f"{path}: cannot read: {err.strerror or err}") from err
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise UserError(f"{path}: not UTF-8 text (byte {err.start})") from err
    if not text.strip():
        raise UserError(f"{path}: empty file (expected a header line with {COLUMNS[4]!r} etc.)")
    reader = csv.reader(text.splitlines())
    header = [h.strip() for h in next(reader)]
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise UserError(f"{path}: line 1 (header): missing column {missing[0]!r}")
    index = {c: header.index(c) for c in COLUMNS}
    rows = list(reader)
    rows = _one_person(path, header, rows, person)
    values: dict[str, list[float]] = {c: [] for c in COLUMNS}
    line = 1
    for line, cells in rows:
        if len(cells) != len(header):
            raise UserError(
                f"{path}: line {line}: {len(cells)} cells, the header has {len(header)}"
            )
        first = not values["time"]  # the log's first data row
        for c in COLUMNS:
            cell = cells[index[c]].strip()
            try:
                v = float(cell)
            except ValueError:
                raise UserError(
                    f"{path}: line {line}, column {c!r}: {cell!r} is not a number"
                ) from None
            if not math.isfinite(v):
                raise UserError(f"{path}: line {line}, column {c!r}: {cell!r} is not finite")
            impossible = _impossible(c, v, first)
            if impossible:
                raise UserError(f"{path}: line {line}, column {c!r}: {cell!r} {impossible}")
            values[c].append(v)
        t = values["time"]
        if len(t) >= 2 and t[-1] <= t[-2]:
            raise UserError(
                f"{path}: line {line}, column 'time': {t[-1]!r} does not come after the "
                f"previous row's {t[-2]!r}"
            )
        if values["occupiedHeights"][-1] <= 0:
            raise UserError(
                f"{path}: line {line}, column 'occupiedHeights': "
                f"{values['occupiedHeights'][-1]!r} is not positive"
            )
    n = len(values["time"])
    if n < MIN_ROWS:
        raise UserError(
            f"{path}: line {line} (end of file): too few rows: {n} data rows, "
            f"at least {MIN_ROWS} needed"
        )
    arr = {c: np.asarray(v, dtype=float) for c, v in values.items()}
    return AuthorsLog(
        path=path,
        sha256=hashlib.sha256(raw).hexdigest(),
        time=arr["time"],
        center_x=arr["currentCenterX"],
        center_y=arr["currentCenterY"],
        phi=arr["angleOfApproach"],
        occupied=arr["occupiedHeights"],
        predicted_x=arr["predictedX"],
        predicted_y=arr["predictedY"],
    )


def _one_person(
    path: Path, header: list[str], rows: list[list[str]], person: int | None
) -> list[tuple[int, list[str]]]:
    """The data rows with their file line numbers, blank lines dropped, only `person`'s
    when the log names people."""
    numbered = [
        (k + 2, cells) for k, cells in enumerate(rows) if cells and any(c.strip() for c in cells)
    ]
    if PERSON_COLUMN not in header:
        if person is not None:
            raise UserError(f"{path}: no {PERSON_COLUMN!r} column: a one-person log")
        return numbered
    column = header.index(PERSON_COLUMN)
    ids = [cells[column].strip() if column < len(cells) else "" for _, cells in numbered]
    people = sorted(set(ids), key=lambda i: (len(i), i))
    if person is None:
        # One person at a time (the one-pedestrian tracker's new identity after each
        # loss) is one track, as today; several in one frame are not.
        frame_column = header.index("frameNumber")
        frames = [cells[frame_column].strip() for _, cells in numbered]
        if len(set(frames)) < len(frames) and len(people) > 1:
            raise UserError(
                f"{path}: rows of {len(people)} people ({PERSON_COLUMN} "
                f"{', '.join(people[:8])}{', ...' if len(people) > 8 else ''}): one "
                "person's track is read at a time (monopic replay --person ID)"
            )
        return numbered
    if str(person) not in people:
        raise UserError(f"{path}: column {PERSON_COLUMN!r}: no row of person {person}")
    return [row for row, i in zip(numbered, ids, strict=True) if i == str(person)]


def _impossible(column: str, value: float, first: bool) -> str:
    """Why a finite cell is a value no camera, walker or clock produces ("" if it is not).

    `first`: the cell is on the log's first data row.
    """
    if column in PIXEL_COLUMNS and abs(value) > MAX_IMAGE_PX:
        return f"is outside any image (beyond +-{MAX_IMAGE_PX:.0f} px)"
    if column == "windowSize" and value <= 0:
        return "is not a window (frames between velocity samples, > 0)"
    if column == "fps" and (value < 0 or (value == 0 and not first)):
        return "is not a frame rate (> 0 frames/s; 0 only on the first row)"
    if column == "timeToFuture" and not 0 < value <= MAX_TIME_S:
        return f"is not a horizon (seconds in (0, {MAX_TIME_S:.0e}])"
    if column == "time" and not 0 <= value <= MAX_TIME_S:
        return f"is beyond any clock (seconds in [0, {MAX_TIME_S:.0e}])"
    return ""
