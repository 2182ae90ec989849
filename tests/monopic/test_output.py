"""Temporaries: named after their output, process and host; a dead writer's are removed.

A process killed outright (SIGKILL, or a sweep worker stopped with SIGTERM) leaves the
temporary it was writing; the next writer of the same output, or a command clearing its
folder, removes it, and never one whose process still runs or that another host made.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from monopic.output import (
    Temporary,
    atomic_path,
    host_tag,
    is_temporary,
    process_running,
    remove_stale_temporaries,
    stale_temporaries_cleared,
    temporary_sibling,
    write_text_atomically,
)
from tests.processes import dead_pid, live_pid


@pytest.fixture()
def sleeper() -> Iterator[int]:
    with live_pid() as pid:
        yield pid


def test_a_temporary_names_its_output_its_process_and_its_host(tmp_path: Path) -> None:
    out = tmp_path / "family" / "0003-ab12.rrd"
    tmp = temporary_sibling(out)
    assert tmp.name == f".0003-ab12.{os.getpid()}@{host_tag()}.tmp.rrd"
    assert Temporary.parse(tmp) == Temporary(tmp, out, os.getpid(), host_tag())
    # Made by code before the host was in the name: this host's.
    legacy = tmp_path / ".0003-ab12.4242.tmp.rrd"
    assert Temporary.parse(legacy) == Temporary(legacy, tmp_path / "0003-ab12.rrd", 4242, None)
    for name in ("archive.tar.gz", "notes", "report.md"):
        sibling = temporary_sibling(tmp_path / name)
        assert Temporary.parse(sibling).output == tmp_path / name  # type: ignore[union-attr]
    assert is_temporary(tmp_path / ".notes.12@h.tmp")  # an output without a suffix
    for name in ("0003-ab12.rrd", ".hidden.rrd", ".x.tmp.rrd", ".x.12x.tmp.rrd", ".x.12@a.b.tmp"):
        assert not is_temporary(tmp_path / name), name


def test_a_process_runs_until_it_has_exited_a_zombie_does_not(sleeper: int) -> None:
    assert process_running(os.getpid()) and process_running(sleeper)
    assert not process_running(dead_pid())
    zombie = subprocess.Popen(["true"])
    try:
        os.waitid(os.P_PID, zombie.pid, os.WEXITED | os.WNOWAIT)  # exited, not reaped
        assert Path(f"/proc/{zombie.pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
        assert not process_running(zombie.pid)
    finally:
        zombie.wait()


def test_only_a_dead_processs_temporaries_made_on_this_host_are_removed(
    tmp_path: Path, sleeper: int
) -> None:
    sub = tmp_path / "family"
    sub.mkdir()
    dead, here = dead_pid(), host_tag()
    stale = [
        sub / f".0001-aa.{dead}@{here}.tmp.rrd",
        tmp_path / f".0002-bb.{dead}.tmp.rrd",  # an older name, without the host
        tmp_path / f".runs.{dead}@{here}.tmp.csv",
    ]
    kept = [
        sub / f".0003-cc.{sleeper}@{here}.tmp.rrd",  # being written
        sub / f".0004-dd.{os.getpid()}@{here}.tmp.rrd",  # ours
        sub / f".0005-ee.{dead}@another-host.tmp.rrd",  # whether it runs is unknown here
        sub / "0006-ff.rrd",
        tmp_path / f".notes.{dead}.txt",
    ]
    for path in stale + kept:
        path.write_text("x")
    assert sorted(remove_stale_temporaries(tmp_path)) == sorted(stale[1:])
    assert stale[0].exists()  # in a sub-folder: not without `recursive`
    assert remove_stale_temporaries(tmp_path, recursive=True) == [stale[0]]
    assert all(p.exists() for p in kept) and not any(p.exists() for p in stale)


def test_writing_an_output_removes_its_own_stale_temporaries_and_no_other(
    tmp_path: Path, sleeper: int
) -> None:
    dead, here = dead_pid(), host_tag()
    mine = tmp_path / f".report.{dead}@{here}.tmp.md"
    live = tmp_path / f".report.{sleeper}@{here}.tmp.md"
    other = tmp_path / f".summary.{dead}@{here}.tmp.md"
    for path in (mine, live, other):
        path.write_text("partial")
    write_text_atomically(tmp_path / "report.md", "whole")
    assert (tmp_path / "report.md").read_text() == "whole"
    assert not mine.exists() and live.exists() and other.exists()


def test_an_interrupted_write_leaves_no_temporary(tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    with pytest.raises(KeyboardInterrupt), atomic_path(out) as tmp:
        tmp.write_text("half")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []


def test_a_folder_is_cleared_on_entry_and_on_leaving_however_it_is_left(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    before = tmp_path / "a" / f".0001.{dead_pid()}@{host_tag()}.tmp.rrd"
    before.write_text("x")
    with pytest.raises(KeyboardInterrupt), stale_temporaries_cleared(tmp_path):
        assert not before.exists()
        # A worker starts a temporary and is killed before it can delete it.
        worker = subprocess.Popen(["sleep", "600"])
        after = tmp_path / "a" / f".0002.{worker.pid}@{host_tag()}.tmp.rrd"
        after.write_text("x")
        assert remove_stale_temporaries(tmp_path, recursive=True) == []  # it runs
        worker.kill()
        worker.wait()
        raise KeyboardInterrupt
    assert not after.exists()
