"""monopic.pose.warp: the four-channel warp gives the three-channel warp's bytes, and a
frame widened only around a region gives that region's crop byte for byte."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.pose.region import Region
from monopic.pose.warp import WarpBuffers, WideFrame, four_channel, warp

FLAGS = (cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, cv2.INTER_LINEAR, cv2.INTER_AREA)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    angle=st.floats(-math.pi, math.pi),
    scale=st.floats(0.1, 4.0),
    x=st.floats(-300.0, 900.0),
    y=st.floats(-300.0, 600.0),
    flags=st.sampled_from(FLAGS),
)
def test_warping_the_four_channel_frame_gives_the_rgb_warp_byte_for_byte(
    seed: int, angle: float, scale: float, x: float, y: float, flags: int
) -> None:
    image = np.random.default_rng(seed).integers(0, 256, (120, 200, 3), dtype=np.uint8)
    c, s = math.cos(angle) * scale, math.sin(angle) * scale
    m = np.array([[c, -s, x], [s, c, y]])
    expected = cv2.warpAffine(image, m, (64, 48), flags=flags)  # zero border, as before
    buffers = WarpBuffers.of((64, 48))
    buffers.three[:] = 7  # what a previous frame left there
    for given_image in (image, four_channel(image)):
        out = warp(given_image, m, (64, 48), flags)
        assert out.shape == (48, 64, 3)
        assert out.flags["C_CONTIGUOUS"]  # the float conversion reads it at full speed
        assert np.array_equal(out, expected)
        into = warp(given_image, m, (64, 48), flags, buffers)
        assert into is buffers.three and np.array_equal(into, expected)


def test_buffers_of_another_size_are_refused() -> None:
    with pytest.raises(ValueError, match=r"buffers of \(64, 48\) for a warp into \(48, 64\)"):
        warp(np.zeros((8, 8, 3), np.uint8), np.eye(2, 3), (48, 64), 0, WarpBuffers.of((64, 48)))


def test_four_channel_keeps_the_colours_and_leaves_a_four_channel_image_alone() -> None:
    image = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    wide = four_channel(image)
    assert wide.shape == (2, 3, 4) and np.array_equal(wide[..., :3], image)
    assert four_channel(wide) is wide


@pytest.mark.parametrize("shape", [(4, 4), (4, 4, 1), (4, 4, 2)])
def test_an_image_that_is_not_rgb_is_named(shape: tuple[int, ...]) -> None:
    with pytest.raises(ValueError, match=r"expected an RGB image \(H, W, 3\)"):
        four_channel(np.zeros(shape, dtype=np.uint8))


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    cx=st.floats(-80.0, 280.0),
    cy=st.floats(-80.0, 200.0),
    side=st.floats(2.0, 260.0),
    rotation=st.floats(-math.pi, math.pi),
    size=st.sampled_from((31, 64, 256)),
)
def test_a_frame_widened_around_a_region_crops_it_as_the_whole_frame_does(
    seed: int, cx: float, cy: float, side: float, rotation: float, size: int
) -> None:
    rng = np.random.default_rng(seed)
    before, image = rng.integers(0, 256, (2, 120, 200, 3), dtype=np.uint8)
    region = Region(cx, cy, side, rotation)
    wide = WideFrame()
    wide.start(before)
    wide.whole()  # the kept buffer now holds another frame's pixels everywhere
    wide.start(image)
    got = region.crop(wide.around(*region.bounds()), size)
    assert np.array_equal(got, region.crop(four_channel(image), size))


def test_a_wide_frame_is_widened_whole_once_and_takes_four_channels_as_they_are() -> None:
    image = np.random.default_rng(3).integers(0, 256, (20, 30, 3), dtype=np.uint8)
    wide = WideFrame()
    wide.start(image)
    whole = wide.whole()
    assert np.array_equal(whole, four_channel(image))
    assert wide.around(0.0, 0.0, 1.0, 1.0) is whole  # nothing more to widen
    rgba = four_channel(image)
    wide.start(rgba)
    assert wide.whole() is rgba and wide.around(5.0, 5.0, 9.0, 9.0) is rgba


def test_a_wide_frame_names_a_frame_that_is_not_rgb_and_a_missing_start() -> None:
    with pytest.raises(RuntimeError, match=r"start\(\) a frame first"):
        WideFrame().whole()
    with pytest.raises(ValueError, match=r"expected an RGB image \(H, W, 3\), got shape \(4, 4\)"):
        WideFrame().start(np.zeros((4, 4), np.uint8))


def test_a_region_s_bounds_hold_its_corners() -> None:
    region = Region(50.0, 40.0, 20.0, 0.4)
    x0, y0, x1, y1 = region.bounds()
    corners = region.corners()
    assert np.isclose(corners[:, 0].min(), x0) and np.isclose(corners[:, 0].max(), x1)
    assert np.isclose(corners[:, 1].min(), y0) and np.isclose(corners[:, 1].max(), y1)


@settings(max_examples=200, deadline=None)
@given(
    cx=st.floats(-500.0, 1500.0),
    cy=st.floats(-500.0, 1500.0),
    side=st.floats(0.01, 3000.0),
    rotation=st.floats(-7.0, 7.0),
    size=st.sampled_from((32, 64, 256)),
)
def test_the_crop_map_in_python_floats_is_numpy_s_product_for_power_of_two_sizes(
    cx: float, cy: float, side: float, rotation: float, size: int
) -> None:
    """Region builds its affine map without numpy calls; for the landmark model's 256
    (a power of two) it must be the floats numpy's 2x2 product gives."""
    c, s = math.cos(rotation), math.sin(rotation)
    k = side / size
    a = np.array([[c * k, -s * k], [s * k, c * k]])
    b = np.array([cx, cy]) - a @ np.array([size / 2, size / 2])
    numpy_map = np.hstack([a, b[:, None]])
    region = Region(cx, cy, side, rotation)
    assert np.array_equal(region.crop_to_image(size), numpy_map)
    points = np.random.default_rng(0).uniform(0.0, size, (39, 2))
    assert np.array_equal(region.to_image(points, size), points @ a.T + b)
