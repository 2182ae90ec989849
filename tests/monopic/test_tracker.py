"""The tracker's search budget: a pedestrian too small for the whole frame is found by the
tile cascade, spread over frames, with no frame spending more detector passes than allowed.
And its landmark filtering across frames: on with timestamps, restarted with each track
(with scripted models, fast), and smoother on the clip (real models, slow)."""

from __future__ import annotations

import math
from dataclasses import replace

import cv2
import numpy as np
import pytest

import monopic.pose.tracker as tracker_module
from monopic.pose.detector import Detection, PoseDetector
from monopic.pose.filtering import LandmarkFilter
from monopic.pose.landmarks import LandmarkModel, Pose
from monopic.pose.region import Region
from monopic.pose.search import SearchSteps, Window, tile_windows
from monopic.pose.sessions import (
    LANDMARK_FILE,
    make_session,
    model_path,
    quantised_unavailable,
    runtime_unavailable,
)
from monopic.pose.tracker import PoseTracker, TrackerConfig
from monopic.video import VideoSource
from tests.monopic.test_end_to_end import CLIP


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


@pytest.mark.slow
def test_unlimited_search_finds_the_small_person_in_the_first_frame():
    tracker = PoseTracker(TrackerConfig(search_budget=0, zoom_score=None))
    first = tracker.process(small_person_frame())
    assert first.found
    assert first.detector_runs > 4  # the whole frame and the 432 px tiles missed it


@pytest.mark.slow
def test_a_zoom_on_a_faint_candidate_finds_the_small_person_at_once():
    """The whole frame sees nothing; a 432 px tile half-sees the 45 px walker (below the
    detector's threshold, above the zoom's), and the zoom on that candidate's region
    finds them in the first frame, where the cascade alone needs seven frames. (The 432 px
    tiles first, as before session 18, to see the zoom at work on this frame.)"""
    frame = small_person_frame()
    tiles = (432, 288, 216)
    zooming = PoseTracker(TrackerConfig(search_budget=4, acquire_tiles=tiles))
    first = zooming.process(frame)
    assert first.found and first.detector_runs == 4  # whole frame, 2 tiles, the zoom
    cascade = PoseTracker(TrackerConfig(search_budget=4, zoom_score=None, acquire_tiles=tiles))
    results = [cascade.process(frame) for _ in range(8)]
    assert next(k for k, r in enumerate(results) if r.found) == 6


@pytest.mark.slow
def test_budgeted_search_spreads_the_cascade_over_frames_and_then_tracks():
    config = TrackerConfig(search_budget=4, zoom_score=None)
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


@pytest.mark.parametrize("score", [0.0, 0.5, 0.9])
def test_the_zoom_threshold_must_lie_below_the_detectors(score: float):
    with pytest.raises(ValueError, match="zoom_score must be None or between 0 and"):
        TrackerConfig(zoom_score=score)


@pytest.mark.slow
def test_timestamps_smooth_the_clip_track():
    """On the clip, the filtered track has less frame-to-frame jitter than the raw one
    (second differences of the landmark positions) and stays within a few pixels of it."""
    frames = list(VideoSource(str(CLIP)))[:30]
    raw_tracker, smooth_tracker = PoseTracker(), PoseTracker()
    raw = [raw_tracker.process(f.image).pose for f in frames]
    smooth = [smooth_tracker.process(f.image, timestamp=f.timestamp).pose for f in frames]
    assert all(p is not None for p in raw + smooth)
    raw_xy = np.stack([p.landmarks[:, :2] for p in raw])
    smooth_xy = np.stack([p.landmarks[:, :2] for p in smooth])
    jitter = lambda xy: float(np.abs(np.diff(xy, n=2, axis=0)).mean())  # noqa: E731
    assert jitter(smooth_xy) < 0.8 * jitter(raw_xy)
    assert np.median(np.linalg.norm(smooth_xy - raw_xy, axis=2)) < 3.0


# Scripted models: the tracker's filtering logic without running a network.

IMAGE = np.zeros((432, 768, 3), dtype=np.uint8)


