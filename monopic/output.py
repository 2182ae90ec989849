"""Output files that appear whole or not at all: write a temporary name, rename when done."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def temporary_sibling(path: Path) -> Path:
    """A hidden name beside `path` with the same suffix (some writers need the suffix)."""
    return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")


@contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """Yield a temporary path; move it onto `path` on success, delete it on any error."""
    path = Path(path)
    tmp = temporary_sibling(path)
    try:
        yield tmp
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    if not tmp.exists():
        raise RuntimeError(f"nothing was written to {path}")
    os.replace(tmp, path)


def write_text_atomically(path: Path, text: str) -> None:
    """Write a whole text file under a temporary name, then rename it into place."""
    with atomic_path(Path(path)) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="")
