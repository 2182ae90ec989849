"""The sweep's results file: one complete JSON line per finished run, appended as it goes.

Each line is written whole with one write, flushed and fsynced, so a sweep stopped at
any moment (Ctrl-C, a crash, a lost machine) leaves every finished run on disk and at
worst one torn last line. Resuming reads the ids already present, cuts a torn tail off
and appends the rest: nothing is lost and nothing is run twice. A line that cannot be
written whole (no space left, a quota, an I/O error) is cut off again before the error
is reported, so the file always ends with a complete line.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import json
import os
import sys
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
    # The first line (1-based) holding each result schema (sim.runs.runner.SCHEMA).
    schemas: dict[int, int] = field(default_factory=dict)
    sweeps: Counter[str] = field(default_factory=Counter)  # lines per sweep name

    def other_sweeps(self, name: str) -> Counter[str]:
        """Lines written by sweeps other than `name` (a results file holds one sweep: two
        sharing a file would be counted as one by the report, naming neither)."""
        return Counter({n: k for n, k in self.sweeps.items() if n not in (name, UNKNOWN)})

    def other_code(self, code: str) -> Counter[str]:
        """Lines made by code other than `code`, per code version."""
        return Counter({c: n for c, n in self.codes.items() if c != code})

    def newer_schema(self, schema: int) -> tuple[int, int] | None:
        """(line, schema) of the first line of a schema newer than `schema`, if any.

        Such lines were written by newer code: this code would misread them.
        """
        newer = sorted((line, s) for s, line in self.schemas.items() if s > schema)
        return newer[0] if newer else None


def scan(path: Path) -> ResultsState:
    """Read run ids from a results file; a torn (unterminated or unparsable) last line is ignored.

    A bad line anywhere else means the file is not ours or was edited: a UserError names
    the file and the line rather than silently dropping runs.
    """
    if not path.exists():
        return ResultsState(frozenset(), 0, False)
    ids: set[str] = set()
    codes: Counter[str] = Counter()
    schemas: dict[int, int] = {}
    sweeps: Counter[str] = Counter()
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
        sweeps[str(row.get("sweep") or UNKNOWN)] += 1
        schema = row.get("schema")
        if isinstance(schema, int) and not isinstance(schema, bool):
            schemas.setdefault(schema, number)
        good += len(raw) + 1
    # Lines are written whole, newline included: an unterminated tail is a torn write.
    return ResultsState(frozenset(ids), good, bool(tail), codes, schemas, sweeps)


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


def check_resumable(out: Path, schema: int, restart: bool, option: str = "--out") -> None:
    """The checks a resumable results file gets before its runs (the Euro NCAP grid's, the
    closed loop's; a sweep's make these and more, sim.runs.sweep.check_output).

    A file holding lines of other code or of a schema newer than `schema` is refused in
    one line naming `option`, unless `restart`: then it is set aside as
    <name>.<code>.jsonl (never over an earlier one). One another process is appending to
    is refused before anything is set aside (its lock)."""
    from sim.runs.code_version import code_version

    if out.is_dir():
        raise UserError(f"{option} {out}: is a folder; give a file name")
    if not out.exists():
        return
    code = code_version()
    state = scan(out)
    other = state.other_code(code)
    newer = state.newer_schema(schema)
    if newer and not restart:
        raise UserError(
            f"{out}:{newer[0]}: a result of schema {newer[1]}, newer than this code's "
            f"{schema} (written by newer code, which alone reads it); use another {option}, or "
            "--restart to set the file aside and start over"
        )
    if other and not restart:
        raise UserError(
            f"{out}: holds runs of other code ({', '.join(other)}; this code is {code}); "
            f"use another {option}, or --restart to set them aside and start over"
        )
    check_unlocked(out)
    if other or newer:
        tag = (next(iter(other)) if len(other) == 1 else "mixed") if other else f"schema{newer[1]}"
        target = out.with_name(f"{out.stem}.{tag}{out.suffix}")
        if target.exists():
            raise UserError(f"{target}: already there; move it away to restart {out}")
        out.rename(target)
        print(f"set aside: {out} -> {target}", file=sys.stderr)


LOCKED = "{path}: another sweep is writing to it; wait for it or use another --out"


def without_keys(
    row: dict[str, Any], top: tuple[str, ...], outcome: tuple[str, ...]
) -> dict[str, Any]:
    """A closed-loop or Euro NCAP row without the keys that hold the host's times, machine
    and the like (`top`) and those of its outcome (`outcome`): what a rerun or a run under
    load must reproduce is the rest."""
    out = {k: v for k, v in row.items() if k not in top}
    if isinstance(out.get("outcome"), dict):
        out["outcome"] = {k: v for k, v in out["outcome"].items() if k not in outcome}
    return out


def check_unlocked(path: Path) -> None:
    """Refuse, as ResultsWriter would, a results file another writer holds (its lock);
    takes the lock for a moment and changes nothing (a dry run checks this way)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return  # not there, or not readable: opening it to write will say why
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise UserError(LOCKED.format(path=path)) from None
    finally:
        os.close(fd)  # closing releases the lock


class ResultsWriter(Closing):
    """Appends result lines durably, one writer per file (a lock), torn tail cut off first.

    The lock keeps two sweeps from appending to the same file at once (each would run
    the runs the other has not finished yet, and both would write them).
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            self._fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        except OSError as err:
            raise UserError(
                f"{path}: cannot write there ({err.strerror or err}); use another --out"
            ) from None
        try:
            fcntl.flock(self._fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self._fd)
            raise UserError(LOCKED.format(path=path)) from None
        try:
            self.state = scan(path)
        except BaseException:
            os.close(self._fd)
            raise
        self._size = self.state.good_bytes
        self.written = 0  # lines appended by this writer
        if self.state.torn:
            os.ftruncate(self._fd, self._size)

    def append(self, row: dict[str, Any]) -> None:
        """One line, whole and on disk; if it cannot be, the file is left as it was."""
        line = json.dumps(row, separators=(",", ":"), allow_nan=False).encode() + b"\n"
        try:
            view = memoryview(line)
            while view:
                view = view[os.write(self._fd, view) :]
            os.fsync(self._fd)
        except OSError as err:
            with contextlib.suppress(OSError):  # else resuming cuts the torn tail off
                os.ftruncate(self._fd, self._size)
            full = err.errno in (errno.ENOSPC, errno.EDQUOT)
            raise UserError(
                f"{self.path}: cannot append run {row.get('id')} ({err.strerror or err}); "
                f"the {len(self.state.ids) + self.written} runs before it are intact: "
                f"{'free some space' if full else 'fix that'} and run the sweep again to "
                "resume"
            ) from None
        self._size += len(line)
        self.written += 1

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1