def scripted_pose(k: int, score: float = 0.99) -> Pose:
    """Frame k of a jittery walker moving right at 4 px per frame, ~100 px tall."""
    rng = np.random.default_rng(k)
    base = np.random.default_rng(0).uniform(0, 100, (33, 3))
    lm = base + [300.0 + 4 * k, 150.0, 0.0] + rng.normal(0, 1.5, (33, 3))
    aux = np.array([[350.0 + 4 * k, 200.0], [350.0 + 4 * k, 140.0]] + [[0.0, 0.0]] * 4)
    aux = aux + rng.normal(0, 1.5, aux.shape)
    return Pose(
        landmarks=lm,
        visibility=rng.uniform(0.2, 1.0, 33),
        presence=np.full(33, 0.9),
        score=score,
        region=Region(350.0, 200.0, 150.0),
        aux=aux,
    )


class ScriptedLandmarks:
    def __init__(self, *args) -> None:
        self.script: list[Pose] = []
        self.regions: list[Region] = []  # the region of every run

    def run(self, image: np.ndarray, region: Region) -> Pose:
        self.regions.append(region)
        return replace(self.script.pop(0), region=region)


class ScriptedDetector:
    _tiles = None  # one thread: the real detector's window-by-window search over `look`
    detect_first = PoseDetector.detect_first

    def look(self, image: np.ndarray, win) -> tuple[list[Detection], None]:
        return self.detect(image, [win]), None

    def __init__(self, *args) -> None:
        self.finds: list[bool] = []  # per detect() call: somebody there or not

    def detect(self, image: np.ndarray, windows=None) -> list[Detection]:
        if not self.finds.pop(0):
            return []
        kps = np.array([[350.0, 200.0], [350.0, 140.0], [350.0, 160.0], [350.0, 120.0]])
        return [Detection(0.9, (300.0, 100.0, 400.0, 300.0), kps)]


@pytest.fixture
def scripted(monkeypatch) -> PoseTracker:
    monkeypatch.setattr(tracker_module, "LandmarkModel", ScriptedLandmarks)
    monkeypatch.setattr(tracker_module, "PoseDetector", ScriptedDetector)
    # No tiles: one detector call per acquiring frame.
    return PoseTracker(TrackerConfig(acquire_tiles=(), far_tiles=()))


def feed(tracker: PoseTracker, poses: list[Pose], finds: list[bool]) -> None:
    tracker.landmarks.script = list(poses)
    tracker.detector.finds = list(finds)


def test_without_timestamps_the_tracker_returns_the_models_poses(scripted):
    poses = [scripted_pose(k) for k in range(6)]
    feed(scripted, poses, [True])
    out = [scripted.process(IMAGE).pose for _ in poses]
    for got, want in zip(out, poses, strict=True):
        np.testing.assert_array_equal(got.landmarks, want.landmarks)
        np.testing.assert_array_equal(got.visibility, want.visibility)
        np.testing.assert_array_equal(got.aux, want.aux)
    # Each next region comes from the raw auxiliary points.
    for k in range(1, len(poses)):
        assert scripted.landmarks.regions[k] == poses[k - 1].next_region()


def test_with_timestamps_landmarks_and_next_region_are_smoothed(scripted):
    poses = [scripted_pose(k) for k in range(6)]
    feed(scripted, poses, [True])
    out = [scripted.process(IMAGE, timestamp=k / 15).pose for k in range(len(poses))]
    oracle = LandmarkFilter()
    for k, (got, raw) in enumerate(zip(out, poses, strict=True)):
        want = oracle.apply(raw, k / 15)
        np.testing.assert_array_equal(got.landmarks, want.landmarks)
        np.testing.assert_array_equal(got.visibility, want.visibility)
        if k:
            assert not np.allclose(got.landmarks, raw.landmarks)
            assert scripted.landmarks.regions[k] == out[k - 1].next_region()
        if k >= 2:  # (frame 0's pose, the filters' first sample, is raw)
            assert scripted.landmarks.regions[k] != poses[k - 1].next_region()
    np.testing.assert_array_equal(out[0].landmarks, poses[0].landmarks)  # first: as is


