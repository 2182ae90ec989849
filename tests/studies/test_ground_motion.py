"""studies.ground_motion.estimators: the per-family table counts as the sweep's metrics do."""

from __future__ import annotations

import numpy as np

from sim.analysis.metrics import FrameCounts, RunOutcome
from studies.ground_motion import estimators


def outcome(
    family: str, kind: str, collision: bool, warned: bool, onset: float | None
) -> RunOutcome:
    return RunOutcome(
        id=f"{family}/{onset}", family=family, kind=kind, scale="small", case=5,
        robot_speed=1.0, horizon=1.5, collision_run=collision,
        contact_time=4.0 if collision else None, warned=warned, onset=onset,
        onset_latency=onset, frames=FrameCounts(),
    )  # fmt: skip


def test_by_family_counts_collisions_warned_a_second_ahead_and_near_misses_warned() -> None:
    outs = [
        outcome("cross", "collision", True, True, 2.5),  # 1.5 s ahead: counts
        outcome("cross", "collision", True, True, 3.5),  # 0.5 s ahead: does not
        outcome("cross", "collision", True, False, None),  # never warned
        outcome("kerb", "near-miss", False, True, None),  # a near miss warned
        outcome("kerb", "near-miss", False, False, None),
        outcome("kerb", "near-miss", True, True, 2.0),  # a near miss that met: a collision
        outcome("look", "collision", False, True, None),  # neither: not counted
    ]
    j = estimators.Judged("x", 1.0, outs, np.zeros(1))
    assert j.by_family() == {"cross": (1, 3), "kerb": (2, 3)}


def test_the_column_noise_option_reads_px_plus_per_height_or_row() -> None:
    import pytest

    assert estimators.column_noise("0.3+0.01") == (0.3, 0.01)
    assert estimators.column_noise("row") == (None, 0.0)
    for bad in ("0.3", "a+b", "0+0.01", "0.3+-1"):
        with pytest.raises(SystemExit, match="--column-noise"):
            estimators.column_noise(bad)
