"""The benchmark history: one JSON line per benchmark run, appended when the run finishes.

BENCHMARKS.md is rendered from this file (bench/render.py), so a figure is never copied
by hand and every figure keeps what made it: the command line, the code digest
(sim.runs.code_version), the git commit, the machine with its CPU's name and vector-unit
flags (the ratio against MediaPipe moved by 2x between hosts with and without AVX-512),
and the load average around the run (this 2-core VM is shared).

A line is a `BenchRun`. Its `results` hold the script's figures as plain JSON data; a
key names its unit (`_ms`, `_us`, `_s`, `_px`, `_mb`, `_fps`, `_pct`, `_x` for a ratio
or speed-up), counts and labels have none, and a figure that could not be measured is
null. `table` is the Markdown the script printed. Adding a field to a record: give it a
default, so older lines still load; renaming or removing one, or changing a unit: raise
SCHEMA and say here how older lines are read.

Lines are written whole with one write, flushed and fsynced (as sweep results files
are), so an interrupted benchmark leaves either its complete line or nothing; a torn last
line (a crash mid-write) is skipped on reading and cut off before the next append.
"""

from __future__ import annotations

import datetime as dt
import fcntl
import json
import math
import os
import platform
import subprocess
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
HISTORY = ROOT / "bench" / "history.jsonl"
BENCHMARKS = ROOT / "BENCHMARKS.md"  # rendered from HISTORY by bench/render.py
SCHEMA = 1

# The CPU flags that decide which kernels onnxruntime and XNNPACK pick, in this order:
# x86 (/proc/cpuinfo "flags") then Arm ("Features"). Only the ones present are recorded.
VECTOR_FLAGS = (
    "sse4_2",
    "avx",
    "fma",
    "f16c",
    "avx2",
    "avx_vnni",
    "avx512f",
    "avx512bw",
    "avx512vl",
    "avx512_vnni",
    "avx512_bf16",
    "avx512_fp16",
    "amx_tile",
    "amx_int8",
    "amx_bf16",
    "asimd",
    "asimddp",
    "i8mm",
    "bf16",
    "sve",
    "sve2",
)


class HistoryError(ValueError):
    """A history file that is not ours (or was edited): names the file and line."""


@dataclass(frozen=True)
class Machine:
    """Where a benchmark ran: enough to tell hosts apart and say why a ratio moved."""

    host: str  # the node name
    cpu_model: str  # /proc/cpuinfo "model name" (lscpu's "Model name")
    cpu_cores: int  # logical CPUs of the machine (os.cpu_count)
    cpu_allowed: int  # logical CPUs this process may run on (its affinity mask)
    cpu_flags: tuple[str, ...]  # the VECTOR_FLAGS present, in that order
    virtual: bool  # the CPU reports a hypervisor
    os: str  # kernel name, release and architecture
    python: str

    def label(self) -> str:
        """How reports name the host: the CPU and its core count."""
        return f"{self.cpu_model}, {self.cpu_cores} cores"

    def vector_summary(self) -> str:
        """The flags in words: 'AVX2, AVX-512 (VNNI, BF16), AMX (INT8, BF16)'."""
        f = set(self.cpu_flags)
        parts = []
        if "avx2" in f:
            parts.append("AVX2" + (" with AVX-VNNI" if "avx_vnni" in f else ""))
        if "avx512f" in f:
            extras = [n for k, n in (("avx512_vnni", "VNNI"), ("avx512_bf16", "BF16"),
                                     ("avx512_fp16", "FP16")) if k in f]  # fmt: skip
            parts.append("AVX-512" + (f" ({', '.join(extras)})" if extras else ""))
        elif f & {"sse4_2", "avx", "avx2"}:  # an x86 CPU
            parts.append("no AVX-512")
        if "amx_tile" in f:
            extras = [n for k, n in (("amx_int8", "INT8"), ("amx_bf16", "BF16")) if k in f]
            parts.append("AMX" + (f" ({', '.join(extras)})" if extras else ""))
        if "asimd" in f:
            parts.append("NEON" + (" with dot product" if "asimddp" in f else ""))
        if "sve" in f:
            parts.append("SVE")
        return ", ".join(parts)


@dataclass(frozen=True)
class BenchRun:
    """One finished benchmark run: what ran, on which code and machine, and what it found."""

    benchmark: str  # the script's name without .py, e.g. "compare_reference"
    title: str  # the heading BENCHMARKS.md gives it
    date: str  # UTC start, ISO 8601 to the second: "2026-11-22T12:31:05Z"
    duration_s: float
    command: str  # how to run it again, from the repository root
    code: str  # sim.runs.code_version.code_version() of the code that ran
    commit: str | None  # git HEAD, when the repository is a git checkout
    dirty: bool | None  # tracked files differed from HEAD (history and BENCHMARKS.md aside)
    machine: Machine
    load_before: float | None  # 1-minute load average when the script started
    load_after: float | None  # ... and when it finished
    results: dict[str, Any]  # the figures as data, units in the key names
    table: str  # the Markdown the script printed
    schema: int = SCHEMA

    def to_line(self) -> str:
        """One JSON line, newline included (NaN refused: the results are cleaned first)."""
        return json.dumps(asdict(self), ensure_ascii=False, allow_nan=False) + "\n"

    @classmethod
    def from_line(cls, line: str) -> BenchRun:
        """The record of one history line (raises KeyError/TypeError/ValueError if it is not)."""
        raw = json.loads(line)
        if not isinstance(raw, dict):
            raise TypeError("not a JSON object")
        schema = raw.get("schema")
        if schema != SCHEMA:
            raise ValueError(f"schema {schema!r}, this code reads {SCHEMA}")
        machine = dict(raw.pop("machine"))
        machine["cpu_flags"] = tuple(machine["cpu_flags"])
        return cls(machine=Machine(**machine), **raw)