def test_smoothing_can_be_switched_off(monkeypatch):
    monkeypatch.setattr(tracker_module, "LandmarkModel", ScriptedLandmarks)
    monkeypatch.setattr(tracker_module, "PoseDetector", ScriptedDetector)
    tracker = PoseTracker(TrackerConfig(smooth_landmarks=False, smooth_region=False))
    poses = [scripted_pose(k) for k in range(4)]
    feed(tracker, poses, [True])
    for k, want in enumerate(poses):
        got = tracker.process(IMAGE, timestamp=k / 15).pose
        np.testing.assert_array_equal(got.landmarks, want.landmarks)
        np.testing.assert_array_equal(got.aux, want.aux)


def test_the_filter_restarts_when_the_person_is_lost(scripted):
    a0, a1, b = scripted_pose(0), scripted_pose(1), scripted_pose(9)
    lost = scripted_pose(2, score=0.1)
    # Frame 0: detect, a0. Frame 1: a1 (tracked). Frame 2: landmarks fail, the detector
    # finds nobody: lost. Frame 3: detect, b.
    feed(scripted, [a0, a1, lost, b], [True, False, True])
    assert scripted.process(IMAGE, timestamp=0.0).found
    assert scripted.process(IMAGE, timestamp=1 / 15).found
    assert not scripted.process(IMAGE, timestamp=2 / 15).found
    got = scripted.process(IMAGE, timestamp=3 / 15).pose
    # A fresh track: b comes back as is, not blended with a1.
    np.testing.assert_array_equal(got.landmarks, b.landmarks)
    np.testing.assert_array_equal(got.visibility, b.visibility)
    np.testing.assert_array_equal(got.aux, b.aux)


def test_the_filter_restarts_when_the_person_is_found_again_in_the_same_frame(scripted):
    a0, b = scripted_pose(0), scripted_pose(9)
    lost = scripted_pose(1, score=0.1)
    # Frame 1: the tracked region fails, the detector finds someone at once: b.
    feed(scripted, [a0, lost, b], [True, True])
    scripted.process(IMAGE, timestamp=0.0)
    got = scripted.process(IMAGE, timestamp=1 / 15).pose
    np.testing.assert_array_equal(got.landmarks, b.landmarks)


@pytest.mark.parametrize("how", ["reset", "region"])
def test_reset_and_a_given_region_restart_the_filter(scripted, how):
    a0, a1 = scripted_pose(0), scripted_pose(1)
    feed(scripted, [a0, a1], [True, True])
    scripted.process(IMAGE, timestamp=0.0)
    if how == "reset":
        scripted.reset()
        got = scripted.process(IMAGE, timestamp=1 / 15).pose
    else:
        got = scripted.process(IMAGE, Region(350.0, 170.0, 150.0), timestamp=1 / 15).pose
    np.testing.assert_array_equal(got.landmarks, a1.landmarks)


def test_the_filter_restarts_after_a_frame_where_nobody_is_found(scripted):
    """The track can also end without a failed landmark pass: a pose whose next region
    is degenerate (here 0.75 px) sends the next frame to the detector, which finds
    nobody."""
    a0, b = scripted_pose(0), scripted_pose(9)
    a1 = scripted_pose(1)
    a1.aux[1] = a1.aux[0] + [0.0, -0.3]
    feed(scripted, [a0, a1, b], [True, False, True])
    assert scripted.process(IMAGE, timestamp=0.0).found
    assert scripted.process(IMAGE, timestamp=1 / 15).found
    assert not scripted.process(IMAGE, timestamp=2 / 15).found
    got = scripted.process(IMAGE, timestamp=3 / 15).pose
    np.testing.assert_array_equal(got.landmarks, b.landmarks)
    np.testing.assert_array_equal(got.visibility, b.visibility)


def clip_truth_first_frame() -> np.ndarray:
    """The true pixel positions of the 33 landmarks in the clip's first frame."""
    import csv

    with CLIP.with_name("walk_clip_truth.csv").open() as fh:
        row = next(csv.DictReader(fh))
    return np.array([[float(row[f"lm{i}_u"]), float(row[f"lm{i}_v"])] for i in range(33)])


INT8_UNAVAILABLE = quantised_unavailable()
needs_int8 = pytest.mark.skipif(INT8_UNAVAILABLE is not None, reason=str(INT8_UNAVAILABLE))


