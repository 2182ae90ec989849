"""The options of every command that runs many runs: where they run (local worker
processes or a Ray cluster, sim.runs.executors) and how many workers, with one set of
checks and one way to build the executor."""

from __future__ import annotations

import argparse
import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from monopic.cli.args import positive_int
from monopic.errors import UserError


def add_executor_options(p: argparse.ArgumentParser, ray_note: str = "") -> None:
    """--workers, --executor and --address; `ray_note` adds what Ray needs of this command."""
    p.add_argument(
        "--workers", type=positive_int, help="local worker processes (>= 1; default: all cores)"
    )
    note = f"; {ray_note}" if ray_note else ""
    p.add_argument(
        "--executor",
        choices=("local", "ray"),
        default="local",
        help=f"local worker processes, or Ray tasks (extra `ray`{note}) (default %(default)s)",
    )
    p.add_argument("--address", help="Ray cluster address for --executor ray (e.g. host:6379)")


def check_executor_options(args: argparse.Namespace) -> None:
    """One line for an option the chosen executor cannot apply."""
    if args.address and args.executor != "ray":
        raise UserError("--address is for --executor ray")
    if args.workers and args.executor == "ray":
        raise UserError("--workers is for --executor local (Ray schedules by the cluster's CPUs)")


def workers_of(args: argparse.Namespace) -> int | None:
    """The local workers the runs will have; None on Ray (the cluster's CPUs, unknown here)."""
    return None if args.executor == "ray" else (args.workers or os.cpu_count() or 1)


def make_executor(args: argparse.Namespace, run: Any = None) -> Any:
    """The executor the options ask for, running `run` on each spec (default: a sweep run)."""
    from sim.runs.executors import local_executor, ray_executor

    extra = {} if run is None else {"run": run}
    if args.executor == "ray":
        return ray_executor(args.address, **extra)
    return local_executor(args.workers, **extra)


@contextmanager
def logs_above_the_bar(executor: str, address: str | None = None) -> Iterator[None]:
    """Ray's log lines (its start, the code upload, its warnings) written above the sweep's
    progress bar through tqdm, instead of into the bar's line.

    Ray logs through the 'ray' logger's own stderr handler, which exists once ray is
    imported, so ray is imported here, before the sweep, as the executor imports it: with
    the executor's connect timeouts set when joining a cluster (Ray reads them as it
    loads; sim.runs.executors.RAY_CONNECT_ENV). Lines Ray's C++ core writes to stderr
    itself bypass logging and are not redirected."""
    if executor != "ray":
        yield
        return
    from sim.runs.executors import RAY_CONNECT_ENV

    joining = (address or os.environ.get("RAY_ADDRESS", "local")) != "local"
    added = {k: v for k, v in RAY_CONNECT_ENV.items() if joining and k not in os.environ}
    os.environ.update(added)
    try:
        import ray  # noqa: F401
    except ImportError:  # the executor says how to install it
        yield
        return
    finally:
        for key in added:
            os.environ.pop(key, None)
    from tqdm.contrib.logging import logging_redirect_tqdm

    with logging_redirect_tqdm(loggers=[logging.getLogger("ray")]):
        yield
