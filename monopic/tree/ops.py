"""A tally of elementary operations, so code can report what one call actually cost.

The paper counts "calculations per prediction" (additions, subtractions, multiplications).
We count three kinds separately, because a comparison is not an addition:
- comparisons: <, <=, >, >=, ==, finite checks, and one test per tree node visited;
- arithmetic: +, -, *, /, negation;
- functions: abs, sqrt, acos and similar library calls.
Container bookkeeping (appends, length checks, loop control) is not counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Ops:
    """How many operations of each kind were performed."""

    comparisons: int = 0
    arithmetic: int = 0
    functions: int = 0

    @property
    def total(self) -> int:
        return self.comparisons + self.arithmetic + self.functions

    def __add__(self, other: Ops) -> Ops:
        return Ops(
            self.comparisons + other.comparisons,
            self.arithmetic + other.arithmetic,
            self.functions + other.functions,
        )

    def __mul__(self, k: int) -> Ops:
        return Ops(self.comparisons * k, self.arithmetic * k, self.functions * k)

    def describe(self) -> str:
        return (
            f"{self.total} ({self.comparisons} comparisons, {self.arithmetic} arithmetic, "
            f"{self.functions} functions)"
        )


class ComparisonCounter:
    """Performs comparisons and counts them, so a count cannot drift from the code."""

    def __init__(self) -> None:
        self.comparisons = 0
        self.functions = 0

    def lt(self, a: float, b: float) -> bool:
        self.comparisons += 1
        return a < b

    def le(self, a: float, b: float) -> bool:
        self.comparisons += 1
        return a <= b

    def finite(self, x: float) -> bool:
        self.comparisons += 1
        return math.isfinite(x)

    def abs(self, x: float) -> float:
        self.functions += 1
        return abs(x)

    @property
    def ops(self) -> Ops:
        return Ops(comparisons=self.comparisons, functions=self.functions)
