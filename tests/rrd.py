"""Reading .rrd files back with rerun's own reader, for the tests."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

from rerun.chunk import RrdReader


def rows_per_entity(path: Path) -> Counter:
    """Number of non-static rows logged per entity path."""
    counts: Counter = Counter()
    for chunk in RrdReader(str(path)).stream().to_chunks():
        if not chunk.is_static:
            counts[chunk.entity_path] += chunk.num_rows
    return counts


def column(path: Path, entity: str, name: str) -> list:
    """All values of one component column of an entity, in file order."""
    values: list = []
    for chunk in RrdReader(str(path)).stream().to_chunks():
        if chunk.entity_path == entity and not chunk.is_static:
            batch = chunk.to_record_batch().to_pydict()
            values.extend(batch[name])
    return values
