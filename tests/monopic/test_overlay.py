"""The overlay's outlined text: the dark edge hugs the text it outlines."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from monopic.overlay import OUTLINE_PX, _text


@pytest.mark.parametrize("height", [432, 720, 240])
def test_the_outline_follows_the_text_and_runs_no_further(height: int) -> None:
    """Under OpenCV 5 a thicker stroke widens each character's advance: an outline drawn as
    thicker text ran ahead of the text on it, ghost letters past its end."""
    img = np.full((height, 900, 3), 128, np.uint8)
    _text(img, "case 5: perpendicular right", (20, height // 2))
    bright = np.all(img > 150, axis=2)  # the text, its anti-aliased edge included
    dark = np.all(img < 40, axis=2)
    assert bright.sum() > 50 and dark.sum() > 100
    # Distance of every pixel to the nearest text pixel.
    distance = cv2.distanceTransform((~bright).astype(np.uint8), cv2.DIST_L2, 5)
    assert distance[dark].max() <= OUTLINE_PX + 1.5
    text_cols, dark_cols = np.nonzero(bright.any(axis=0))[0], np.nonzero(dark.any(axis=0))[0]
    assert dark_cols.max() <= text_cols.max() + OUTLINE_PX + 1


def test_text_at_the_edge_is_clipped_not_an_error() -> None:
    img = np.full((100, 120, 3), 128, np.uint8)
    _text(img, "COLLISION IMMINENT", (60, 8), (230, 30, 30), 1.0)
    _text(img, "outside", (500, 500))
    assert (img != 128).any()
