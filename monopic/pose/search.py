"""Where the detector looks while no one is tracked: the whole frame, then a tile cascade.

The detector squeezes its window into 224 px, so a pedestrian must be about a quarter of
the window tall to be found; far ones need small tiles, which cost one detector pass
each. When the camera is known (height, pitch), a person standing on flat ground can
only appear in a band of rows around the horizon, and the smaller the person the
narrower the band: then the cascade keeps one row of tiles per size, and adds tiles
smaller than the detector's input (upscaled, 96 px by default) that find pedestrians
28-90 px tall, whom the whole-frame and 216 px passes miss (measured on rendered frames:
96 px tiles found 10/10 at 32 px where 216 px tiles found 0/10).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from monopic.camera import CameraModel

PERSON_HEIGHTS_M = (1.0, 2.0)  # a small child to a tall adult
PERSON_SHARE = 0.5  # a tile finds people up to about half its side tall


@dataclass(frozen=True)
class Window:
    """A rectangular part of the frame the detector looks at (may extend past the edges)."""

    x: float
    y: float
    width: float
    height: float


@dataclass(frozen=True)
class GroundBand:
    """Rows where a person standing on flat ground can appear, from the camera alone."""

    horizon_v: float  # image row of the horizon
    camera_height: float  # m above the ground

    @classmethod
    def from_camera(cls, camera: CameraModel) -> GroundBand:
        return cls(camera.horizon_v(), camera.mount_height)

    def rows(self, person_px: float) -> tuple[float, float]:
        """Top and bottom image rows of any 1-2 m person whose image is `person_px` tall.

        Feet sit below the horizon by person_px * camera height / person height; the head
        is person_px above the feet.
        """
        shortest, tallest = PERSON_HEIGHTS_M
        top = self.horizon_v + person_px * min(0.0, self.camera_height / tallest - 1.0)
        bottom = self.horizon_v + person_px * self.camera_height / shortest
        return top, bottom


def _starts(length: float, tile: float, overlap: float) -> list[float]:
    """Tile origins along one axis covering `length` with at least `overlap` between tiles."""
    if tile >= length:
        return [(length - tile) / 2]
    n = math.ceil((length - tile) / (tile * (1 - overlap))) + 1
    return [i * (length - tile) / (n - 1) for i in range(n)]


def tile_windows(width: int, height: int, tile: int, overlap: float = 0.25) -> list[Window]:
    """Square tiles of side `tile` covering the frame with at least `overlap` between them."""
    if tile >= max(width, height):
        return [Window(0, 0, width, height)]
    return [
        Window(x, y, tile, tile)
        for y in _starts(height, tile, overlap)
        for x in _starts(width, tile, overlap)
    ]


def band_windows(
    width: int, height: int, tile: int, rows: tuple[float, float], overlap: float = 0.25
) -> list[Window]:
    """Square tiles covering image rows `rows` (clipped to the frame) across its width.

    One row of tiles centred on the band when it fits in a tile, else rows overlapping
    like `tile_windows`; none when the band lies outside the frame.
    """
    top, bottom = max(0.0, rows[0]), min(float(height), rows[1])
    if bottom <= top:
        return []
    span = bottom - top
    if span <= tile:
        ys = [min(max((top + bottom - tile) / 2, 0.0), max(height - tile, 0.0))]
        if tile >= height:
            ys = [(height - tile) / 2]
    else:
        ys = [top + s for s in _starts(span, tile, overlap)]
    return [Window(x, y, tile, tile) for y in ys for x in _starts(width, tile, overlap)]


def search_windows(
    width: int,
    height: int,
    tiles: tuple[int, ...],
    far_tiles: tuple[int, ...],
    overlap: float,
    band: GroundBand | None,
) -> list[list[Window]]:
    """The tile cascade after the whole frame, one list per tile size, coarse to fine.

    Without a band every tile size covers the whole frame and `far_tiles` are left out
    (a frame of 96 px tiles is 66 passes); with one, each size covers only its band.
    """
    levels: list[list[Window]] = []
    for tile in tiles:
        if tile >= max(width, height):
            continue
        if band is None:
            levels.append(tile_windows(width, height, tile, overlap))
        else:
            rows = band.rows(tile * PERSON_SHARE)
            levels.append(band_windows(width, height, tile, rows, overlap))
    for tile in far_tiles if band is not None else ():
        levels.append(band_windows(width, height, tile, band.rows(tile * PERSON_SHARE), overlap))
    return [level for level in levels if level]
