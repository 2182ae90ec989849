"""`monopic view FILE.rrd`: open a recording in the rerun viewer, or say how without a display."""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

from monopic.errors import UserError

RRD_MAGIC = b"RRF"  # every .rrd starts with it (RRF2 in rerun 0.41)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "view",
        help="open a .rrd recording in the rerun viewer",
        description="Open a .rrd recording in the rerun viewer (the `rerun` executable that "
        "comes with rerun-sdk). Without a display ($DISPLAY and $WAYLAND_DISPLAY unset) it "
        "prints how to view the file instead and exits with status 1.",
    )
    p.add_argument("file", type=Path, metavar="FILE.rrd", help="a .rrd file (record, sweep)")
    p.set_defaults(func=run)


def check_recording(path: Path) -> None:
    """UserError unless `path` is a readable rerun recording."""
    if not path.exists():
        raise UserError(f"{path}: no such file")
    if path.is_dir():
        raise UserError(f"{path}: is a folder, not a .rrd recording")
    try:
        with path.open("rb") as fh:
            head = fh.read(4)
    except OSError as err:
        raise UserError(f"{path}: cannot read: {err.strerror or err}") from None
    if not head.startswith(RRD_MAGIC):
        raise UserError(f"{path}: not a rerun recording (starts with {head!r}, not {RRD_MAGIC!r})")


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def rerun_executable() -> str:
    """The viewer installed beside this Python (a venv need not be on PATH), else on PATH."""
    beside = Path(sys.executable).parent / "rerun"
    if beside.is_file() and os.access(beside, os.X_OK):
        return str(beside)
    found = shutil.which("rerun")
    if found is None:
        raise UserError(
            "the rerun viewer executable is not installed (it comes with rerun-sdk==0.41.0)"
        )
    return found


def run(args: argparse.Namespace) -> int:
    path: Path = args.file
    check_recording(path)
    if not has_display():
        print(
            f"monopic view: no display ($DISPLAY and $WAYLAND_DISPLAY are unset): run "
            f"`rerun {path}` on a machine with a display, or `rerun --serve-web {path}` here "
            f"and open the http://<this host>:9090 address it prints in a browser (screenshots "
            f"without a display: .venv/bin/python -m tools.view.screenshot {path} --at SECONDS)",
            file=sys.stderr,
        )
        return 1
    return subprocess.call([rerun_executable(), str(path)])
