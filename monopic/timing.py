"""Per-frame stage timing: a small stopwatch that records named laps in milliseconds."""

from __future__ import annotations

import time
from dataclasses import dataclass, field


@dataclass
class StageTimer:
    laps: dict[str, float] = field(default_factory=dict)
    _t: float = field(default_factory=time.perf_counter)

    def lap(self, stage: str) -> None:
        """Record the time since the previous lap under `stage` (ms)."""
        now = time.perf_counter()
        self.laps[stage] = self.laps.get(stage, 0.0) + (now - self._t) * 1e3
        self._t = now

    def restart(self) -> None:
        self._t = time.perf_counter()