def jsonable(value: Any) -> Any:
    """Plain JSON data: tuples as lists, numpy scalars as numbers, NaN and inf as null.

    Applied to every result before it is stored, so a record read back equals the record
    written, and a figure that could not be measured reads as null rather than breaking
    strict JSON.
    """
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, str):
        return value
    if isinstance(value, Sequence):
        return [jsonable(v) for v in value]
    if isinstance(value, bool) or value is None:
        return value
    if hasattr(value, "item") and callable(value.item):  # numpy scalar
        value = value.item()
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    raise TypeError(f"{type(value).__name__} is not a result value: {value!r}")


def parse_cpuinfo(text: str) -> tuple[str | None, tuple[str, ...], bool]:
    """CPU model name, the VECTOR_FLAGS present and whether a hypervisor shows, from
    /proc/cpuinfo text (the first processor's block is enough: they agree)."""
    model = None
    flags: set[str] = set()
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip().lower()
        if key in ("model name", "hardware") and model is None:
            model = value.strip() or None
        elif key in ("flags", "features") and not flags:
            flags = set(value.split())
    return model, tuple(f for f in VECTOR_FLAGS if f in flags), "hypervisor" in flags


def lscpu_model() -> str | None:
    """lscpu's "Model name", for CPUs whose /proc/cpuinfo has none (most Arm kernels)."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
    except OSError:
        return None
    for line in out.splitlines():
        key, _, value = line.partition(":")
        if key.strip() == "Model name" and value.strip():
            return value.strip()
    return None


def this_machine() -> Machine:
    """The machine this process runs on."""
    try:
        cpuinfo = Path("/proc/cpuinfo").read_text()
    except OSError:
        cpuinfo = ""
    model, flags, virtual = parse_cpuinfo(cpuinfo)
    model = model or lscpu_model() or platform.processor() or platform.machine()
    try:
        allowed = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        allowed = os.cpu_count() or 0
    return Machine(
        host=platform.node(),
        cpu_model=model,
        cpu_cores=os.cpu_count() or 0,
        cpu_allowed=allowed,
        cpu_flags=flags,
        virtual=virtual,
        os=f"{platform.system()} {platform.release()} {platform.machine()}",
        python=platform.python_version(),
    )


def git_state(root: Path = ROOT) -> tuple[str | None, bool | None]:
    """HEAD's commit and whether tracked files differ from it, or (None, None) without git.

    The history file and BENCHMARKS.md are left out of "differ": a benchmark run changes
    them itself.
    """

    def git(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            ["git", "-C", str(root), *args], capture_output=True, text=True, check=False
        )

    try:
        head = git("rev-parse", "HEAD")
    except OSError:
        return None, None
    if head.returncode != 0:
        return None, None
    diff = git("diff", "--quiet", "HEAD", "--", ".", ":!bench/history.jsonl", ":!BENCHMARKS.md")
    return head.stdout.strip(), diff.returncode != 0


def utc_now() -> str:
    """Now in UTC, as the history writes dates (they sort as text)."""
    return dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def load_average() -> float | None:
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def append(path: Path, run: BenchRun) -> None:
    """Append one whole line: one write, flushed and fsynced, under an exclusive lock.

    A torn tail left by a crash mid-write is cut off first, so it never glues onto the
    new line.
    """
    data = run.to_line().encode("utf-8")
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("ab") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        good = _good_bytes(path.read_bytes())
        if good != fh.tell():
            fh.truncate(good)
            fh.seek(good)
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())


def _good_bytes(data: bytes) -> int:
    """Length of the prefix made of newline-terminated lines."""
    end = data.rfind(b"\n")
    return end + 1


def read(path: Path = HISTORY) -> list[BenchRun]:
    """Every complete line of a history file, in file order (missing file: no runs).

    An unterminated last line is a torn write and is skipped; a bad line anywhere else
    raises HistoryError naming it, rather than silently dropping runs.
    """
    if not path.exists():
        return []
    data = path.read_bytes()
    runs = []
    for number, raw in enumerate(data[: _good_bytes(data)].splitlines(), start=1):
        if not raw.strip():
            continue
        try:
            runs.append(BenchRun.from_line(raw.decode("utf-8")))
        except (KeyError, TypeError, ValueError) as err:
            raise HistoryError(f"{path}:{number}: not a benchmark history line ({err})") from None
    return runs
