"""Tracks paired with simulated people by box overlap (sim.geometry.box_match)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from sim.geometry.box_match import clipped, match_tracks

W, H = 640, 480


def test_each_track_pairs_with_the_person_it_covers_and_a_phantom_with_nobody() -> None:
    people = [(100, 100, 140, 200), (300, 120, 340, 220), None]
    tracks = [[7, 302, 118, 338, 224], [3, 98, 104, 141, 198], [9, 500, 100, 540, 200]]
    assert match_tracks(tracks, people, W, H) == {7: 1, 3: 0}


def test_one_person_is_never_two_tracks() -> None:
    people = [(100, 100, 140, 200)]
    tracks = [[1, 100, 100, 140, 200], [2, 102, 102, 142, 202]]
    assert match_tracks(tracks, people, W, H) == {1: 0}


def test_boxes_are_clipped_to_the_image_before_they_are_compared() -> None:
    assert clipped((-50, 400, 30, 600), W, H) == (0.0, 400.0, 30.0, 480.0)
    assert clipped((700, 0, 800, 10), W, H) is None
    assert clipped((0, 0, None, 10), W, H) is None
    # a person half out of the image pairs with the track of their visible half
    assert match_tracks([[4, 0, 300, 40, 480]], [(-40, 300, 40, 560)], W, H) == {4: 0}


@given(st.lists(st.tuples(st.floats(0, 600), st.floats(0, 400), st.floats(5, 80)), max_size=6))
def test_pairs_are_one_to_one(boxes: list[tuple[float, float, float]]) -> None:
    people = [(u, v, u + s / 2, v + s) for u, v, s in boxes]
    tracks = [[k, u + 1, v + 1, u + s / 2 + 1, v + s + 1] for k, (u, v, s) in enumerate(boxes)]
    pairs = match_tracks(tracks, people, W, H)
    assert len(set(pairs.values())) == len(pairs)
