"""Process ids for tests of files named after their writer: one that has exited, one that runs."""

from __future__ import annotations

import contextlib
import subprocess
from collections.abc import Iterator


def dead_pid() -> int:
    """The pid of a process that has exited (and been reaped)."""
    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid


@contextlib.contextmanager
def live_pid() -> Iterator[int]:
    """The pid of a process other than this one, running until the block ends."""
    proc = subprocess.Popen(["sleep", "600"])
    try:
        yield proc.pid
    finally:
        proc.kill()
        proc.wait()
