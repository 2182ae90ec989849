"""Which code made a result: a digest of the pipeline's and the simulator's files.

A sweep resumes by run id. Without this, a results file written before a change to the
pipeline would be "resumed" after it, and a report would silently mix (or wholly show)
the old code's numbers. Every result line carries the digest; a sweep resumes only lines
of its own code.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import monopic
import sim

UNKNOWN = "unknown"  # result lines written before lines carried a code version


def code_version() -> str:
    """12 hex digits over every file of the monopic and sim packages (models included).

    Content only (not times or the install location), so a clean clone and a working
    copy with the same files agree.
    """
    digest = hashlib.sha256()
    for package in (monopic, sim):
        base = Path(package.__file__).resolve().parent
        for path in sorted(base.rglob("*")):
            if not path.is_file() or "__pycache__" in path.parts or path.suffix == ".pyc":
                continue
            digest.update(str(path.relative_to(base.parent)).encode() + b"\0")
            digest.update(path.read_bytes())
    return digest.hexdigest()[:12]
