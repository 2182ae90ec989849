"""A benchmark run's history line, written when the run finishes, and BENCHMARKS.md re-rendered.

Apart from bench/history.py (the line's format, reading and appending) because it renders:
bench/render.py reads the history, and the recorder calls the renderer, so neither of the
two imports the other's caller.
"""

from __future__ import annotations

import shlex
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bench.history import (
    BENCHMARKS,
    HISTORY,
    ROOT,
    BenchRun,
    append,
    git_state,
    jsonable,
    load_average,
    this_machine,
    utc_now,
)
from bench.render import render_file


def this_command(argv: list[str] | None = None, main_module: str | None = None) -> str:
    """The command line just run, as typed from the repository root: `python -m MODULE`
    for a module run that way (as `make bench` runs them), else the script's path."""
    argv = sys.argv if argv is None else argv
    if main_module is None:
        spec = getattr(sys.modules.get("__main__"), "__spec__", None)
        main_module = spec.name if spec is not None else None
    if main_module:
        shown = f"-m {main_module}"
    else:
        script = Path(argv[0]).resolve()
        try:
            shown = str(script.relative_to(ROOT))
        except ValueError:
            shown = str(script)
    return f".venv/bin/python {shown} {shlex.join(argv[1:])}".rstrip()


@dataclass
class Recorder:
    """Started when a benchmark starts, finished with its results: one history line.

    Starting captures the date and the load before the work; `finish` adds the rest and
    appends the line, so a benchmark that fails on the way writes nothing.
    """

    benchmark: str
    title: str
    history: Path = HISTORY
    rendered: Path = BENCHMARKS
    date: str = field(default_factory=utc_now)
    load_before: float | None = field(default_factory=load_average)
    _t0: float = field(default_factory=time.perf_counter, init=False, repr=False)

    def finish(self, results: Mapping[str, Any], table: str, *, write: bool = True) -> BenchRun:
        """The run's record; appended to the history (and BENCHMARKS.md re-rendered) if `write`."""
        from sim.runs.code_version import code_version

        commit, dirty = git_state()
        run = BenchRun(
            benchmark=self.benchmark,
            title=self.title,
            date=self.date,
            duration_s=round(time.perf_counter() - self._t0, 1),
            command=this_command(),
            code=code_version(),
            commit=commit,
            dirty=dirty,
            machine=this_machine(),
            load_before=self.load_before,
            load_after=load_average(),
            results=jsonable(results),
            table=table.rstrip(),
        )
        if write:
            append(self.history, run)
            render_file(self.history, self.rendered)
            print(f"{self.history}: +1 line; {self.rendered} rendered", file=sys.stderr)
        return run
