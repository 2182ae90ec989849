"""bench/render_ab.py: bad input gets one line, no traceback (the timing itself is a benchmark)."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import ROOT


def run(*args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "bench.render_ab", *args, "--no-append"]
    return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)


def test_an_unknown_revision_is_named_in_one_line() -> None:
    r = run("--before", "no-such-revision")
    assert r.returncode != 0
    assert r.stderr.strip() == "render_ab: --before 'no-such-revision' is not a git revision here"


def test_too_few_renders_is_named_in_one_line() -> None:
    r = run("--renders", "1")
    assert r.returncode != 0
    assert r.stderr.strip() == "render_ab: --renders must be at least 2, got 1"
