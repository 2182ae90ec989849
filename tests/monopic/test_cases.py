"""The case vocabulary and its labelling functions."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from monopic.cases import (
    AUTHORS_TO_CASE,
    CASE_TO_AUTHORS,
    Case,
    case_from_ground_velocity,
    case_from_image_track,
)


def test_numbering_matches_paper():
    assert [c.value for c in Case] == list(range(1, 10))
    assert Case(1).label == "oblique right away"
    assert Case(7).label == "toward"
    assert Case(9).label == "still"


def test_authors_mapping_is_a_bijection_with_their_image_directions():
    assert set(AUTHORS_TO_CASE) == set(range(1, 10))
    assert set(AUTHORS_TO_CASE.values()) == set(Case)
    # their 1 = up-right: right and away (up the image) for a static camera
    assert AUTHORS_TO_CASE[1] is Case.OBLIQUE_RIGHT_AWAY
    assert AUTHORS_TO_CASE[2] is Case.OBLIQUE_LEFT_TOWARD
    assert AUTHORS_TO_CASE[7] is Case.AWAY and AUTHORS_TO_CASE[8] is Case.TOWARD
    assert all(AUTHORS_TO_CASE[CASE_TO_AUTHORS[c]] is c for c in Case)


@pytest.mark.parametrize(
    "angle_deg, case",
    [
        (0, Case.AWAY),
        (45, Case.OBLIQUE_LEFT_AWAY),
        (90, Case.PERPENDICULAR_LEFT),
        (135, Case.OBLIQUE_LEFT_TOWARD),
        (180, Case.TOWARD),
        (-135, Case.OBLIQUE_RIGHT_TOWARD),
        (-90, Case.PERPENDICULAR_RIGHT),
        (-45, Case.OBLIQUE_RIGHT_AWAY),
    ],
)
def test_ground_velocity_sectors(angle_deg, case):
    a = math.radians(angle_deg)
    assert case_from_ground_velocity(1.4 * math.cos(a), 1.4 * math.sin(a)) is case


def test_ground_dead_zone_is_still():
    assert case_from_ground_velocity(0.1, -0.1) is Case.STILL
    assert case_from_ground_velocity(0.0, 0.0) is Case.STILL


@given(st.floats(-179.9, 179.9), st.floats(0.5, 5.0))
def test_ground_sector_boundaries_are_45_degrees(angle_deg, speed):
    a = math.radians(angle_deg)
    case = case_from_ground_velocity(speed * math.cos(a), speed * math.sin(a))
    centre = {
        Case.AWAY: 0, Case.OBLIQUE_LEFT_AWAY: 45, Case.PERPENDICULAR_LEFT: 90,
        Case.OBLIQUE_LEFT_TOWARD: 135, Case.TOWARD: 180, Case.OBLIQUE_RIGHT_TOWARD: -135,
        Case.PERPENDICULAR_RIGHT: -90, Case.OBLIQUE_RIGHT_AWAY: -45,
    }[case]  # fmt: skip
    diff = (angle_deg - centre + 180) % 360 - 180
    assert abs(diff) <= 22.5 + 1e-6


def _track(du, dv, dh, h0=200.0, n=16, dt=1 / 15):
    t = [i * dt for i in range(n)]
    return (
        t,
        [400 + du * x for x in t],
        [300 + dv * x for x in t],
        [h0 + dh * x for x in t],
    )


@pytest.mark.parametrize(
    "du, dv, dh, case",
    [
        (120, 0, 0, Case.PERPENDICULAR_RIGHT),
        (-120, 0, 0, Case.PERPENDICULAR_LEFT),
        (0, 30, 20, Case.TOWARD),
        (0, -30, -20, Case.AWAY),
        (120, 30, 20, Case.OBLIQUE_RIGHT_TOWARD),
        (-120, -30, -20, Case.OBLIQUE_LEFT_AWAY),
        (120, -30, -20, Case.OBLIQUE_RIGHT_AWAY),
        (-120, 30, 20, Case.OBLIQUE_LEFT_TOWARD),
        (5, 1, 0.5, Case.STILL),
    ],
)
def test_image_track_labels(du, dv, dh, case):
    assert case_from_image_track(*_track(du, dv, dh)) is case


def test_image_track_rejects_bad_input():
    with pytest.raises(ValueError):
        case_from_image_track([0.0], [1.0], [1.0], [1.0])
    with pytest.raises(ValueError):
        case_from_image_track([0, 1], [1, 2], [1, 2], [0, 0])
