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


# Numeric options whose range is not their argument type's but the scenario's own checks
# (a case placement is built and checked as a scenario file): their help ranges are tried
# end by end against those checks in tests/sim/test_cli_errors.py.
CHECKED_BY_THE_SCENARIO = {
    ("record", f"--{name}")
    for name in ("distance", "lateral-offset", "pedestrian-speed", "robot-speed", "duration",
                 "seed")
}  # fmt: skip


def numeric_options() -> list[tuple[str, argparse.Action]]:
    """Every option of every command whose value is a number (by its argument type)."""
    out = []
    for command, parser in sorted(COMMANDS.items()):
        for action in parser._actions:
            if not action.option_strings or action.help == argparse.SUPPRESS:
                continue
            kind = action.type
            if kind in (int, float) or hasattr(kind, "range_text"):
                out.append((command, action))
    return out


def test_every_numeric_option_states_its_checked_range() -> None:
    """A number option's type is a ranged check (monopic.cli.args) and its help shows that
    range, or the option's range is the scenario's (CHECKED_BY_THE_SCENARIO)."""
    for command, action in numeric_options():
        name = action.option_strings[0]
        if (command, name) in CHECKED_BY_THE_SCENARIO:
            continue
        text = getattr(action.type, "range_text", None)
        assert text is not None, f"{command} {name}: a bare int/float type, no checked range"
        assert text in (action.help or ""), f"{command} {name}: help lacks its range {text!r}"


def _just(value: float, integer: bool, outward: int) -> str:
    step = 1 if integer else 1e-3
    return str(int(value) + outward) if integer else repr(value + outward * step)


@pytest.mark.parametrize(
    ("command", "option"),
    [(c, a.option_strings[0]) for c, a in numeric_options() if hasattr(a.type, "range_text")],
)
def test_each_ranged_option_takes_its_ends_and_refuses_just_beyond(command: str, option: str):
    """Parsed as the command line parses it: the ends stated in the help pass (or the
    value just inside an open end), the values just beyond are one-line usage errors."""
    parser = COMMANDS[command]
    action = next(a for a in parser._actions if option in a.option_strings)
    text = action.type.range_text
    integer = getattr(action.type, "integer", action.type.__name__ == "positive_int")
    low = getattr(action.type, "low", None)
    high = getattr(action.type, "high", None)
    if low is None and high is None:  # the plain checks: '> 0', '>= 0', '>= 1'
        low = float(text.split()[-1])
    open_low = text.startswith(("(", ">")) and not text.startswith(">=")
    open_high = getattr(action.type, "open_high", False)
    inside, outside = [], []
    if low is not None:
        inside.append(_just(low, integer, 1) if open_low else _just(low, integer, 0))
        outside.append(_just(low, integer, 0) if open_low else _just(low, integer, -1))
    if high is not None:
        inside.append(_just(high, integer, -1) if open_high else _just(high, integer, 0))
        outside.append(_just(high, integer, 0) if open_high else _just(high, integer, 1))
    for value in inside:
        action.type(value)
    for value in outside:
        with pytest.raises(argparse.ArgumentTypeError):
            action.type(value)


def test_every_renamed_option_keeps_its_old_name_as_a_warning_alias(capsys) -> None:
    """Each deprecated name sets its new option's value, says once on stderr which name
    to use, and is listed in CHANGELOG.md."""
    from monopic.cli.args import DeprecatedAlias
    from tests.paths import ROOT

    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    aliases = [
        (command, action)
        for command, parser in COMMANDS.items()
        for action in parser._actions
        if isinstance(action, DeprecatedAlias)
    ]
    assert {(c, a.option_strings[0]) for c, a in aliases} >= {
        ("record", "--rrd"), ("ncap", "--speeds"), ("ncap", "--seeds"), ("video", "--speed")
    }  # fmt: skip
    for command, action in aliases:
        parser = COMMANDS[command]
        old = action.option_strings[0]
        value = "1" if action.nargs != 0 else None
        argv = [old] if value is None else [old, value]
        namespace = argparse.Namespace()
        action(parser, namespace, action.type(value) if action.type and value else value, old)
        assert getattr(namespace, action.dest) == (True if value is None else action.type(value)
                                                   if action.type else value)  # fmt: skip
        err = capsys.readouterr().err
        assert err == f"{parser.prog}: warning: {old} is deprecated, use {action.new}\n", argv
        assert f"`{old}`" in changelog and f"{action.new}`" in changelog, (command, old)
        assert old not in parser.format_help().replace(action.new, ""), (command, old)


def test_a_command_with_actions_names_each_in_its_description() -> None:
    """`monopic tree --help` once described two of its four actions."""
    for command, parser in COMMANDS.items():
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction) and command:
                for name in action.choices:
                    assert f"{command} {name}" in (parser.description or ""), (command, name)
