"""How long the test suite takes: the fast part (-m "not slow") and the whole suite, once each.

Timed once (the suite's own run time is the figure, not a distribution); the
pytest summary line is kept beside the time, since a failing or skipped test changes it.
The results go to bench/history.jsonl (bench/history.py) unless --no-append.

    .venv/bin/python -m bench.suite_time [--no-append]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from bench.recorder import Recorder

HERE = Path(__file__).resolve().parent

ROOT = HERE.parent
SUITES = (
    ("fast: -m 'not slow'", ["-q", "-m", "not slow"]),
    ("full", ["-q"]),
)


def run_suite(args: list[str]) -> tuple[float, str, int]:
    """Wall seconds, pytest's last summary line and its exit code."""
    cmd = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *args]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    tail = [ln for ln in proc.stdout.strip().splitlines() if ln.strip()]
    return wall, (tail[-1].strip("= ") if tail else "(no output)"), proc.returncode


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    recorder = Recorder("suite_time", "Test suite run time")
    load0 = os.getloadavg()[0]
    lines = ["| suite | wall | pytest summary | exit |", "| --- | ---: | --- | ---: |"]
    suites = []
    for name, pytest_args in SUITES:
        wall, summary, code = run_suite(pytest_args)
        lines.append(f"| {name} | {wall:.0f} s | {summary} | {code} |")
        suites.append({"suite": name, "wall_s": wall, "summary": summary, "exit_code": code})
    lines.insert(
        0,
        f"`.venv/bin/python -m pytest` as listed, once each; load average {load0:.1f} before, "
        f"{os.getloadavg()[0]:.1f} after, on {os.cpu_count()} cores.\n",
    )
    table = "\n".join(lines)
    print(table)
    recorder.finish({"suites": suites}, table, write=not args.no_append)


if __name__ == "__main__":
    main()
