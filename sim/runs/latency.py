"""The latency a closed-loop run applies to each processed frame, and what it measured.

A run's brake acts on a frame's warning once the pipeline has processed that frame, so
each frame's latency moves the brake. Three sources: a fixed figure (what a real-time
implementation would guarantee, and what makes a run depend on nothing but its scenario
and seed), the pipeline's own measured `stage_ms["total"]` of that frame (the host's
speed and load), or a recorded sequence (a replay: the measured latencies an earlier run
kept, so that run is made again exactly). The measured latencies are kept in every case,
one per processed frame.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

DECLARED, FIXED, MEASURED = "declared", "fixed", "measured"


@dataclass(frozen=True)
class LatencySetting:
    """The latency a run applies: a declared figure (the Euro NCAP car file's), a fixed
    figure given on the command line, or the pipeline's measured one per frame (`ms` None).
    Results rows keep it as `latency` (to_json), so a row says what its run applied."""

    source: str  # DECLARED, FIXED or MEASURED
    ms: float | None

    def __post_init__(self) -> None:
        if (self.source == MEASURED) != (self.ms is None) or self.source not in (
            DECLARED, FIXED, MEASURED,
        ):  # fmt: skip
            raise ValueError(f"not a latency setting: {self.source!r} {self.ms!r}")

    def describe(self) -> str:
        """As reports say it: "declared 50 ms", "fixed 40 ms", "measured per frame"."""
        return "measured per frame" if self.ms is None else f"{self.source} {self.ms:g} ms"

    def to_json(self) -> dict[str, Any]:
        return {"source": self.source, "applied_ms": self.ms}

    @classmethod
    def from_json(cls, data: Any) -> LatencySetting:
        """A row's `latency` back; ValueError if it is not one."""
        if not isinstance(data, dict) or set(data) != {"source", "applied_ms"}:
            raise ValueError(f"not a latency setting: {data!r}")
        ms = data["applied_ms"]
        if ms is not None and (isinstance(ms, bool) or not isinstance(ms, int | float)):
            raise ValueError(f"not a latency setting: {data!r}")
        return cls(data["source"], None if ms is None else float(ms))


def replay_latencies(row: dict[str, Any]) -> list[float] | None:
    """What a closed-loop or AEB run needs (`latencies_ms=`) to make a row's run again exactly.

    A run that applied the measured latency: its measured per-frame latencies. A run that
    applied a declared or fixed figure: None (its setting carries the figure, and nothing
    else of the run depended on the host).
    """
    if row["latency"]["source"] != MEASURED:
        return None
    return [float(v) for v in row["outcome"]["latencies_ms"]]


@dataclass
class AppliedLatency:
    """The latency each processed frame gets: fixed, recorded (a replay) or measured.

    `latency_ms` a number: that figure on every frame. `recorded`: the k-th processed
    frame gets the k-th value (a replay of a run made with the measured latency). Neither:
    the pipeline's own measured latency of that frame. `measured` keeps the pipeline's
    measured latencies either way, one per processed frame.
    """

    latency_ms: float | None = None
    recorded: Sequence[float] | None = None
    measured: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.latency_ms is not None and self.recorded is not None:
            raise ValueError("give a fixed latency or recorded latencies, not both")
        if self.latency_ms is not None and not (
            math.isfinite(self.latency_ms) and self.latency_ms >= 0
        ):
            raise ValueError(f"latency must be finite and >= 0 ms, got {self.latency_ms}")
        if self.recorded is not None:
            for v in self.recorded:
                if not (math.isfinite(v) and v >= 0):
                    raise ValueError(f"recorded latencies must be finite and >= 0 ms, got {v}")

    def next_ms(self, measured_ms: float) -> float:
        """The latency (ms) applied to the next processed frame, whose pipeline took
        `measured_ms`."""
        k = len(self.measured)
        self.measured.append(measured_ms)
        if self.recorded is not None:
            if k >= len(self.recorded):
                raise ValueError(
                    f"recorded latencies end after {len(self.recorded)} frames; this run "
                    "processes more (not the run they were recorded in)"
                )
            return float(self.recorded[k])
        return measured_ms if self.latency_ms is None else self.latency_ms

    def check_used(self) -> None:
        """A replay must process exactly the recorded frames: anything else is another run."""
        if self.recorded is not None and len(self.measured) != len(self.recorded):
            raise ValueError(
                f"recorded latencies cover {len(self.recorded)} frames; this run processed "
                f"{len(self.measured)} (not the run they were recorded in)"
            )
