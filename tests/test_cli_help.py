"""`monopic --help` and every sub-command's: a description, help and defaults everywhere."""

from __future__ import annotations

import argparse
import subprocess
import sys
from importlib.metadata import version

import pytest

from monopic.cli.main import build_parser


def sub_parsers(parser: argparse.ArgumentParser, prefix: str = "") -> dict[str, object]:
    """Every (nested) sub-command's parser by its command line, e.g. 'tree train'."""
    out: dict[str, argparse.ArgumentParser] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                out[f"{prefix}{name}"] = sub
                out.update(sub_parsers(sub, f"{prefix}{name} "))
    return out


COMMANDS = sub_parsers(build_parser())


def test_every_command_is_there() -> None:
    expected = {"video", "tree", "tree train", "tree show", "tree judge", "tree sensitivity",
                "replay", "view", "record", "sweep", "report", "dataset",
                "closed-loop"}  # fmt: skip
    assert expected <= set(COMMANDS)


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_has_a_description_and_every_option_help_and_its_default(
    command: str,
) -> None:
    parser = COMMANDS[command]
    assert parser.description and len(parser.description) > 30, command
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
            continue
        name = action.option_strings[0] if action.option_strings else action.dest
        assert action.help, f"{command} {name}: no help"
        shows_default = action.default not in (None, False, argparse.SUPPRESS, [])
        if action.option_strings and shows_default and not action.required:
            assert "default" in action.help, f"{command} {name}: default not in its help"


def test_version() -> None:
    r = subprocess.run(
        [sys.executable, "-m", "monopic", "--version"], capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 0 and r.stdout.strip() == f"monopic {version('monopic')}"
