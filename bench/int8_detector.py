"""An int8 detector against the float one: calibration windows, detection agreement, time.

The search frames (four detector passes while nobody is tracked) are about a quarter of a
scenario run's time and of our CPU-seconds against MediaPipe. An int8
detector would make each pass cheaper; it is worth shipping only if it finds the same
people in the same places. Three steps:

    .venv/bin/python -m bench.int8_detector windows --out recordings/int8/detector_windows.npz
        the detector's letterboxed input windows (the whole frame and every tile of the
        search cascade) of the calibration frame set (bench/frameset.py CALIBRATION),
        uint8, at most 600 of them
    .venv-models/bin/python -m tools.models.quantize --detector \
        --crops recordings/int8/detector_windows.npz --out recordings/int8/pose_detection_int8.onnx
    .venv/bin/python -m bench.int8_detector judge recordings/int8/pose_detection_int8.onnx
        on the large frame set (bench/frameset.py LARGE; other seeds and distances): every
        window through both detectors (who is found, and how far the int8 detection's
        keypoints move, over the float box's height), the tracker with each detector
        (share of frames found, sequences reset; and, since the detector only seeds the
        landmark model's region, the paired block-bootstrap interval of the landmark error
        difference on the frames both trackers found, bench/paired.py, the clip frames
        the calibration saw left out), and both timed on the same windows, alternated, at
        1 thread

`judge` appends one line to bench/history.jsonl unless --no-append. Nothing is shipped by
this script. The judged int8 detector ships as the tracker's `detector="int8"`
choice (monopic/pose/models/pose_detection_int8.onnx, `make models-int8`); the default
detector stays the float one.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

import numpy as np

from bench.alternate import alternated_ms
from bench.frameset import CALIBRATION, LARGE, FrameSet, build, load
from bench.int8_landmarks import errors, track
from bench.paired import paired_mean_difference
from bench.recorder import Recorder
from monopic.pose.anchors import INPUT_SIZE
from monopic.pose.detector import Detection, PoseDetector, letterbox
from monopic.pose.search import Window, search_windows
from monopic.pose.sessions import make_session
from monopic.pose.tracker import PoseTracker, TrackerConfig

TITLE = "An int8 detector against the float one (the search frames' time and CPU)"
FLOAT, INT8 = "float (shipped)", "int8 candidate"
MAX_WINDOWS = 600


def all_windows(width: int, height: int) -> list[Window]:
    """The whole frame and every tile the tracker's cascade visits (no ground band)."""
    cfg = TrackerConfig()
    levels = search_windows(width, height, cfg.acquire_tiles, cfg.far_tiles, cfg.tile_overlap, None)
    return [Window(0, 0, width, height), *[w for level in levels for w in level]]


def detector_with(path: Path | None, windows_only: bool = False) -> PoseDetector:
    """The shipped detector; with `path`, its session runs that file instead (with
    `windows_only`, on the windows smaller than the frame only, as the tracker's
    `window_detector`)."""
    detector = PoseDetector(1)
    if path is not None:
        session = make_session(path, 1)
        if session.get_inputs()[0].name != detector.input_name:
            raise SystemExit(f"int8_detector: {path} does not take the detector's input")
        detector._window_session = session
        if not windows_only:
            detector.session = session
    return detector


def cmd_windows(args: argparse.Namespace) -> None:
    fs = load(*build(recipe=CALIBRATION))
    h, w = fs.images.shape[1:3]
    tensors = [
        letterbox(np.asarray(fs.images[i]), win, INPUT_SIZE)[0]
        for i in range(len(fs))
        for win in all_windows(w, h)
    ]
    rng = np.random.default_rng(0)
    pick = np.sort(rng.choice(len(tensors), min(MAX_WINDOWS, len(tensors)), replace=False))
    windows = np.stack(
        [np.clip(np.rint((tensors[i] + 1.0) * 127.5), 0, 255).astype(np.uint8) for i in pick]
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, crops=windows)
    os.replace(tmp, args.out)
    print(f"{args.out}: {len(windows)} of {len(tensors)} windows from {len(fs)} frames")


def best(dets: list[Detection]) -> Detection | None:
    return dets[0] if dets else None


def tracked(fs: FrameSet, detector: PoseDetector) -> list[np.ndarray | None]:
    """The shipped tracker's landmarks (33, 2) or None per frame, with `detector` as its
    detector."""
    tracker = PoseTracker(TrackerConfig(threads=1))
    tracker.detector = detector
    return track(fs, tracker)["landmarks"]


def pass_times(paths: dict[str, Path | None], tensors: list[np.ndarray], rounds: int) -> dict:
    """Median ms per detector pass of each model on the same windows, alternated."""
    detectors = {k: detector_with(p) for k, p in paths.items()}
    calls = {
        k: (lambda t, d=d: d.session.run([d.regressor_name, d.score_name], {d.input_name: t[None]}))
        for k, d in detectors.items()
    }
    return alternated_ms(calls, tensors, rounds)


