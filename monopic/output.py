"""Output files that appear whole or not at all: write a temporary name, rename when done.

A temporary is named after its output, the process writing it and that process's host
(`.NAME.PID@HOST.tmp.SUFFIX` beside NAME.SUFFIX), so one left behind can be told from one
being written. A process stopped by Ctrl-C or SIGTERM deletes its own (`atomic_path`,
monopic.recording); one killed outright cannot (SIGKILL, or a worker process its command
stopped: they die of SIGTERM without running any cleanup), so its temporaries are stale
once it is gone, and are removed when an output is written again
(`remove_stale_temporaries`: `atomic_path` clears its output's, a command whose workers
write into a folder clears the folder before it starts them and after they are gone).
A temporary whose process still runs is never touched (nor one whose pid a new process
has taken since: it goes once that one ends), nor one made on another host (a folder
shared over the network, as a Ray cluster's may be): from here there is no telling
whether its process runs.
"""

from __future__ import annotations

import contextlib
import os
import re
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

# `.NAME.PID@HOST.tmp.SUFFIX`; temporaries made before the host was in the name have none.
TEMPORARY = re.compile(
    r"\.(?P<stem>.+)\.(?P<pid>\d+)(?:@(?P<host>[A-Za-z0-9-]+))?\.tmp(?P<suffix>(?:\.[^.]*)?)"
)


def host_tag() -> str:
    """This machine's name as it goes into a temporary's name (letters, digits and '-')."""
    return re.sub(r"[^A-Za-z0-9-]+", "-", socket.gethostname()).strip("-")[:40] or "host"


def temporary_sibling(path: Path) -> Path:
    """A hidden name beside `path` with the same suffix (some writers need the suffix)."""
    return path.with_name(f".{path.stem}.{os.getpid()}@{host_tag()}.tmp{path.suffix}")


@dataclass(frozen=True)
class Temporary:
    """A temporary file found in a folder: what it becomes and who writes it."""

    path: Path
    output: Path  # the file it is renamed to when done
    pid: int
    host: str | None  # None: a name without a host (made here, by older code)

    @classmethod
    def parse(cls, path: Path) -> Temporary | None:
        """The temporary `path` is, or None for any other file."""
        match = TEMPORARY.fullmatch(path.name)
        if match is None:
            return None
        output = path.with_name(match["stem"] + match["suffix"])
        return cls(path, output, int(match["pid"]), match["host"])

    def stale(self) -> bool:
        """Made on this host by a process that no longer runs: nobody will finish it."""
        return self.host in (None, host_tag()) and not process_running(self.pid)


def is_temporary(path: Path) -> bool:
    """Whether `path` is named as a temporary of this module's (finished or not)."""
    return Temporary.parse(Path(path)) is not None


def process_running(pid: int) -> bool:
    """Whether process `pid` runs on this host (a zombie has exited: it writes no more)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:  # it has just exited, or there is no /proc to ask
        return not Path("/proc/self/stat").exists()
    except (OSError, IndexError):
        return True
    return state != "Z"


def remove_stale_temporaries(
    folder: Path, *, output: Path | None = None, recursive: bool = False
) -> list[Path]:
    """Delete the stale temporaries in `folder` (of `output` only, if given); the removed.

    Best effort: a file that cannot be removed is left (the folder is someone else's or
    read-only, and writing the output there fails on its own terms).
    """
    # Every output written scans its folder: names are sifted as strings before any Path
    # is made (a Path per name made a 10 000-file folder's scan 15 times slower).
    prefix = f".{Path(output).stem}." if output is not None else "."
    removed = []
    for path in _candidates(Path(folder), prefix, recursive):
        temporary = Temporary.parse(path)
        if temporary is None or (output is not None and temporary.output != Path(output)):
            continue
        if temporary.stale():
            with contextlib.suppress(FileNotFoundError, PermissionError, IsADirectoryError):
                path.unlink()
                removed.append(path)
    return removed


def _candidates(folder: Path, prefix: str, recursive: bool) -> Iterator[Path]:
    """Files in `folder` whose names start with `prefix` and hold ".tmp"."""
    if recursive:
        for root, _, names in os.walk(folder):
            for name in names:
                if name.startswith(prefix) and ".tmp" in name:
                    yield Path(root, name)
        return
    try:
        names = os.listdir(folder)
    except (FileNotFoundError, NotADirectoryError):  # nothing there to clear
        return
    for name in names:
        if name.startswith(prefix) and ".tmp" in name:
            yield Path(folder, name)


@contextmanager
def stale_temporaries_cleared(folder: Path) -> Iterator[None]:
    """Clear `folder` (and its sub-folders) of stale temporaries on entry and on leaving.

    For a command whose worker processes write into `folder`: entered once no other
    run of it can be writing there, left once its workers are gone (a worker stopped
    mid-run dies without deleting its temporary; this deletes it).
    """
    remove_stale_temporaries(folder, recursive=True)
    try:
        yield
    finally:
        remove_stale_temporaries(folder, recursive=True)


@contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """Yield a temporary path; move it onto `path` on success, delete it on any error.

    Stale temporaries of `path` (a killed writer's) are deleted first.
    """
    path = Path(path)
    remove_stale_temporaries(path.parent, output=path)
    tmp = temporary_sibling(path)
    try:
        yield tmp
        if not tmp.exists():
            raise RuntimeError(f"nothing was written to {path}")
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text_atomically(path: Path, text: str) -> None:
    """Write a whole text file under a temporary name, then rename it into place."""
    with atomic_path(Path(path)) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="")
