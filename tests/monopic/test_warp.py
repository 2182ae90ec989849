"""monopic.pose.warp: the four-channel warp gives the three-channel warp's bytes."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.pose.warp import WarpBuffers, four_channel, warp

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
