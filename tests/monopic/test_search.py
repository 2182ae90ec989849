"""Where the detector looks while searching: the ground band, the tiles that cover it, and
the order a searching frame tries its windows in (zooms on faint candidates included)."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from monopic.camera import CameraModel
from monopic.pose.region import Region
from monopic.pose.search import (
    MAX_ZOOMS,
    PERSON_HEIGHTS_M,
    Faint,
    GroundBand,
    SearchSteps,
    Window,
    band_windows,
    search_windows,
    tile_windows,
    zoom_window,
)


def test_band_rows_hold_every_person_height_at_that_size():
    band = GroundBand(horizon_v=200.0, camera_height=1.2)
    top, bottom = band.rows(50.0)
    # A 1 m child seen 50 px tall: feet 1.2 x 50 = 60 px below the horizon, head 10 above them.
    assert bottom == pytest.approx(260.0)
    # A 2 m adult: feet 30 px below, head 20 px above the horizon.
    assert top == pytest.approx(180.0)


def test_band_follows_the_camera_model():
    cam = CameraModel.from_fov(768, 432, vertical_fov_deg=65.0, mount_height=1.2, pitch_deg=5.0)
    band = GroundBand.from_camera(cam)
    assert band.camera_height == 1.2
    assert band.horizon_v == pytest.approx(216 - cam.fy * math.tan(math.radians(5.0)))


@given(
    distance=st.floats(8.0, 60.0),
    height=st.floats(*PERSON_HEIGHTS_M),
    camera_height=st.floats(0.5, 2.0),
)
def test_a_standing_person_projects_inside_the_band_of_its_size(distance, height, camera_height):
    cam = CameraModel.from_fov(768, 432, vertical_fov_deg=65.0, mount_height=camera_height)
    feet = cam.project([[distance, 0.0, 0.0]])[0, 1]
    head = cam.project([[distance, 0.0, height]])[0, 1]
    top, bottom = GroundBand.from_camera(cam).rows(feet - head)
    assert top - 1e-6 <= head and feet <= bottom + 1e-6


def test_band_windows_one_row_centred_on_a_narrow_band():
    wins = band_windows(768, 432, 96, (150.0, 230.0))
    assert {w.y for w in wins} == {142.0}  # centred: (150 + 230 - 96) / 2
    assert min(w.x for w in wins) == 0 and max(w.x + w.width for w in wins) == 768
    assert len(wins) == len(tile_windows(768, 96, 96))  # same columns as a full row


def test_band_windows_clip_to_the_frame_and_vanish_outside_it():
    assert {w.y for w in band_windows(768, 432, 96, (400.0, 470.0))} == {336.0}
    assert band_windows(768, 432, 96, (440.0, 500.0)) == []
    rows = {w.y for w in band_windows(768, 432, 96, (0.0, 300.0))}
    assert len(rows) > 1 and min(rows) == 0 and max(rows) + 96 == 300


def test_search_without_band_covers_the_frame_and_skips_far_tiles():
    levels = search_windows(768, 432, (432, 288, 216), (96,), 0.25, None)
    assert [len(level) for level in levels] == [3, 8, 15]


def test_search_with_band_is_narrower_and_adds_far_tiles():
    band = GroundBand(horizon_v=186.0, camera_height=1.2)
    levels = search_windows(768, 432, (432, 288, 216), (96,), 0.25, band)
    assert [len(level) for level in levels] == [3, 4, 5, 11]
    far = levels[-1]
    top, bottom = band.rows(48.0)
    assert all(w.width == 96 and w.y <= top and w.y + 96 >= bottom for w in far)


WHOLE = Window(0, 0, 768, 432)
TILES = [Window(float(k), 0, 216, 216) for k in range(6)]


def faint(score: float, x: float = 300.0) -> Faint:
    return Faint(score, Region(x, 200.0, 60.0))


def tried(steps: SearchSteps, learnt: dict[int, Faint] | None = None) -> list[Window]:
    """Every window `steps` gives, telling it `learnt[k]` after the k-th."""
    out = []
    while (win := steps.next()) is not None:
        steps.learn((learnt or {}).get(len(out)))
        out.append(win)
    return out


def test_a_search_tries_the_whole_frame_then_the_cascade_from_where_it_stopped():
    steps = SearchSteps(WHOLE, TILES, start=4, budget=4)
    assert tried(steps) == [WHOLE, TILES[4], TILES[5], TILES[0]]
    assert steps.next_tile == 1 and steps.carry is None
    assert tried(SearchSteps(WHOLE, TILES, start=0, budget=0)) == [WHOLE, *TILES]
    assert tried(SearchSteps(WHOLE, [], start=0, budget=4)) == [WHOLE]


def test_a_faint_candidate_is_zoomed_on_next_within_the_budget():
    steps = SearchSteps(WHOLE, TILES, start=0, budget=4)
    windows = tried(steps, {0: faint(0.2)})
    assert windows == [WHOLE, zoom_window(faint(0.2).region), TILES[0], TILES[1]]
    assert windows[1] == Window(252.0, 152.0, 96.0, 96.0)  # the region, at least 96 px
    assert steps.next_tile == 2  # the zoom took a tile's place, not its turn


def test_a_zoom_is_followed_only_by_a_stronger_candidate():
    weaker = tried(SearchSteps(WHOLE, TILES, 0, 0), {0: faint(0.2), 1: faint(0.15, 500.0)})
    assert weaker[2] == TILES[0]  # the zoom's weaker candidate is background: dropped
    stronger = tried(SearchSteps(WHOLE, TILES, 0, 0), {0: faint(0.2), 1: faint(0.3, 500.0)})
    assert stronger[2] == zoom_window(faint(0.3, 500.0).region)


def test_zooms_are_bounded_and_what_is_left_carries_to_the_next_frame():
    learnt = {k: faint(0.1 + 0.05 * k, 100.0 * k) for k in range(7)}
    windows = tried(SearchSteps(WHOLE, TILES, 0, 0), learnt)
    zooms = [w for w in windows if w not in TILES and w != WHOLE]
    assert len(zooms) == MAX_ZOOMS and len(windows) == 1 + MAX_ZOOMS + len(TILES)
    steps = SearchSteps(WHOLE, TILES, 0, budget=2)
    assert tried(steps, {1: faint(0.3)}) == [WHOLE, TILES[0]]  # no pass left to zoom
    assert steps.carry == faint(0.3)
    again = SearchSteps(WHOLE, TILES, steps.next_tile, budget=3, carried=steps.carry)
    assert tried(again) == [WHOLE, zoom_window(faint(0.3).region), TILES[1]]


def test_upcoming_windows_are_what_next_gives_when_nothing_is_learnt():
    steps = SearchSteps(WHOLE, TILES, 0, budget=4)
    assert steps.next() == WHOLE
    assert steps.upcoming(2) == [TILES[0], TILES[1]]
    steps.learn(faint(0.2))
    assert steps.upcoming(5) == [zoom_window(faint(0.2).region), TILES[0], TILES[1]]
