"""Shared helpers of the benchmarks: machine description and appending dated results."""

from __future__ import annotations

import datetime as dt
import os
import platform
import shlex
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[1] / "BENCHMARKS.md"


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}"


def append_section(title: str, command: str, body: str) -> None:
    """Append a dated section with the command that produced it to BENCHMARKS.md."""
    if not BENCHMARKS.exists():
        BENCHMARKS.write_text("# Benchmarks\n\nEach section: command, machine, date, table.\n")
    stamp = dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    text = f"\n## {title}\n\n`{command}`  \n{machine()}, {stamp}\n\n{body.rstrip()}\n"
    with BENCHMARKS.open("a") as fh:
        fh.write(text)


def append_this_run(title: str, body: str) -> None:
    """Append a section whose command is the benchmark command line just run."""
    script = Path(sys.argv[0]).name
    command = f".venv/bin/python bench/{script} {shlex.join(sys.argv[1:])}".rstrip()
    append_section(title, command, body)
