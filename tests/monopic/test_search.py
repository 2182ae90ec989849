"""Where the detector looks while searching: the ground band and the tiles that cover it."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from monopic.camera import CameraModel
from monopic.pose.search import (
    PERSON_HEIGHTS_M,
    GroundBand,
    band_windows,
    search_windows,
    tile_windows,
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
