"""The stage after pose's small-array helpers give numpy's floats bit for bit.

They replace numpy calls whose overhead outweighs the work on a handful of numbers
(issue 21: the stage after pose took 0.7 ms a frame against the reference's 0.5), so the
sweeps, datasets and recordings must not move: each is checked against the numpy code it
replaces, on the bits (a -0.0 or a NaN counts).
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from monopic.features.window import median
from monopic.variants.zone import point_in_polygon, points_in_polygon

FLOATS = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)


def bits(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64).view(np.int64)


def numpy_points_in_polygon(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """The vectorised even-odd rule monopic used before (session 16)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    x, y = pts[:, :1], pts[:, 1:]
    poly = np.asarray(polygon, dtype=float)
    x1, y1 = poly[:, 0], poly[:, 1]
    x2, y2 = np.concatenate((x1[1:], x1[:1])), np.concatenate((y1[1:], y1[:1]))
    crosses = (y1 > y) != (y2 > y)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        xi = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
    inside = (np.count_nonzero(crosses & (x < xi), axis=1) % 2) == 1
    return inside & np.all(np.isfinite(pts), axis=1)


@st.composite
def points_and_polygon(draw):
    polygon = draw(arrays(np.float64, (draw(st.integers(3, 8)), 2), elements=FLOATS))
    coords = st.one_of(
        FLOATS,
        st.sampled_from([float(v) for v in polygon.ravel()]),  # on a vertex's row or column
        st.sampled_from([np.nan, np.inf, -np.inf]),
    )
    points = draw(arrays(np.float64, (draw(st.integers(0, 20)), 2), elements=coords))
    return points, polygon


@settings(max_examples=400)
@given(points_and_polygon())
def test_points_in_polygon_is_the_numpy_even_odd_rule(case) -> None:
    points, polygon = case
    expected = numpy_points_in_polygon(points, polygon)
    got = points_in_polygon(points, polygon)
    assert got.dtype == bool and np.array_equal(got, expected)
    for point, inside in zip(points, expected, strict=True):
        assert point_in_polygon((point[0], point[1]), polygon) is bool(inside)


def test_points_in_polygon_on_the_robots_zone() -> None:
    zone = np.array([[268.8, 237.6], [499.2, 237.6], [652.8, 432.0], [115.2, 432.0]])
    points = np.array([[384.0, 300.0], [100.0, 300.0], [384.0, 200.0], [np.nan, 300.0]])
    assert points_in_polygon(points, zone).tolist() == [True, False, False, False]


@given(st.lists(FLOATS.map(lambda v: v + 0.0), min_size=1, max_size=30))
def test_median_is_numpys_median(values: list[float]) -> None:
    """Without -0.0 (the head window holds |facing|): which of 0.0 and -0.0 is the middle
    one is np.partition's choice, not a value."""
    assert bits(median(values)) == bits(np.median(np.array(values)))