@pytest.mark.parametrize(
    "model", ["lite", "full", "heavy", pytest.param("full-int8", marks=needs_int8)]
)
def test_every_landmark_model_choice_finds_the_walker(model: str):
    """Each of MediaPipe's three landmark models, and the full one quantised, loads and
    puts the walker's shoulders and hips within a few pixels of the truth in the clip's
    first frame (a 768x432 frame in which the walker is about 230 px tall)."""
    tracker = PoseTracker(TrackerConfig(model=model))
    assert tracker.landmarks.model == model
    result = tracker.process(next(iter(VideoSource(str(CLIP)))).image)
    assert result.found
    assert result.pose is not None and result.pose.score > 0.5
    torso = [11, 12, 23, 24]
    err = np.linalg.norm(result.pose.landmarks[torso, :2] - clip_truth_first_frame()[torso], axis=1)
    assert np.all(err < 12.0), err


@needs_int8
def test_the_int8_landmarks_stay_near_the_full_models_over_the_clip():
    """full-int8 is the full model quantised: over the clip's first 30 frames its visible
    landmarks stay within a pixel or two of the float model's on a typical frame (issue
    21's judge: 1.6-2.0 px apart on average, the error against the truth unchanged within
    0.3 px; a frame where the two tracks part can be 10 px apart, hence the median)."""
    trackers = [PoseTracker(TrackerConfig(model=m)) for m in ("full", "full-int8")]
    gaps = []
    for i, frame in enumerate(VideoSource(str(CLIP))):
        if i == 30:
            break
        a, b = (t.process(frame.image).pose for t in trackers)
        assert a is not None and b is not None
        seen = a.visibility > 0.5
        gaps.append(np.linalg.norm(a.landmarks[seen, :2] - b.landmarks[seen, :2], axis=1).mean())
    assert 0.0 < float(np.median(gaps)) < 2.0, gaps  # not the float model, and close to it


def test_the_int8_models_are_refused_on_an_x86_cpu_without_vnni(monkeypatch):
    """onnxruntime's u8s8 kernels saturate without VNNI: the int8 files, judged only on
    VNNI CPUs, lost the walker there. Refused by name, float models unaffected."""
    import monopic.pose.sessions as sessions

    avx2 = frozenset({"sse4_2", "avx", "avx2", "fma"})
    assert sessions.quantised_unavailable(avx2) is not None
    assert sessions.quantised_unavailable(avx2 | {"avx512_vnni"}) is None
    assert sessions.quantised_unavailable(avx2 | {"avx_vnni"}) is None
    monkeypatch.setattr(sessions, "x86_cpu_flags", lambda: avx2)
    with pytest.raises(ValueError, match="'full-int8'.*VNNI"):
        TrackerConfig(model="full-int8")
    with pytest.raises(ValueError, match="'int8'.*VNNI"):
        TrackerConfig(detector="int8")
    with pytest.raises(ValueError, match="'int8'.*VNNI"):
        TrackerConfig(window_detector="int8")
    TrackerConfig(model="full", detector="float")


def test_an_unknown_landmark_model_is_refused_with_the_choices():
    with pytest.raises(ValueError, match="lite, full, heavy"):
        TrackerConfig(model="medium")
    with pytest.raises(ValueError, match="unknown detector model 'fp16': choose one of float"):
        TrackerConfig(detector="fp16")


@needs_int8
def test_the_int8_detector_finds_the_walker_where_the_float_one_does():
    """The int8 detector (issue 21) on the clip's first frames, whole frame: one person,
    box and keypoints a few pixels from the float detector's (the judge: keypoints move
    1 % of the box's height at the median, 3 % at p95; the walker is about 230 px tall)."""
    float_det, int8_det = PoseDetector(model="float"), PoseDetector(model="int8")
    for i, frame in enumerate(VideoSource(str(CLIP))):
        if i == 10:
            break
        a, b = float_det.detect(frame.image), int8_det.detect(frame.image)
        assert len(a) == len(b) == 1
        height = a[0].box[3] - a[0].box[1]
        assert 0.0 < np.abs(np.subtract(a[0].box, b[0].box)).max() < 0.05 * height
        assert np.abs(a[0].keypoints - b[0].keypoints).max() < 0.05 * height


