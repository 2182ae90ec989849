"""The authors' bins at and around every boundary, the cut-point bins and the MDL cuts."""

from __future__ import annotations

import bisect
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from monopic.tree.discretise import (
    MISSING,
    AuthorsPhiBins,
    CutPointBins,
    DeadZoneSignBins,
    Discretiser,
    authors_discretiser,
    ground_discretiser,
    mdlp_cut_points,
)

EPS = 1e-9

# (phi, bin) for the authors' notebook rules with dead zone 15, tested in their order:
# 4 if 75 < phi < 105, 3 if -15 < phi < 15, 2 if 0 < phi < 90, 1 if 90 < phi < 180, else 5.
PHI_CASES = [
    (75.0, 2),
    (75.0 + EPS, 4),
    (90.0, 4),
    (105.0 - EPS, 4),
    (105.0, 1),
    (15.0, 2),
    (15.0 - EPS, 3),
    (0.0, 3),
    (-15.0 + EPS, 3),
    (-15.0, 5),
    (-90.0, 5),
    (-180.0, 5),
    (45.0, 2),
    (150.0, 1),
    (180.0 - EPS, 1),
    (180.0, 5),
    (200.0, 5),
    (math.nan, MISSING),
    (math.inf, MISSING),
]


@pytest.mark.parametrize(("phi", "expected"), PHI_CASES)
def test_authors_phi_bins_around_each_boundary(phi, expected):
    assert AuthorsPhiBins().bin_counted(phi)[0] == expected


VELOCITY_CASES = [
    (0.0, 3),
    (15.0 - EPS, 3),
    (15.0, 1),
    (100.0, 1),
    (-15.0 + EPS, 3),
    (-15.0, 2),
    (-100.0, 2),
    (math.nan, MISSING),
]


@pytest.mark.parametrize(("v", "expected"), VELOCITY_CASES)
def test_authors_velocity_bins_around_each_boundary(v, expected):
    assert DeadZoneSignBins().bin_counted(v)[0] == expected


def test_dead_zone_is_configurable():
    assert AuthorsPhiBins(20.0).bin_counted(72.0)[0] == 4
    assert AuthorsPhiBins(15.0).bin_counted(72.0)[0] == 2
    assert DeadZoneSignBins(20.0).bin_counted(18.0)[0] == 3
    d = authors_discretiser(20.0)
    assert d.discretise({"phi": 72.0, "vx": 18.0, "vy": -25.0}) == {"phi": 4, "vx": 3, "vy": 2}


finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


@given(finite)
def test_phi_bin_is_one_of_five_and_the_first_matching_rule(phi):
    b = AuthorsPhiBins().bin_counted(phi)[0]
    assert b in {1, 2, 3, 4, 5}
    if 75 < phi < 105:
        assert b == 4
    elif -15 < phi < 15:
        assert b == 3
    elif b == 2:
        assert 15 <= phi <= 75
    elif b == 1:
        assert 105 <= phi < 180
    else:
        assert phi <= -15 or phi >= 180


@given(st.floats(min_value=0, max_value=1e6, allow_nan=False), st.floats(0.1, 100.0))
def test_velocity_bins_are_mirror_images(v, dead_zone):
    bins = DeadZoneSignBins(dead_zone)
    up, down = bins.bin_counted(v)[0], bins.bin_counted(-v)[0]
    if v < dead_zone:
        assert up == down == 3
    else:
        assert (up, down) == (1, 2)


@given(
    st.lists(finite, min_size=0, max_size=8, unique=True).map(sorted),
    finite,
)
def test_cut_point_bin_counts_the_cuts_below(cuts, value):
    bins = CutPointBins(tuple(cuts))
    b, ops = bins.bin_counted(value)
    assert b == 1 + bisect.bisect_left(cuts, value)
    assert ops.comparisons <= 1 + math.ceil(math.log2(len(cuts) + 1))


@given(st.lists(finite, min_size=1, max_size=8, unique=True).map(sorted), finite, finite)
def test_cut_point_bins_are_monotone(cuts, a, b):
    bins = CutPointBins(tuple(cuts))
    lo, hi = sorted((a, b))
    assert bins.bin_counted(lo)[0] <= bins.bin_counted(hi)[0]


def test_cut_points_must_increase():
    with pytest.raises(ValueError):
        CutPointBins((1.0, 1.0))
    with pytest.raises(ValueError):
        CutPointBins((2.0, 1.0))


def test_descriptions_name_the_intervals():
    phi = AuthorsPhiBins()
    assert phi.describe(4) == "75 < phi < 105"
    assert phi.describe(2) == "15 <= phi <= 75"
    assert phi.describe(5) == "phi <= -15 or phi >= 180"
    assert DeadZoneSignBins().describe(2) == "v <= -15 px/s"
    cuts = CutPointBins((-1.0, 2.5))
    assert [cuts.describe(b) for b in (1, 2, 3)] == ["<= -1", "(-1, 2.5]", "> 2.5"]


def test_mdlp_finds_the_class_boundary():
    x = np.concatenate([np.linspace(-10, -1, 50), np.linspace(1, 10, 50)])
    y = np.array([0] * 50 + [1] * 50)
    assert mdlp_cut_points(x, y) == (0.0,)
    three = np.concatenate([x, np.linspace(12, 20, 50)])
    assert mdlp_cut_points(three, np.concatenate([y, [2] * 50])) == (0.0, 11.0)


def test_mdlp_refuses_cuts_that_do_not_pay():
    rng = np.random.default_rng(3)
    x = rng.normal(size=200)
    assert mdlp_cut_points(x, rng.integers(0, 3, size=200)) == ()
    assert mdlp_cut_points(x, np.zeros(200, dtype=int)) == ()
    assert mdlp_cut_points(np.array([1.0, np.nan]), np.array([0, 1])) == ()


def test_discretiser_json_round_trip_and_order():
    for d in (
        authors_discretiser(12.5),
        ground_discretiser(),
        Discretiser("entropy", (("vx", CutPointBins((-3.0, 4.0))), ("phi", CutPointBins(())))),
    ):
        assert Discretiser.from_json(d.to_json()) == d
    assert ground_discretiser().attributes == ("forward", "left")
    assert authors_discretiser().attributes == ("phi", "vx", "vy")
