"""One-pedestrian tracker wired like MediaPipe's pose solution.

Acquire: run the detector on the whole frame, then on square tiles (288 px first, then
432 and 216) until a window finds someone (far pedestrians are too small for the whole
frame squeezed into 224 px; monopic.pose.search says which tiles, fewer and smaller ones
when the camera's ground band is known); keep that window's most confident detection. A
window that finds no one but half-sees someone (a faint candidate) is followed by a zoom
on that candidate's region. Each window costs a detector pass (the 27 tiles of a 768x432
frame took about 380 ms on one core), so a frame spends at most `search_budget` passes:
the whole frame every time (near pedestrians are found at once), zooms, and the next
tiles of the cascade, which resumes where the previous frame stopped. Track: crop the
rotated region, run the landmark model, take the next frame's region from this frame's
auxiliary points. When the pose flag drops, the person is lost and the detector runs
again (in the same frame).
Filter: given frame timestamps, landmarks, visibility and the auxiliary points are smoothed
across frames as MediaPipe's PoseLandmarkFiltering does (monopic.pose.filtering), and the
next region comes from the smoothed auxiliary points; the filters restart with each track.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from monopic.pose.detector import PoseDetector
from monopic.pose.filtering import LandmarkFilter
from monopic.pose.landmarks import LandmarkModel, Pose
from monopic.pose.region import DEFAULT_SCALE, Region
from monopic.pose.search import Faint, GroundBand, SearchSteps, Window, search_windows
from monopic.pose.sessions import (
    DEFAULT_DETECTOR_MODEL,
    DEFAULT_LANDMARK_MODEL,
    DEFAULT_RUNTIME,
    check_runtime,
    detector_file,
    landmark_file,
)
from monopic.pose.warp import WideFrame


@dataclass(frozen=True)
class TrackerConfig:
    # onnxruntime intra-op threads per model; while searching, also the number of detector
    # windows run side by side (monopic.pose.detector.PoseDetector.detect_first).
    threads: int = 1
    # With threads > 1: the pool's threads spin-wait between a run's operators (stopping
    # when it returns). About 0.8x the time on cores the pipeline has to itself, 2x on
    # busy ones (monopic.pose.sessions.make_session), so off unless asked.
    spin: bool = False
    # MediaPipe's landmark model choice: "lite", "full" (its default) or "heavy".
    model: str = DEFAULT_LANDMARK_MODEL
    # The person detector: "float" (MediaPipe's) or "int8" (quantised; faster passes
    # while searching, monopic.pose.sessions.DETECTOR_MODELS).
    detector: str = DEFAULT_DETECTOR_MODEL
    # The detector for the search's windows smaller than the frame (zooms and tiles, for
    # walkers the whole frame cannot see); None: `detector`. "int8" there keeps every
    # whole-frame detection, and so the landmarks of the walkers it finds, the float
    # model's, and makes the search for far walkers cheaper.
    window_detector: str | None = None
    # onnxruntime's execution provider for both models (monopic.pose.sessions.RUNTIMES).
    runtime: str = DEFAULT_RUNTIME
    min_detection_score: float = 0.5
    min_pose_score: float = 0.5  # pose flag below this: person lost
    region_scale: float = DEFAULT_SCALE
    # Square tile sides tried, in this order, after the whole frame finds nobody. 288 px
    # first: on the validation frames (bench/frameset.py --recipe search) the 432 px tiles
    # found no one directly (97 passes; the whole frame and its zooms take the near
    # walkers), so starting with them cost 322 passes and 502 of 550 frames found,
    # starting with 288 px 204 and 533. 432 px stays for large walkers the whole frame
    # misses.
    acquire_tiles: tuple[int, ...] = (288, 432, 216)
    # Upscaled tiles for far pedestrians, tried only inside the camera's ground band.
    far_tiles: tuple[int, ...] = (96,)
    tile_overlap: float = 0.25
    # Detector passes per frame while searching: the whole frame, zooms and tiles of the
    # cascade, one window at a time until one finds someone. 0 runs the whole cascade in
    # every frame (offline, no time limit). 4 passes (about 50 ms on one core) keep a
    # searching frame within a 15 fps frame period.
    search_budget: int = 4
    # A window that finds no one but whose best anchor scores at least this (below
    # min_detection_score) is followed by a zoom on that candidate's own region
    # (monopic.pose.search.SearchSteps); None: no zooms. 0.1 was chosen on the validation
    # frames (bench/frameset.py --recipe search): background windows reach it in 0.2 % of
    # passes (0.07: 13.5 %), windows holding a person the detector misses in 18 %.
    zoom_score: float | None = 0.1
    # With frame timestamps: smooth landmarks and visibility across frames (MediaPipe
    # Pose's smooth_landmarks, on by default there too).
    smooth_landmarks: bool = True
    # With frame timestamps: build the next region from smoothed auxiliary points.
    # MediaPipe always does; False only for ablations.
    smooth_region: bool = True

    def __post_init__(self) -> None:
        landmark_file(self.model)  # an unknown name fails here, with the choices
        detector_file(self.detector)
        if self.window_detector is not None:
            detector_file(self.window_detector)
        check_runtime(self.runtime)
        if self.zoom_score is not None and not 0 < self.zoom_score < self.min_detection_score:
            raise ValueError(
                f"zoom_score must be None or between 0 and min_detection_score "
                f"({self.min_detection_score}), got {self.zoom_score}"
            )
        if self.search_budget < 0 or self.search_budget == 1 and self.acquire_tiles:
            raise ValueError(
                f"search_budget must be 0 (no limit) or >= 2 when tiles are used, "
                f"got {self.search_budget}"
            )


@dataclass(frozen=True)
class PoseResult:
    """What the tracker saw in one frame: a pose or explicitly none."""

    pose: Pose | None
    detector_runs: int = 0  # detector passes (windows) spent this frame
    detect_ms: float = 0.0
    landmark_ms: float = 0.0

    @property
    def found(self) -> bool:
        return self.pose is not None


def detector_for(cfg: TrackerConfig, zoom_score: float | None) -> PoseDetector:
    """The person detector as `cfg` sets it up; `zoom_score`, the faint candidates' score
    worth a zoom (None: no zooms, as when everyone's detections are kept)."""
    return PoseDetector(
        cfg.threads,
        cfg.min_detection_score,
        cfg.runtime,
        cfg.detector,
        cfg.spin,
        zoom_score,
        cfg.region_scale,
        cfg.window_detector,
    )


@dataclass
class PoseTracker:
    config: TrackerConfig = field(default_factory=TrackerConfig)

    def __post_init__(self) -> None:
        cfg = self.config
        self.detector = detector_for(cfg, cfg.zoom_score)
        self.landmarks = LandmarkModel(cfg.threads, cfg.model, cfg.runtime, cfg.spin)
        self._region: Region | None = None
        self._next_tile = 0  # where the search resumes in the tile cascade
        self._faint: Faint | None = None  # a faint candidate the last search left to zoom on
        self._filter = LandmarkFilter(self.config.smooth_landmarks, self.config.smooth_region)
        self._wide = WideFrame()  # each frame's four-channel form

    def reset(self) -> None:
        """Forget the tracked person (e.g. at a cut in the video)."""
        self._region = None
        self._next_tile = 0
        self._faint = None
        self._filter.reset()

    def process(
        self,
        image: np.ndarray,
        region: Region | None = None,
        band: GroundBand | None = None,
        timestamp: float | None = None,
    ) -> PoseResult:
        """Landmarks of the tracked person in this RGB frame.

        `region`, when given, replaces detection and tracking for this frame (used to feed
        a known crop, e.g. for ablations; it restarts the filters); the next frame tracks
        from its result. `band`, from the camera model when known, narrows the search to
        where people can stand. `timestamp` (s), when given, turns on the filtering across
        frames (TrackerConfig.smooth_landmarks / smooth_region); without it the pose is
        the landmark model's alone and the filters' state is left as it is.
        """
        runs, detect_ms, landmark_ms = 0, 0.0, 0.0
        # Four channels warp faster; widened once a frame, the whole frame only to search.
        self._wide.start(image)
        if region is not None:
            self._region = region
            self._filter.reset()
        for attempt in range(2):
            if self._region is None:
                self._filter.reset()  # a new track: MediaPipe's filters restart with it
                t0 = time.perf_counter()
                self._region, runs_now = self._acquire(self._wide.whole(), band)
                runs += runs_now
                detect_ms += (time.perf_counter() - t0) * 1e3
                if self._region is None:
                    break
            t0 = time.perf_counter()
            pose = self.landmarks.run(self._wide.around(*self._region.bounds()), self._region)
            landmark_ms += (time.perf_counter() - t0) * 1e3
            if pose.score >= self.config.min_pose_score:
                if timestamp is not None:
                    pose = self._filter.apply(pose, timestamp)
                next_region = pose.next_region(self.config.region_scale)
                self._region = next_region if next_region.valid else None
                return PoseResult(pose, runs, detect_ms, landmark_ms)
            self._region = None
            if attempt == 0 and runs > 0:
                break  # fresh detection already failed the landmark check
        return PoseResult(None, runs, detect_ms, landmark_ms)

    def _acquire(self, image: np.ndarray, band: GroundBand | None) -> tuple[Region | None, int]:
        h, w = image.shape[:2]
        cfg = self.config
        levels = search_windows(w, h, cfg.acquire_tiles, cfg.far_tiles, cfg.tile_overlap, band)
        tiles = [win for level in levels for win in level]
        steps = SearchSteps(
            Window(0, 0, w, h), tiles, self._next_tile, cfg.search_budget, self._faint
        )

        # The first window whose best detection gives a valid region; a window whose best
        # does not is passed over, as if it had found no one.
        dets, runs = self.detector.detect_first(
            image, steps, lambda d: d[0].region(cfg.region_scale).valid
        )
        if not dets:
            self._next_tile, self._faint = steps.next_tile, steps.carry
            return None, runs
        self._next_tile, self._faint = 0, None
        return dets[0].region(cfg.region_scale), runs