@needs_int8
@pytest.mark.parametrize("threads", [1, 2])
def test_the_window_detector_runs_on_zooms_and_tiles_and_the_whole_frame_keeps_its_own(threads):
    """`window_model` (TrackerConfig.window_detector): the whole frame gives the float
    detector's detections bit for bit, a tile the int8 detector's, alone or beside other
    windows on two threads."""
    frame = small_person_frame()
    whole, tiles = Window(0, 0, 768, 432), tile_windows(768, 432, 216)
    mixed = PoseDetector(threads=threads, model="float", window_model="int8")
    float_det, int8_det = PoseDetector(model="float"), PoseDetector(model="int8")

    def same(a: list[Detection], b: list[Detection]) -> bool:
        return len(a) == len(b) and all(
            x.score == y.score and x.box == y.box and np.array_equal(x.keypoints, y.keypoints)
            for x, y in zip(a, b, strict=True)
        )

    near = next(iter(VideoSource(str(CLIP)))).image
    assert float_det.detect(near) and same(mixed.detect(near), float_det.detect(near))
    assert not same(int8_det.detect(near), float_det.detect(near))
    found = [t for t in tiles if int8_det.detect(frame, [t])]
    assert found  # the small walker is in some tile
    assert same(mixed.detect(frame, [found[0]]), int8_det.detect(frame, [found[0]]))
    assert not same(int8_det.detect(frame, [found[0]]), float_det.detect(frame, [found[0]]))
    # The search: the whole frame finds no one here, then the first tile with someone.
    dets, _ = mixed.detect_first(frame, SearchSteps(whole, tiles, 0, 0))
    want, _ = int8_det.detect_first(frame, SearchSteps(whole, tiles, 0, 0))
    assert same(dets, want)
    with pytest.raises(ValueError, match="unknown detector model 'fp16'"):
        TrackerConfig(window_detector="fp16")


def test_spinning_threads_spin_within_runs_only_and_give_the_same_landmarks():
    """`spin` (issue 21) lets a 2-thread pool spin-wait between operators and stops it
    when a run returns; one thread has no pool to spin. Spinning changes when threads
    wake, not what they compute: the tracked landmarks are the same bits."""

    def entries(session) -> tuple[str | None, ...]:
        opts, out = session.get_session_options(), []
        for key in ("session.intra_op.allow_spinning", "session.force_spinning_stop"):
            try:
                out.append(opts.get_session_config_entry(key))
            except RuntimeError:  # onnxruntime's answer for a key never set
                out.append(None)
        return tuple(out)

    assert entries(make_session(model_path(LANDMARK_FILE), 2, spin=True)) == ("1", "1")
    assert entries(make_session(model_path(LANDMARK_FILE), 2)) == ("0", None)
    assert entries(make_session(model_path(LANDMARK_FILE), 1, spin=True)) == ("0", None)
    spinning = PoseTracker(TrackerConfig(threads=2, spin=True))
    assert entries(spinning.landmarks.session) == entries(spinning.detector.session)
    sleeping = PoseTracker(TrackerConfig(threads=2))
    for i, frame in enumerate(VideoSource(str(CLIP))):
        if i == 5:
            break
        a = spinning.process(frame.image, timestamp=frame.timestamp).pose
        b = sleeping.process(frame.image, timestamp=frame.timestamp).pose
        assert np.array_equal(a.landmarks, b.landmarks)


def test_tiles_run_side_by_side_with_two_threads_and_find_the_same():
    """With threads > 1 a frame's tiles run in parallel, one single-threaded pass each
    (issue 21): the same detections, bit for bit, as one after another on one thread."""
    frame = small_person_frame()
    tiles = tile_windows(768, 432, 216)
    one, two = PoseDetector(threads=1), PoseDetector(threads=2, spin=True)
    assert one._tiles is None and two._tiles is not None
    (a, runs_a), (b, runs_b) = (
        d.detect_first(frame, SearchSteps(Window(0, 0, 768, 432), tiles, 0, 0)) for d in (one, two)
    )
    assert len(a) >= 1 and len(a) == len(b) and runs_a <= runs_b <= runs_a + 1
    for x, y in zip(a, b, strict=True):
        assert x.score == y.score and x.box == y.box
        assert np.array_equal(x.keypoints, y.keypoints)
    tracked = [PoseTracker(TrackerConfig(threads=t, search_budget=0)) for t in (1, 2)]
    poses = [t.process(frame).pose for t in tracked]
    assert poses[0] is not None and np.array_equal(poses[0].landmarks, poses[1].landmarks)


