"""`monopic` command: one sub-command per job, each registered by its own module."""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading
from collections.abc import Sequence

from monopic.errors import UserError

# Each module defines register(subparsers) which adds its sub-command(s) and sets
# `func=handler(args) -> int` as the parser default.
COMMAND_MODULES = (
    "monopic.cli.video",
    "monopic.cli.tree",
    "monopic.cli.replay",
    "monopic.cli.record",
    "monopic.cli.view",
    "monopic.cli.dataset",
    "monopic.cli.closed_loop",
    "monopic.cli.sweep",
    "monopic.cli.report",
)


class OneLineParser(argparse.ArgumentParser):
    """Usage mistakes end in one clear line (and exit code 2), not a usage dump."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="monopic", description="MonoPIC pedestrian intention pipeline and test bed"
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


class Terminated(Exception):
    """SIGTERM, raised so that cleanup (stopping workers, closing files) runs as on Ctrl-C."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if in_main_thread else None
    try:
        return int(args.func(args) or 0)
    except UserError as err:
        print(f"monopic {args.command}: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"monopic {args.command}: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print(f"monopic {args.command}: terminated", file=sys.stderr)
        return 143
    finally:
        if in_main_thread:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
