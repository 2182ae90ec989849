"""Argument types shared by sub-commands: each rejects bad values with one clear line."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from monopic.errors import UserError


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


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text!r}")
    return value


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
