"""bench/ncap_latency.py's figures from result rows made by hand (no run is timed here)."""

from __future__ import annotations

import pytest

from bench.ncap_latency import declared_figure, summarise


def test_the_declared_figure_is_the_p95_rounded_up_to_5_ms() -> None:
    assert declared_figure(463.3) == 465.0
    assert declared_figure(465.0) == 465.0  # already a multiple: kept
    assert declared_figure(465.01) == 470.0
    assert declared_figure(0.2) == 5.0
    assert declared_figure(12.0, step=10.0) == 20.0
    with pytest.raises(ValueError):
        declared_figure(float("nan"))


def test_percentiles_are_over_every_frame_of_every_run() -> None:
    rows = [
        {"outcome": {"latencies_ms": [10.0] * 18 + [200.0, 300.0]}},
        {"outcome": {"latencies_ms": [20.0] * 20}},
    ]
    res = summarise(rows)
    assert (res["runs"], res["frames"]) == (2, 40)
    assert res["p50_ms"] == 20.0 and res["max_ms"] == 300.0
    # 40 frames: the p95 lies between the 38th and 39th smallest (20 and 200 ms).
    assert res["p95_ms"] == pytest.approx(20.0 + 0.05 * 180.0)  # 29 ms
    assert res["declared_ms"] == 30.0
    with pytest.raises(ValueError, match="no frame"):
        summarise([{"outcome": {"latencies_ms": []}}])
