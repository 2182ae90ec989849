"""Argument types shared by sub-commands: each rejects bad values with one clear line."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from monopic.errors import UserError


def ranged(
    low: float | None = None,
    high: float | None = None,
    *,
    integer: bool = False,
    open_low: bool = False,
    open_high: bool = False,
) -> Callable[[str], float]:
    """An argument type that accepts a finite number in [low, high] (an end excluded with
    `open_low` / `open_high`; an integer with `integer`), refusing anything else in one line.

    Its `range_text` ('>= 1', '(0, 60]') is what the option's help shows: tests/
    test_cli_help.py checks every ranged option's help against it and tries the values
    just inside and outside each end, so the help cannot drift from the check."""

    if low is None and high is None:
        raise ValueError("a range needs a low or a high end")
    if low is None:
        text = f"{'<' if open_high else '<='} {_shown(high)}"
    elif high is None:
        text = f"{'>' if open_low else '>='} {_shown(low)}"
    else:
        ends = f"{_shown(low)}, {_shown(high)}"
        text = f"{'(' if open_low else '['}{ends}{')' if open_high else ']'}"

    def check(value_text: str) -> float:
        try:
            value = int(value_text) if integer else float(value_text)
        except ValueError:
            kind = "an integer" if integer else "a number"
            raise argparse.ArgumentTypeError(f"expected {kind}, got {value_text!r}") from None
        below = low is not None and (value <= low if open_low else value < low)
        above = high is not None and (value >= high if open_high else value > high)
        if not math.isfinite(value) or below or above:
            shown = f"in {text}" if text[0] in "[(" else text
            raise argparse.ArgumentTypeError(f"must be {shown}, got {value_text!r}")
        return value

    check.range_text = text  # type: ignore[attr-defined]
    check.low, check.high = low, high  # type: ignore[attr-defined]
    check.integer = integer  # type: ignore[attr-defined]
    check.open_low, check.open_high = open_low, open_high  # type: ignore[attr-defined]
    return check


def _shown(value: float) -> str:
    """A range's end as people write it: whole numbers in full (2147483647, not 2.14748e+09)."""
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


class DeprecatedAlias(argparse.Action):
    """An option's old name, kept working: it sets the new option's value and says on
    stderr, once per use, that the name is deprecated and which to use (CHANGELOG.md)."""

    def __init__(self, option_strings: list[str], dest: str, new: str, **kwargs: Any) -> None:
        self.new = new
        super().__init__(option_strings, dest, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        print(
            f"{parser.prog}: warning: {option_string} is deprecated, use {self.new}",
            file=sys.stderr,
        )
        setattr(namespace, self.dest, True if self.nargs == 0 else values)


def deprecated_alias(
    parser: argparse.ArgumentParser | Any, new: argparse.Action, *old: str
) -> None:
    """Add `old` names for the option `new` (its destination and type), hidden from --help.

    `parser` may be an argument group. The alias's default is SUPPRESS, so the new
    option's default stands when the old name is not given."""
    parser.add_argument(
        *old,
        dest=new.dest,
        type=new.type,
        choices=new.choices,
        metavar=new.metavar,
        nargs=new.nargs,
        action=DeprecatedAlias,
        new=new.option_strings[0],
        default=argparse.SUPPRESS,
        help=argparse.SUPPRESS,
    )


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text!r}")
    return value


def non_negative_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


positive_float.range_text = "> 0"  # type: ignore[attr-defined]
non_negative_float.range_text = ">= 0"  # type: ignore[attr-defined]


def parameter_limit(text: str) -> tuple[str, float]:
    """'NAME=VALUE' with a finite number: a swept parameter and a limit on it."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"expected PARAM=VALUE, got {text!r}")
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(number):
        raise argparse.ArgumentTypeError(f"{name}: must be finite, got {value!r}")
    return name.strip(), number


def _integer_at_least(low: int, name: str) -> Callable[[str], int]:
    """An argparse type: an integer of at least `low`, its range stated for the help."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be >= {low}, got {text!r}")
        return value

    parse.__name__ = parse.__qualname__ = name
    parse.range_text = f">= {low}"  # type: ignore[attr-defined]
    parse.integer = True  # type: ignore[attr-defined]
    return parse


positive_int = _integer_at_least(1, "positive_int")
non_negative_int = _integer_at_least(0, "non_negative_int")


def output_folder(folder: Path, option: str) -> Path:
    """Create the folder an output goes to, parents too (`mkdir -p`); one line if it cannot.

    The one rule for every command's output paths, given or default: the folder is made
    as needed, and the output itself appears whole or not at all. Call it once the
    input is checked, so a mistake leaves no new folder behind.
    """
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise UserError(f"{option} {folder}: a file is in the way of this folder") from None
    except OSError as err:
        raise UserError(f"{option} {folder}: cannot create it: {err.strerror or err}") from None
    return folder


def output_file(path: Path, option: str) -> Path:
    """`path`, its folder created (output_folder); a folder at `path` itself is refused."""
    if path.is_dir():
        raise UserError(f"{option} {path}: is a folder; give a file name")
    output_folder(path.parent, option)
    return path
