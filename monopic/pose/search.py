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
from monopic.pose.region import Region

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
    """The tile cascade after the whole frame, one list per tile size, in `tiles` order.

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


# A zoom window is never smaller than the far tiles: the detector upscales it to 224 px.
ZOOM_MIN_SIDE = 96.0
# Zooms one searching frame may spend (each one detector pass of its budget).
MAX_ZOOMS = 2


@dataclass(frozen=True)
class Faint:
    """The best anchor of a window that found no one: below the detector's threshold
    but above the zoom's, with the region its keypoints give (frame pixels)."""

    score: float
    region: Region


def zoom_window(region: Region) -> Window:
    """The square the faint candidate's own region spans, upright: the view the landmark
    model would get of that person, for the detector (at least ZOOM_MIN_SIDE)."""
    side = max(region.side, ZOOM_MIN_SIDE)
    return Window(region.cx - side / 2, region.cy - side / 2, side, side)


class SearchSteps:
    """The windows one searching frame tries, one at a time, and what it learns on the way.

    The order: the whole frame; a zoom on the faint candidate the last frame left
    unexplored; then the tile cascade from where it stopped. A window that finds no one
    but holds a faint candidate (monopic.pose.detector: score at least the zoom's
    threshold, below the detector's) puts a zoom on it next: a far pedestrian the
    whole frame or a coarse tile barely sees is then found in its own region, in one
    pass, instead of at the cascade's turn for their tile size (on the validation frames,
    bench/frameset.py's `search` recipe, with the 432 px tiles first: 36 % fewer passes,
    found 0.5 frames sooner on average). A zoom's own faint candidate is followed only if
    it scores higher than the one that led there, so a patch of background the detector
    half-likes costs one pass.
    `budget` windows at most (0: the whole cascade once); at most MAX_ZOOMS zooms.
    """

    def __init__(
        self,
        whole: Window,
        tiles: list[Window],
        start: int,
        budget: int,
        carried: Faint | None = None,
    ) -> None:
        self._queue: list[tuple[Window, float | None]] = [(whole, None)]  # (window, led by)
        if carried is not None:
            self._queue.append((zoom_window(carried.region), carried.score))
        self._tiles, self._start = tiles, start % len(tiles) if tiles else 0
        self._budget = budget or 1 + MAX_ZOOMS + len(tiles)
        self._tiles_budget = len(tiles) if budget == 0 else min(len(tiles), budget)
        self._tried = 0
        self._zooms = 1 if carried is not None else 0
        self._tiles_given = 0
        self._current: tuple[Window, float | None] | None = None
        self._left: Faint | None = None  # the best faint candidate not zoomed on

    def _tile(self, k: int) -> Window:
        return self._tiles[(self._start + k) % len(self._tiles)]

    def _planned(self) -> list[tuple[Window, float | None]]:
        """The windows still to come if nothing more is learnt, in order."""
        left = self._budget - self._tried
        tiles = self._tiles_budget - self._tiles_given
        planned = self._queue + [(self._tile(self._tiles_given + k), None) for k in range(tiles)]
        return planned[: max(left, 0)]

    def next(self) -> Window | None:
        """The next window to try, or None when the frame's search is over."""
        planned = self._planned()
        if not planned:
            self._current = None
            return None
        self._current = planned[0]
        if self._queue:
            self._queue.pop(0)
        else:
            self._tiles_given += 1
        self._tried += 1
        return self._current[0]

    def upcoming(self, n: int) -> list[Window]:
        """The `n` windows after the current one if it teaches nothing (to run ahead)."""
        return [win for win, _ in self._planned()[:n]]

    def learn(self, faint: Faint | None) -> None:
        """What the window last given found: nobody, perhaps a faint candidate."""
        assert self._current is not None, "learn() follows next()"
        led_by = self._current[1]
        if faint is None or (led_by is not None and faint.score <= led_by):
            return
        if self._zooms < MAX_ZOOMS and self._tried < self._budget:
            self._zooms += 1
            self._queue.insert(0, (zoom_window(faint.region), faint.score))
        elif self._left is None or faint.score > self._left.score:
            self._left = faint

    @property
    def next_tile(self) -> int:
        """Where the next frame's cascade starts: after the tiles this frame tried."""
        return (self._start + self._tiles_given) % len(self._tiles) if self._tiles else 0

    @property
    def carry(self) -> Faint | None:
        """The best faint candidate this frame left unexplored, for the next frame."""
        return self._left
