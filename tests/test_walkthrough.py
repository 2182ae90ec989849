"""README's "first ten minutes", every command run as written, in order, in a fresh folder."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from tests.paths import DATA, ROOT, SCENARIOS

MONOPIC = ".venv/bin/monopic"


def walkthrough() -> list[str]:
    """The commands of the README's walkthrough block, comments dropped."""
    text = (ROOT / "README.md").read_text()
    section = text.split("## The first ten minutes", 1)[1].split("\n## ", 1)[0]
    block = section.split("```sh\n", 1)[1].split("```", 1)[0]
    return [line.split("#", 1)[0].strip() for line in block.splitlines() if line.strip()]


def monopic_command() -> list[str]:
    """The installed console script beside this Python (what .venv/bin/monopic is)."""
    script = Path(sys.executable).parent / "monopic"
    return [str(script)] if script.is_file() else [sys.executable, "-m", "monopic"]


def test_the_walkthrough_is_set_up_then_monopic_commands_only() -> None:
    commands = walkthrough()
    assert commands[0] == "make install"
    assert len(commands) >= 8 and all(c.startswith(f"{MONOPIC} ") for c in commands[1:])


@pytest.mark.slow
def test_the_first_ten_minutes_run_as_written(tmp_path: Path) -> None:
    # The clone's folders the commands read; recordings/ is made by the commands.
    (tmp_path / "scenarios").symlink_to(SCENARIOS)
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "data").symlink_to(DATA)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    printed: dict[str, str] = {}
    for command in walkthrough()[1:]:
        argv = shlex.split(command)[1:]
        r = subprocess.run(
            [*monopic_command(), *argv], cwd=tmp_path, env=env,
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        expected = 1 if argv[0] == "view" else 0  # no display: it says how, status 1
        assert r.returncode == expected, f"{command}\n{r.stdout}\n{r.stderr}"
        printed[" ".join(argv)] = r.stdout + r.stderr
    rec = tmp_path / "recordings"
    assert printed["--version"].startswith("monopic ")
    assert (rec / "walk.mp4").stat().st_size > 10_000
    assert (rec / "walk.csv").read_text().count("\n") > 30
    assert (rec / "case5.rrd").read_bytes()[:3] == b"RRF"
    assert "rerun --serve-web recordings/case5.rrd" in printed["view recordings/case5.rrd"]
    assert (
        "recording: recordings/case5.rrd"
        in printed["record 5 --duration 2 --out recordings/case5.rrd"]
    )
    dry = printed["sweep scenarios/sweeps/first.toml --dry-run"]
    assert "2 runs in 2 families" in dry and "time: about" in dry
    assert "2 runs finished" in printed["sweep scenarios/sweeps/first.toml"]
    lines = (rec / "first.jsonl").read_text().splitlines()
    assert len(lines) == 2 and all(json.loads(line)["frames"] > 0 for line in lines)
    assert (rec / "first_report" / "report.md").is_file()
    assert (
        "| rules/ground | 1 |"
        in printed["closed-loop --cases 5 --robot-speeds 2 --policies rules/ground"]
    )


def own_scenario_section() -> str:
    text = (ROOT / "README.md").read_text()
    return text.split("## Your own scenario file", 1)[1].split("\n## ", 1)[0]


def fenced(section: str, language: str) -> list[str]:
    """The bodies of the section's ```LANGUAGE blocks, in order."""
    return [part.split("```", 1)[0] for part in section.split(f"```{language}\n")[1:]]


def test_the_own_scenario_section_names_its_files_and_runs_monopic_only() -> None:
    section = own_scenario_section()
    files = [
        block.splitlines()[0].split(":", 1)[0].lstrip("# ") for block in fenced(section, "toml")
    ]
    assert files == ["my/child_parked_30.toml", "my/sweep.toml"]
    (commands,) = fenced(section, "sh")
    assert all(c.startswith(f"{MONOPIC} ") for c in commands.splitlines() if c.strip())
    assert len(fenced(section, "python")) == 1


@pytest.mark.slow
def test_a_users_own_scenario_file_runs_through_record_closed_loop_sweep_and_the_env(
    tmp_path: Path,
) -> None:
    """The README's "Your own scenario file" as a new user would run it: the files written
    as shown, each command as written, the environment made from the file. The file's own
    values are what runs (its 8.33 m/s), and a swept key reaches the runs."""
    section = own_scenario_section()
    (tmp_path / "scenarios").symlink_to(SCENARIOS)
    for block in fenced(section, "toml"):
        name = block.splitlines()[0].split(":", 1)[0].lstrip("# ")
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(block)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    printed: dict[str, str] = {}
    for command in fenced(section, "sh")[0].splitlines():
        argv = shlex.split(command)[1:]
        r = subprocess.run(
            [*monopic_command(), *argv], cwd=tmp_path, env=env,
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert r.returncode == 0, f"{command}\n{r.stdout}\n{r.stderr}"
        printed[argv[0] + (" --dry-run" if "--dry-run" in argv else "")] = r.stdout + r.stderr
    rec = tmp_path / "recordings"
    assert (rec / "child.rrd").read_bytes()[:3] == b"RRF"
    assert "contact at" in printed["record"] or "contact: none" in printed["record"]
    assert "robot speeds 8.33 m/s: each file's own" in printed["closed-loop"]
    assert "2 runs in 1 families" in printed["sweep --dry-run"]
    rows = [json.loads(line) for line in (rec / "my-sweep.jsonl").read_text().splitlines()]
    assert sorted(r["params"]["path.impact_point"] for r in rows) == [0.25, 0.75]
    assert (rec / "my-sweep_report" / "report.md").is_file()
    (python,) = fenced(section, "python")
    script = python + (
        "\nassert obs.shape == (432, 768, 3)"
        "\nassert abs(info['robot']['speed'] - (8.33 - 9.0 / 15)) < 0.01, info['robot']"
        "\nprint('ok')\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, env=env,
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr
