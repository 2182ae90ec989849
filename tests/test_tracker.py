"""The tracker's search budget: a pedestrian too small for the whole frame is found by the
tile cascade, spread over frames, with no frame spending more detector passes than allowed."""

import math

import cv2
import numpy as np
import pytest

from monopic.pose.search import tile_windows
from monopic.pose.tracker import PoseTracker, TrackerConfig
from monopic.video import VideoSource
from tests.test_end_to_end import CLIP

pytestmark = pytest.mark.slow


def small_person_frame(scale: float = 0.2) -> np.ndarray:
    """The clip's first frame shrunk into a grey frame: the walker is ~45 px tall."""
    image = next(iter(VideoSource(str(CLIP)))).image
    small = cv2.resize(image, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    canvas = np.full_like(image, 90)
    h, w = small.shape[:2]
    canvas[250 : 250 + h, 550 : 550 + w] = small
    return canvas


def tiles_in_cascade(config: TrackerConfig, width: int = 768, height: int = 432) -> int:
    return sum(
        len(tile_windows(width, height, t, config.tile_overlap)) for t in config.acquire_tiles
    )


def test_unlimited_search_finds_the_small_person_in_the_first_frame():
    tracker = PoseTracker(TrackerConfig(search_budget=0))
    first = tracker.process(small_person_frame())
    assert first.found
    assert first.detector_runs > 4  # the whole frame missed it; the tiles found it


def test_budgeted_search_spreads_the_cascade_over_frames_and_then_tracks():
    config = TrackerConfig(search_budget=4)
    tracker = PoseTracker(config)
    frame = small_person_frame()
    results = [tracker.process(frame) for _ in range(12)]
    assert all(r.detector_runs <= config.search_budget for r in results)
    first_found = next(k for k, r in enumerate(results) if r.found)
    # Within one pass over the tile cascade, (budget - 1) tiles a frame.
    assert 0 < first_found <= math.ceil(tiles_in_cascade(config) / (config.search_budget - 1))
    assert all(r.found and r.detector_runs == 0 for r in results[first_found + 1 :])


def test_search_budget_must_leave_room_for_a_tile():
    with pytest.raises(ValueError, match="search_budget"):
        TrackerConfig(search_budget=1)
    with pytest.raises(ValueError, match="search_budget"):
        TrackerConfig(search_budget=-2)
