"""The affine resampling both pose models' inputs go through (crop, letterbox).

OpenCV warps a four-channel uint8 image with its vector kernels and a three-channel one
without: a rotated 256 px crop of a 768x432 frame took 0.57 against 0.89 ms on one core
here, the detector's 224 px letterbox of the whole frame 0.24 against 0.41 ms, the same
bytes in the colour channels, and the frame's one conversion to four channels 0.14 ms
(bench/crop_warp.py). So the tracker widens each frame once and every warp of it reads
that; `warp` widens a three-channel image itself when given one. While it tracks, the
tracker widens only around the landmark crop (`WideFrame`): the same crop bytes, and in
the 2-thread benchmark worker 87 us a frame for the widening against 138 for the whole
frame (`bench/cold_paths.py`).

The landmark model's crop is warped into the same buffers frame after frame
(`WarpBuffers`), the same bytes without a fresh allocation per frame. What that saves is
within this host's noise: right after a model run, widening a frame, cropping it and
making the model's float input took 0.56 and 0.64 ms in two runs, against 0.62 with fresh
arrays (`bench/cold_paths.py`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

# Pixels widened beyond a region's bounds: bilinear sampling reads the pixel at or left of
# (above) a sample and the next one, and a sample's index coordinate is its continuous
# one minus half a pixel, so one pixel each side would do; two leave slack for
# warpAffine's fixed-point coordinates (1/32 px).
WIDEN_MARGIN = 2


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


class WideFrame:
    """A frame's four-channel form in a kept buffer, widened only where warps will read.

    While a person is tracked, a frame is warped once, into the landmark crop, which reads
    a median 7 % of a 768x432 benchmark frame (10-90 %: 2-29 %); widening the whole frame
    took 0.14 ms right after a model run (bench/cold_paths.py). Outside what has been
    widened the buffer holds earlier frames' pixels: only `around`'s bounds may be warped
    from what it returns, `whole` for anything else (the detector's windows). Each `start`
    overwrites what the last frame's calls returned.
    """

    def __init__(self) -> None:
        self._kept: np.ndarray | None = None
        self._image: np.ndarray | None = None
        self._view: np.ndarray | None = None
        self._whole = False

    def start(self, image: np.ndarray) -> None:
        """A new RGB (H, W, 3) frame, nothing widened yet; a four-channel one is used as is."""
        if _is_four_channel(image):
            self._image, self._view, self._whole = image, image, True
            return
        if self._kept is None or self._kept.shape[:2] != image.shape[:2]:
            self._kept = np.empty((*image.shape[:2], 4), np.uint8)
        self._image, self._view, self._whole = image, self._kept, False

    def whole(self) -> np.ndarray:
        """The frame, widened everywhere."""
        image, view = self._frame()
        if not self._whole:
            four_channel(image, out=view)
            self._whole = True
        return view

    def around(self, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
        """The frame, widened at least over x0..x1, y0..y1 (continuous image pixels, as
        `Region.bounds`) and WIDEN_MARGIN beyond, where they lie on the frame."""
        image, view = self._frame()
        if not self._whole:
            h, w = image.shape[:2]
            c0, c1 = max(0, math.floor(x0) - WIDEN_MARGIN), min(w, math.ceil(x1) + WIDEN_MARGIN)
            r0, r1 = max(0, math.floor(y0) - WIDEN_MARGIN), min(h, math.ceil(y1) + WIDEN_MARGIN)
            if c0 < c1 and r0 < r1:
                four_channel(image[r0:r1, c0:c1], out=view[r0:r1, c0:c1])
        return view

    def _frame(self) -> tuple[np.ndarray, np.ndarray]:
        if self._image is None or self._view is None:
            raise RuntimeError("WideFrame: start() a frame first")
        return self._image, self._view


def four_channel(image: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """The RGB uint8 image (H, W, 3) with a fourth channel (written into `out` when
    given, of the same height and width); a 4-channel image as it is."""
    if _is_four_channel(image):
        return image
    return cv2.cvtColor(image, cv2.COLOR_RGB2RGBA, dst=out)


def _is_four_channel(image: np.ndarray) -> bool:
    """True for a four-channel image, False for RGB; anything else is refused."""
    if image.ndim == 3 and image.shape[2] == 4:
        return True
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an RGB image (H, W, 3), got shape {image.shape}")
    return False


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
    takes 40 us against 230-390 us through the strided view (one core, `bench/crop_warp.py`). With
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
