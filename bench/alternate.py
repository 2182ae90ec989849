"""Two or more models timed side by side on the same inputs, alternated (A B B A ...).

The int8 judges (bench/int8_landmarks.py, bench/int8_detector.py) compare a candidate with
the shipped float model in the same minutes: on a shared, noisy host only a ratio measured
this way means anything.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np


def alternated_ms(
    calls: Mapping[str, Callable[[Any], object]],
    inputs: Sequence[Any],
    rounds: int,
    warmup: int = 5,
) -> dict[str, Any]:
    """Median ms per call of each callable over `inputs`, after `warmup` untimed calls
    each; rounds alternate the order (A B, then B A). Also the 1-minute load average range
    seen at the start of each round."""
    for call in calls.values():
        for x in inputs[:warmup]:
            call(x)
    samples: dict[str, list[float]] = {k: [] for k in calls}
    loads = []
    order = list(calls)
    for r in range(rounds):
        loads.append(os.getloadavg()[0])
        for k in order if r % 2 == 0 else order[::-1]:
            for x in inputs:
                t0 = time.perf_counter()
                calls[k](x)
                samples[k].append(1e3 * (time.perf_counter() - t0))
    return {
        "ms": {k: float(np.median(v)) for k, v in samples.items()},
        "load_min": min(loads),
        "load_max": max(loads),
    }