def cmd_judge(args: argparse.Namespace) -> None:
    if not args.model.is_file():
        raise SystemExit(f"int8_detector: {args.model}: no such file")
    recorder = Recorder("int8_detector", TITLE)
    fs = load(*build(recipe=LARGE))
    h, w = fs.images.shape[1:3]
    dets = {FLOAT: detector_with(None), INT8: detector_with(args.model, args.windows_only)}
    windows = all_windows(w, h)
    found = {FLOAT: 0, INT8: 0}
    both = only_float = only_int8 = 0
    moved: list[float] = []
    for i in range(len(fs)):
        image = np.asarray(fs.images[i])
        for win in windows:
            f = best(dets[FLOAT].detect(image, [win]))
            q = best(dets[INT8].detect(image, [win]))
            found[FLOAT] += f is not None
            found[INT8] += q is not None
            if f is not None and q is not None:
                both += 1
                height = max(f.box[3] - f.box[1], 1.0)
                moved.append(
                    float(np.linalg.norm(f.keypoints - q.keypoints, axis=1).max()) / height
                )
            elif f is not None:
                only_float += 1
            elif q is not None:
                only_int8 += 1
    landmarks = {k: tracked(fs, d) for k, d in dets.items()}
    found_frames = {k: np.array([lm is not None for lm in v]) for k, v in landmarks.items()}
    # The clip frames the calibration frame set holds are not judged (as int8_landmarks).
    scored = ~((fs.sequence == 0) & (np.arange(len(fs)) < (CALIBRATION.clip_frames or 0)))
    paired = np.flatnonzero(
        found_frames[FLOAT] & found_frames[INT8] & scored & fs.visible.any(axis=1)
    )
    err = {k: errors(fs, v, paired) for k, v in landmarks.items()}
    diff = paired_mean_difference(err[INT8], err[FLOAT], fs.sequence[paired])
    same = sum(np.array_equal(landmarks[FLOAT][i], landmarks[INT8][i]) for i in paired)
    sample = [
        letterbox(np.asarray(fs.images[i]), win, INPUT_SIZE)[0]
        for i in range(0, len(fs), max(1, len(fs) // 12))
        for win in windows[:: max(1, len(windows) // 4)]
    ]
    times = pass_times({FLOAT: None, INT8: args.model}, sample, args.rounds)
    moved_arr = np.array(moved) if moved else np.array([np.nan])
    n_win = len(fs) * len(windows)
    results: dict[str, Any] = {
        "model": str(args.model),
        "model_bytes": args.model.stat().st_size,
        "windows_only": args.windows_only,
        "frames": len(fs),
        "windows": n_win,
        "windows_found_float": found[FLOAT],
        "windows_found_int8": found[INT8],
        "windows_both": both,
        "windows_only_float": only_float,
        "windows_only_int8": only_int8,
        "keypoint_move_p50_pct": 100 * float(np.nanmedian(moved_arr)),
        "keypoint_move_p95_pct": 100 * float(np.nanpercentile(moved_arr, 95)),
        "tracked_pct": {k: 100 * float(v.mean()) for k, v in found_frames.items()},
        "tracked_disagree_frames": int((found_frames[FLOAT] != found_frames[INT8]).sum()),
        "landmark_judged_frames": len(paired),
        "landmark_identical_frames": int(same),
        "landmark_error_float_px": float(np.mean(np.concatenate(err[FLOAT]))),
        "landmark_error_int8_px": float(np.mean(np.concatenate(err[INT8]))),
        "landmark_difference_px": diff.difference,
        "landmark_difference_low_px": diff.low,
        "landmark_difference_high_px": diff.high,
        "pass_ms": times["ms"],
        "pass_ratio_x": times["ms"][INT8] / times["ms"][FLOAT],
    }
    lines = [
        f"Candidate `{args.model}` ({args.model.stat().st_size:,} bytes) against the shipped "
        f"float `pose_detection.onnx` on the large frame set ({len(fs)} frames, "
        f"{len(windows)} windows each: the whole frame and the search cascade's tiles)"
        + (
            ", the candidate on the windows smaller than the frame only."
            if args.windows_only
            else "."
        ),
        "",
        "| | float | int8 |",
        "| --- | ---: | ---: |",
        f"| windows with a detection (of {n_win}) | {found[FLOAT]} | {found[INT8]} |",
        f"| found by this one only | {only_float} | {only_int8} |",
        f"| frames the tracker found someone in | {results['tracked_pct'][FLOAT]:.1f} % "
        f"| {results['tracked_pct'][INT8]:.1f} % |",
        f"| tracker's mean landmark error, {len(paired)} frames both found "
        f"| {results['landmark_error_float_px']:.2f} px "
        f"| {results['landmark_error_int8_px']:.2f} px |",
        f"| ms per detector pass, 1 thread (load {times['load_min']:.1f}-"
        f"{times['load_max']:.1f}) | {times['ms'][FLOAT]:.2f} | {times['ms'][INT8]:.2f} |",
        "",
        f"Both found someone in {both} windows; the int8 detection's farthest keypoint moved "
        f"{results['keypoint_move_p50_pct']:.1f} % of the float box's height at the median, "
        f"{results['keypoint_move_p95_pct']:.1f} % at p95. The tracker's found/not-found "
        f"differed on {results['tracked_disagree_frames']} of {len(fs)} frames. "
        f"int8 / float per pass: {results['pass_ratio_x']:.2f}.",
        "",
        f"The tracker's landmark error, int8 detector - float detector, on the {len(paired)} "
        f"frames both found (clip frames 0-{(CALIBRATION.clip_frames or 0) - 1} left out; "
        f"{same} of them with identical landmarks): {diff.difference:+.2f} "
        f"[{diff.low:+.2f}, {diff.high:+.2f}] px (paired block bootstrap, 95 %).",
    ]
    table = "\n".join(lines)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("windows", help="calibration windows for the quantizer")
    w.add_argument("--out", type=Path, default=Path("recordings/int8/detector_windows.npz"))
    j = sub.add_parser("judge", help="judge an int8 detector against the float one")
    j.add_argument("model", type=Path)
    j.add_argument("--rounds", type=int, default=4)
    j.add_argument(
        "--windows-only",
        action="store_true",
        help="the candidate runs on the zooms and tiles only, the float model on the whole "
        "frame (TrackerConfig.window_detector)",
    )
    j.add_argument("--no-append", action="store_true")
    args = ap.parse_args()
    cmd_windows(args) if args.cmd == "windows" else cmd_judge(args)


if __name__ == "__main__":
    main()
