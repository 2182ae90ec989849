"""An int8 landmark model against the float one: calibration crops, landmark error, time.

An int8 landmark model (per-channel weights, calibrated on rendered frames and
the shipped clip) ships only if the paired mean landmark difference, int8 minus float in
error against the truth on the frames both found, has a 95 % upper bound within 0.3 px on
at least 500 frames. Three steps:

    .venv/bin/python -m bench.int8_landmarks crops --out recordings/int8/calibration.npz
        the float tracker over the calibration frame set (bench/frameset.py CALIBRATION:
        the clip's first 30 frames and 16 rendered clips with their own seeds); every
        landmark-model input crop it made, uint8
    .venv-models/bin/python -m tools.models.quantize --crops recordings/int8/calibration.npz
        --out recordings/int8/pose_landmark_full_int8.onnx   (onnxruntime's quantizer)
    .venv/bin/python -m bench.int8_landmarks judge recordings/int8/pose_landmark_full_int8.onnx
        the tracker with each model over the large frame set (600 frames: the clip and the
        nine cases at 3, 5 and 8 m; the clip frames used for calibration are not scored),
        the paired block-bootstrap interval of the mean difference (bench/paired.py), and
        both models timed on the same crops, alternated, at 1 and 2 threads

`judge` appends one line to bench/history.jsonl unless --no-append.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from bench.alternate import alternated_ms
from bench.frameset import CALIBRATION, LARGE, FrameSet, build, load
from bench.paired import paired_mean_difference, paired_median_difference
from bench.recorder import Recorder
from monopic.pose.landmarks import INPUT_SIZE
from monopic.pose.sessions import LANDMARK_MODELS, make_session, model_path
from monopic.pose.tracker import PoseTracker, TrackerConfig

BOUND_PX = 0.3  # px: the most an int8 model may add to the error, the paired interval's upper end
MIN_FRAMES = 500
TITLE = "An int8 landmark model against the float one (its 0.3 px bound)"
FLOAT, INT8 = "float (shipped)", "int8 candidate"


def tracker_with(path: Path | None, threads: int = 1) -> PoseTracker:
    """The shipped tracker; with `path`, its landmark session runs that file instead."""
    tracker = PoseTracker(TrackerConfig(threads=threads))
    if path is not None:
        session = make_session(path, threads, spin=False)
        names = {o.name for o in session.get_outputs()}
        if missing := set(tracker.landmarks.output_names) - names:
            raise SystemExit(f"int8_landmarks: {path} lacks the output(s) {sorted(missing)}")
        if session.get_inputs()[0].name != tracker.landmarks.input_name:
            raise SystemExit(f"int8_landmarks: {path} does not take `image` as its input")
        tracker.landmarks.session = session
    return tracker


def track(fs: FrameSet, tracker: PoseTracker, keep_crops: bool = False) -> dict[str, Any]:
    """Landmarks (33, 2) or None per frame, tracker reset at each sequence, and the crops."""
    out: list[np.ndarray | None] = []
    crops: list[np.ndarray] = []
    run = tracker.landmarks.run

    def recording(image: np.ndarray, region: Any) -> Any:
        crops.append(region.crop(image, INPUT_SIZE))
        return run(image, region)

    if keep_crops:
        tracker.landmarks.run = recording  # type: ignore[method-assign]
    for i in range(len(fs)):
        if i == 0 or fs.sequence[i] != fs.sequence[i - 1]:
            tracker.reset()
        r = tracker.process(np.array(fs.images[i]), timestamp=float(fs.timestamp[i]))
        out.append(None if r.pose is None else r.pose.landmarks[:, :2].copy())
    return {"landmarks": out, "crops": crops}


def cmd_crops(args: argparse.Namespace) -> None:
    npy, npz = build(recipe=CALIBRATION)
    fs = load(npy, npz)
    crops = track(fs, tracker_with(None), keep_crops=True)["crops"]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(args.out, crops=np.stack(crops))
    print(f"{args.out}: {len(crops)} crops from {len(fs)} calibration frames ({CALIBRATION})")


def errors(fs: FrameSet, lms: list[np.ndarray | None], frames: np.ndarray) -> list[np.ndarray]:
    """Per frame, the pixel errors of the visible landmarks against the truth."""
    out = []
    for i in frames:
        lm = lms[i]
        assert lm is not None
        d = np.linalg.norm(lm - fs.landmarks[i], axis=1)
        out.append(d[fs.visible[i]])
    return out


def model_times(
    paths: dict[str, Path], crops: np.ndarray, threads: int, rounds: int
) -> dict[str, Any]:
    """Median ms per run of each model on the same crops, alternated (A B B A ...)."""
    sessions = {k: make_session(p, threads, spin=False) for k, p in paths.items()}
    feeds = [{"image": (c.astype(np.float32) / 255.0)[None]} for c in crops]
    calls = {k: (lambda feed, s=s: s.run(None, feed)) for k, s in sessions.items()}
    return {"threads": threads, **alternated_ms(calls, feeds, rounds)}


def cmd_judge(args: argparse.Namespace) -> None:
    if not args.model.is_file():
        raise SystemExit(f"int8_landmarks: {args.model}: no such file")
    recorder = Recorder("int8_landmarks", TITLE)
    start = time.perf_counter()
    npy, npz = build(recipe=LARGE)
    fs = load(npy, npz)
    runs = {
        FLOAT: track(fs, tracker_with(None), keep_crops=True),
        INT8: track(fs, tracker_with(args.model)),
    }
    n = len(fs)
    found = {k: np.array([lm is not None for lm in r["landmarks"]]) for k, r in runs.items()}
    # The clip frames the calibration saw are not judged.
    scored = ~((fs.sequence == 0) & (np.arange(n) < (CALIBRATION.clip_frames or 0)))
    both = np.flatnonzero(found[FLOAT] & found[INT8] & scored & fs.visible.any(axis=1))
    e = {k: errors(fs, r["landmarks"], both) for k, r in runs.items()}
    seq = fs.sequence[both]
    mean = paired_mean_difference(e[INT8], e[FLOAT], seq)
    median = paired_median_difference(e[INT8], e[FLOAT], seq)
    shift = np.concatenate(
        [
            np.linalg.norm(runs[INT8]["landmarks"][i] - runs[FLOAT]["landmarks"][i], axis=1)[
                fs.visible[i]
            ]
            for i in both
        ]
    )
    passes = len(both) >= MIN_FRAMES and mean.high <= BOUND_PX
    crops = np.stack(runs[FLOAT]["crops"])[:: max(1, len(runs[FLOAT]["crops"]) // 40)]
    paths = {FLOAT: model_path(LANDMARK_MODELS["full"]), INT8: args.model}
    times = [model_times(paths, crops, t, args.rounds) for t in args.threads]
    groups = [("all judged", np.ones(len(both), dtype=bool))]
    groups.append(("clip (frames 30-59)", fs.sequence[both] == 0))
    for d in sorted({float(x) for x in fs.distance if np.isfinite(x)}):
        groups.append((f"rendered, {d:g} m", fs.distance[both] == d))
    rows = []
    for name, g in groups:
        idx = np.flatnonzero(g)
        if not len(idx):
            continue
        a, b = [e[INT8][k] for k in idx], [e[FLOAT][k] for k in idx]
        d = paired_mean_difference(a, b, seq[idx])
        rows.append(
            {
                "group": name,
                "frames": len(idx),
                "mean_error_float_px": float(np.mean(np.concatenate(b))),
                "mean_error_int8_px": float(np.mean(np.concatenate(a))),
                "difference_px": d.difference,
                "low_px": d.low,
                "high_px": d.high,
            }
        )
    results: dict[str, Any] = {
        "model": str(args.model),
        "model_bytes": args.model.stat().st_size,
        "frames": n,
        "judged_frames": len(both),
        "found_pct": {k: 100 * float(v.mean()) for k, v in found.items()},
        "mean_difference_px": mean.difference,
        "mean_low_px": mean.low,
        "mean_high_px": mean.high,
        "median_difference_px": median.difference,
        "median_low_px": median.low,
        "median_high_px": median.high,
        "shift_mean_px": float(shift.mean()),
        "shift_p95_px": float(np.percentile(shift, 95)),
        "bound_px": BOUND_PX,
        "min_frames": MIN_FRAMES,
        "passes": passes,
        "groups": rows,
        "times": times,
    }
    lines = [
        f"Candidate `{args.model}` ({args.model.stat().st_size:,} bytes) against the shipped "
        f"float `pose_landmark_full.onnx`, each in the shipped tracker over the large frame "
        f"set ({n} frames, {len(fs.sequences)} sequences); judged: {len(both)} frames both "
        f"found (found: float {results['found_pct'][FLOAT]:.0f} %, int8 "
        f"{results['found_pct'][INT8]:.0f} %), clip frames 0-29 left out (calibration).",
        "",
        "| frames | n | mean error float | mean error int8 | int8 - float [95 % interval] |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        lines.append(
            f"| {r['group']} | {r['frames']} | {r['mean_error_float_px']:.2f} px "
            f"| {r['mean_error_int8_px']:.2f} px | {r['difference_px']:+.2f} "
            f"[{r['low_px']:+.2f}, {r['high_px']:+.2f}] px |"
        )
    lines += [
        "",
        f"Median over landmarks: int8 - float {median.difference:+.2f} [{median.low:+.2f}, "
        f"{median.high:+.2f}] px. int8 landmarks moved from the float ones by {shift.mean():.2f} "
        f"px on average (p95 {np.percentile(shift, 95):.2f} px).",
        "",
        "| threads | load | float ms per run | int8 ms per run | int8 / float |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for t in times:
        lines.append(
            f"| {t['threads']} | {t['load_min']:.1f}-{t['load_max']:.1f} | {t['ms'][FLOAT]:.2f} "
            f"| {t['ms'][INT8]:.2f} | {t['ms'][INT8] / t['ms'][FLOAT]:.2f} |"
        )
    verdict = "passes" if passes else "fails"
    lines += [
        "",
        f"Bound (upper end of the paired mean interval <= {BOUND_PX} px on >= {MIN_FRAMES} "
        f"frames): {mean.high:+.2f} px on {len(both)} frames: {verdict}.",
        f"{time.perf_counter() - start:.0f} s in all.",
    ]
    table = "\n".join(lines)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    c = sub.add_parser("crops", help="calibration crops from the float tracker")
    c.add_argument("--out", type=Path, default=Path("recordings/int8/calibration.npz"))
    j = sub.add_parser("judge", help="an int8 candidate against the shipped float model")
    j.add_argument("model", type=Path)
    j.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    j.add_argument("--rounds", type=int, default=6)
    j.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    {"crops": cmd_crops, "judge": cmd_judge}[args.command](args)


if __name__ == "__main__":
    main()
