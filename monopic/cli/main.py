"""`monopic` command: one sub-command per job, each registered by its own module."""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from collections.abc import Sequence
from importlib.metadata import EntryPoint, entry_points, version

from monopic.errors import UserError

# The commands are read from the `monopic.commands` entry-point group: each entry names a
# `register(subparsers)` that adds its sub-command(s) and sets `func=handler(args) -> int`
# as the parser default. This package lists its own (video, tree, replay, view) and the
# simulator lists its own in the same group (pyproject.toml), so the pipeline never
# imports the simulator and another installed package adds commands without editing this.
COMMAND_GROUP = "monopic.commands"


def command_entry_points() -> list[EntryPoint]:
    """The installed commands, by name."""
    return sorted(entry_points(group=COMMAND_GROUP), key=lambda ep: ep.name)


class OneLineParser(argparse.ArgumentParser):
    """Usage mistakes end in one clear line (and exit code 2), not a usage dump."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="monopic",
        description="MonoPIC pedestrian intention pipeline and test bed. `monopic COMMAND "
        "--help` describes each command; README.md has a first-ten-minutes walkthrough.",
    )
    parser.add_argument(
        "--version",
        action="version",
        version=f"monopic {version('monopic')}",
        help="print the version and stop",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    found = command_entry_points()
    if not found:
        raise UserError(
            f"no commands in the {COMMAND_GROUP!r} entry-point group: install the project "
            "(pip install -e .) so that its entry points exist"
        )
    for ep in found:
        try:
            register = ep.load()
        except Exception as err:  # a broken plug-in must not take the other commands down
            print(
                f"monopic: command {ep.name!r} ({ep.value}) failed to load: {err}", file=sys.stderr
            )
            continue
        register(sub)
    return parser


class Terminated(BaseException):
    """SIGTERM, raised so that cleanup (stopping workers, closing files) runs as on Ctrl-C.

    A BaseException, as KeyboardInterrupt is: an `except Exception` that wraps errors (the
    renderer's "cannot create a GL context", a run's failure record) must not swallow a stop
    that lands inside it.
    """


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


def main(argv: Sequence[str] | None = None) -> int:
    """Run one sub-command; every way it ends is one line and an exit code.

    0 done, 1 the command's own failure (e.g. failed runs), 2 bad input (UserError),
    130 interrupted (SIGINT, Ctrl-C), 143 terminated (SIGTERM), 141 the output's reader
    went away (a closed pipe). The SIGTERM handler goes
    in first, so a stop while the commands load is answered like one mid-run.
    """
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if in_main_thread else None
    command = "monopic"
    try:
        try:
            parser = build_parser()
        except UserError as err:
            print(f"monopic: error: {err}", file=sys.stderr)
            return 2
        args = parser.parse_args(argv)
        command = f"monopic {args.command}"
        try:
            return int(args.func(args) or 0)
        except UserError as err:
            print(f"{command}: error: {err}", file=sys.stderr)
            return 2
    except KeyboardInterrupt:
        print(f"{command}: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print(f"{command}: terminated", file=sys.stderr)
        return 143
    except BrokenPipeError:
        # The reader went away (`monopic ... | head`): stop quietly, as other tools do.
        # Python would flush stdout again at exit and print a traceback for that too.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    finally:
        if in_main_thread:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
