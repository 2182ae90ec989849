"""The reports' Markdown pieces: tables and the way numbers are shown in them.

One module below every report section (the sweep report, its beside and triage sections),
so that a section never imports the report that includes it."""

from __future__ import annotations

import math
from collections.abc import Sequence


def pct(value: float) -> str:
    return "-" if math.isnan(value) else f"{100 * value:.0f} %"


def num(value: float, digits: int = 2) -> str:
    return "-" if math.isnan(value) else f"{value:.{digits}f}"


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """A Markdown table (which also reads well as plain text)."""
    widths = [max(len(str(c)) for c in col) for col in zip(header, *rows, strict=True)]

    def line(cells: Sequence[str]) -> str:
        return "| " + " | ".join(str(c).ljust(w) for c, w in zip(cells, widths, strict=True)) + " |"

    return [line(header), "|" + "|".join("-" * (w + 2) for w in widths) + "|"] + [
        line(r) for r in rows
    ]