def test_the_budgeted_search_finds_the_same_with_two_threads_spending_a_pass_ahead():
    """With two threads the next batch's first window runs beside the current batch (the
    whole frame beside the first tile): the same frames found, the same landmarks and
    the same place in the cascade; the passes spent count the one run ahead."""
    small, near = small_person_frame(), next(iter(VideoSource(str(CLIP)))).image
    frames = [small] * 6 + [IMAGE] * 2 + [near]  # search, track, lose, find near at once
    one, two = (PoseTracker(TrackerConfig(threads=t)) for t in (1, 2))
    for k, image in enumerate(frames):
        a, b = one.process(image), two.process(image)
        assert a.found == b.found, k
        if a.found:
            assert np.array_equal(a.pose.landmarks, b.pose.landmarks), k
        assert one._next_tile == two._next_tile, k
        if a.detector_runs:  # the batches one thread ran, and at most one pass ahead
            assert a.detector_runs <= b.detector_runs <= a.detector_runs + 1, k
    assert a.found and a.detector_runs == 1 and b.detector_runs == 2  # near: whole frame


class PointDetector(ScriptedDetector):
    """The whole frame finds a 'person' whose two keypoints coincide (no region); the
    tiles find a real one."""

    def detect(self, image: np.ndarray, windows=None) -> list[Detection]:
        whole = len(windows) == 1 and windows[0].width == image.shape[1]
        kps = np.array([[350.0, 200.0], [350.0, 200.0 if whole else 140.0]] + [[350.0, 150.0]] * 2)
        return [Detection(0.9, (300.0, 100.0, 400.0, 300.0), kps)]


def test_a_batch_whose_best_detection_gives_no_region_is_passed_over(monkeypatch):
    monkeypatch.setattr(tracker_module, "LandmarkModel", ScriptedLandmarks)
    monkeypatch.setattr(tracker_module, "PoseDetector", PointDetector)
    tracker = PoseTracker(TrackerConfig())
    tracker.landmarks.script = [scripted_pose(0)]
    result = tracker.process(IMAGE)
    assert result.found and result.detector_runs == 2  # the whole frame, then the first tile
    assert [r.side > 100.0 for r in tracker.landmarks.regions] == [True]  # the tiles' 60 px


OPENVINO_UNAVAILABLE = runtime_unavailable("openvino")  # why not, asked once


@pytest.mark.skipif(OPENVINO_UNAVAILABLE is not None, reason=str(OPENVINO_UNAVAILABLE))
def test_the_openvino_runtime_gives_the_cpu_runtimes_landmarks_on_the_clip():
    """The same crops, the same landmarks: OpenVINO computes in float32 (no bfloat16 on
    AMX). Measured: at most 2e-4 px apart. (Tracked over 40 frames the two drift up to
    pixels apart, as any change in the last digits would: the region follows the pose.)"""
    frames = list(VideoSource(str(CLIP)))[:12]
    tracker = PoseTracker(TrackerConfig(runtime="cpu"))
    regions = []
    for f in frames:
        tracker.process(f.image)
        regions.append(tracker._region)
    models = {rt: LandmarkModel(1, "full", rt) for rt in ("cpu", "openvino")}
    checked = 0
    for f, region in zip(frames[1:], regions[:-1], strict=True):
        if region is None:
            continue
        cpu, ov = (models[rt].run(f.image, region) for rt in ("cpu", "openvino"))
        assert np.max(np.abs(cpu.landmarks[:, :2] - ov.landmarks[:, :2])) < 0.01  # px
        assert abs(cpu.score - ov.score) < 1e-3
        checked += 1
    assert checked >= 10


def test_an_unknown_or_missing_runtime_is_one_clear_error():
    with pytest.raises(ValueError, match="unknown runtime 'gpu': choose one of cpu, openvino"):
        TrackerConfig(runtime="gpu")


def test_the_openvino_runtime_without_its_extra_names_the_extra(monkeypatch):
    import sys

    from monopic.pose.sessions import check_runtime

    monkeypatch.setitem(sys.modules, "onnxruntime_ep_openvino", None)  # import fails
    with pytest.raises(ValueError, match=r"pip install -e '\.\[openvino\]'"):
        check_runtime("openvino")
