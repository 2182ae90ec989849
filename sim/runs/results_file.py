"""The sweep's results file: one complete JSON line per finished run, appended as it goes.

Each line is written whole with one write, flushed and fsynced, so a sweep stopped at
any moment (Ctrl-C, a crash, a lost machine) leaves every finished run on disk and at
worst one torn last line. Resuming reads the ids already present, cuts a torn tail off
and appends the rest: nothing is lost and nothing is run twice.
"""

from __future__ import annotations

import fcntl
import json
import os
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from monopic.closing import Closing
from monopic.errors import UserError
from sim.runs.code_version import UNKNOWN
from sim.runs.result import RunResult


@dataclass(frozen=True)
class ResultsState:
    """What an existing results file holds: finished run ids and where good data ends."""

    ids: frozenset[str]
    good_bytes: int  # length of the prefix made of complete lines
    torn: bool  # a partial last line follows the good prefix
    codes: Counter[str] = field(default_factory=Counter)  # lines per code version

    def other_code(self, code: str) -> Counter[str]:
        """Lines made by code other than `code`, per code version."""
        return Counter({c: n for c, n in self.codes.items() if c != code})


def scan(path: Path) -> ResultsState:
    """Read run ids from a results file; a torn (unterminated or unparsable) last line is ignored.

    A bad line anywhere else means the file is not ours or was edited: a UserError names
    the file and the line rather than silently dropping runs.
    """
    if not path.exists():
        return ResultsState(frozenset(), 0, False)
    ids: set[str] = set()
    codes: Counter[str] = Counter()
    good = 0
    *complete, tail = path.read_bytes().split(b"\n")
    for number, raw in enumerate(complete, start=1):
        try:
            row = json.loads(raw)
            run_id = row["id"]
            if not isinstance(run_id, str):
                raise TypeError("its id is not a string")
        except (ValueError, KeyError, TypeError) as err:
            raise UserError(
                f"{path}:{number}: not a result line ({err}); remove it or use another --out"
            ) from None
        ids.add(run_id)
        codes[str(row.get("code") or UNKNOWN)] += 1
        good += len(raw) + 1
    # Lines are written whole, newline included: an unterminated tail is a torn write.
    return ResultsState(frozenset(ids), good, bool(tail), codes)


def read_rows(path: Path) -> Iterator[dict[str, Any]]:
    """Every complete result line (a torn last line is skipped)."""
    state = scan(path)
    with path.open("rb") as fh:
        data = fh.read(state.good_bytes)
    for raw in data.split(b"\n"):
        if raw:
            yield json.loads(raw)


def read_results(path: Path) -> Iterator[RunResult]:
    """Every complete result line as a record; a line that does not fit names its number."""
    for number, row in enumerate(read_rows(path), start=1):
        yield RunResult.from_json(row, f"{path}:{number}")


class ResultsWriter(Closing):
    """Appends result lines durably, one writer per file (a lock), torn tail cut off first.

    The lock keeps two sweeps from appending to the same file at once (each would run
    the runs the other has not finished yet, and both would write them).
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self._fh = path.open("ab")
        try:
            fcntl.flock(self._fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._fh.close()
            raise UserError(
                f"{path}: another sweep is writing to it; wait for it or use another --out"
            ) from None
        self.state = scan(path)
        if self.state.torn:
            self._fh.truncate(self.state.good_bytes)

    def append(self, row: dict[str, Any]) -> None:
        line = json.dumps(row, separators=(",", ":"), allow_nan=False).encode() + b"\n"
        self._fh.write(line)
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        self._fh.close()
