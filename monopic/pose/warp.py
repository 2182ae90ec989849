"""The affine resampling both pose models' inputs go through (crop, letterbox).

OpenCV warps a four-channel uint8 image with its vector kernels and a three-channel one
without: a rotated 256 px crop of a 768x432 frame took 0.57 against 0.89 ms on one core
here, the detector's 224 px letterbox of the whole frame 0.24 against 0.41 ms, the same
bytes in the colour channels, and the frame's one conversion to four channels 0.14 ms
(bench/crop_warp.py). So the tracker widens each frame once (`four_channel`) and every
warp of it reads that; `warp` widens a three-channel image itself when given one.

The landmark model's crop is warped into the same buffers frame after frame
(`WarpBuffers`), the same bytes without a fresh allocation per frame. What that saves is
within this host's noise: right after a model run, widening a frame, cropping it and
making the model's float input took 0.56 and 0.64 ms in two runs, against 0.62 with fresh
arrays (`bench/cold_paths.py`, docs/benchmarks.md session 20).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True)
class WarpBuffers:
    """Output buffers of `warp` for one size (w, h), reused call after call: each call
    overwrites what the last one returned."""

    four: np.ndarray  # (h, w, 4) uint8: warpAffine's output
    three: np.ndarray  # (h, w, 3) uint8: its colour channels, what `warp` returns

    @classmethod
    def of(cls, size: tuple[int, int]) -> WarpBuffers:
        w, h = size
        return cls(np.empty((h, w, 4), np.uint8), np.empty((h, w, 3), np.uint8))


def four_channel(image: np.ndarray) -> np.ndarray:
    """The RGB uint8 image (H, W, 3) with a fourth channel; a 4-channel image as it is."""
    if image.ndim == 3 and image.shape[2] == 4:
        return image
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an RGB image (H, W, 3), got shape {image.shape}")
    return cv2.cvtColor(image, cv2.COLOR_RGB2RGBA)


def warp(
    image: np.ndarray,
    matrix: np.ndarray,
    size: tuple[int, int],
    flags: int,
    buffers: WarpBuffers | None = None,
) -> np.ndarray:
    """cv2.warpAffine of the image's colour channels into `size` (w, h), zero outside.

    Returns a contiguous (h, w, 3) copy of the result's colour channels: dropping the
    fourth channel costs 5 us, and the models' float conversion of a contiguous crop then
    takes 40 us against 230-390 us through the strided view (session 16, one core). With
    `buffers` (of this size) the result is `buffers.three`, overwritten by the next call.
    """
    if buffers is not None and buffers.three.shape[1::-1] != tuple(size):
        raise ValueError(f"buffers of {buffers.three.shape[1::-1]} for a warp into {size}")
    out = cv2.warpAffine(
        four_channel(image),
        matrix,
        size,
        dst=None if buffers is None else buffers.four,
        flags=flags,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=(0, 0, 0, 0),
    )
    return cv2.cvtColor(out, cv2.COLOR_RGBA2RGB, dst=None if buffers is None else buffers.three)
