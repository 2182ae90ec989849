"""The stage after pose: time per frame (µs) and operation count, beside the paper's 8 ms / 23.

Poses are recorded once by running our tracker over the benchmark frame set
(bench/frameset.py); then the stage after pose (features: facing angle, Kalman, image
velocity, foot point, ground motion; each predictor; warning; path projection) is
replayed over those poses many times, a fresh FeatureExtractor per sequence, exactly as
Pipeline.process runs it. One onnxruntime-free, single-threaded Python loop: the
thread count does not matter here. Operation counts come from monopic/tree/opcount.py:
the worst case over inputs and the mean over the recorded frames. The results go to
bench/history.jsonl (bench/history.py) unless --no-append.

With --intent-tree FILE (a ground intent tree, `monopic tree train --mode ground`) the
runner set is timed again with that tree added, as a sweep spec's `intent_tree` runs it,
and the tree's operation counts (worst case and mean over the recorded frames) are added.

    .venv/bin/python -m bench.post_pose [--repeats 30] [--intent-tree FILE] [--no-append]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from bench.frameset import build, load
from bench.recorder import Recorder
from monopic.features.extractor import FeatureExtractor
from monopic.frame import EgoState
from monopic.horizon import HORIZON_S
from monopic.pose.tracker import PoseTracker, TrackerConfig
from monopic.predict.base import Mode
from monopic.predict.registry import make_predictor
from monopic.tree.model import TreePredictor
from monopic.tree.opcount import (
    PAPER_CALCULATIONS_PER_PREDICTION,
    mean_prediction_ops,
    prediction_ops,
    stage_ops,
    worst_case_prediction_ops,
)
from monopic.variants.path import project_path
from monopic.variants.warning import CollisionWarning
from sim.scenario.spec import CameraSpec

PAPER_TREE_MS = 8.0
HORIZON = HORIZON_S
# (label, predictors, with robot state): the paper's image-mode predictors alone, then
# the set every simulator run evaluates side by side (sim/runs/runner.py PREDICTORS).
SETS = (
    ("rules, image (the reference cascade)", (("rules", Mode.IMAGE),), False),
    ("ID3 tree, image", (("tree", Mode.IMAGE),), False),
    (
        "runner set: rules, tree, const-vel image + rules, const-vel ground",
        (
            ("rules", Mode.IMAGE),
            ("tree", Mode.IMAGE),
            ("constant-velocity", Mode.IMAGE),
            ("rules", Mode.GROUND),
            ("constant-velocity", Mode.GROUND),
        ),
        True,
    ),
)


def record_poses(fs) -> list:
    """Our tracker's pose (or None) on every frame, trackers reset per sequence."""
    tracker = PoseTracker(TrackerConfig(threads=1))
    poses = []
    for i in range(len(fs)):
        if i == 0 or fs.sequence[i] != fs.sequence[i - 1]:
            tracker.reset()
        poses.append(tracker.process(np.array(fs.images[i])).pose)
    return poses


def replay(fs, poses, predictors, ego, size) -> dict[str, float]:
    """One pass of the stage after pose over all frames; seconds per part."""
    w, h = size
    warning = CollisionWarning()
    parts = {"features": 0.0, "predict": 0.0, "warning + path": 0.0}
    extractor = FeatureExtractor()
    clock = time.perf_counter
    for i, pose in enumerate(poses):
        if i == 0 or fs.sequence[i] != fs.sequence[i - 1]:
            extractor = FeatureExtractor()
        t0 = clock()
        feats = extractor.update(float(fs.timestamp[i]), pose, h, ego)
        t1 = clock()
        parts["features"] += t1 - t0
        if feats is None:
            continue
        for p in predictors:
            if p.mode is Mode.GROUND and feats.ground is None:
                continue
            t1 = clock()
            pred = p.predict(feats, HORIZON)
            t2 = clock()
            wn = warning.assess(feats, pred, p.mode, (w, h), ego)
            project_path(feats, pred, wn.zone)
            t3 = clock()
            parts["predict"] += t2 - t1
            parts["warning + path"] += t3 - t2
    return parts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=30, help="timed passes per predictor set")
    ap.add_argument(
        "--intent-tree", type=Path, help="a ground intent tree: also time the runner set with it"
    )
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    recorder = Recorder("post_pose", "Stage after pose: time and operation count")
    sets_to_run = [
        (label, [make_predictor(name, mode) for name, mode in names], names, with_ego)
        for label, names, with_ego in SETS
    ]
    if args.intent_tree is not None:
        label, names, with_ego = SETS[-1]
        intent = make_predictor("intent-tree", Mode.GROUND, args.intent_tree)
        sets_to_run.append(
            (
                "runner set + intent tree, ground",
                [*(make_predictor(name, mode) for name, mode in names), intent],
                (*names, ("intent-tree", Mode.GROUND)),
                True,
            )
        )
    npy, npz = build()
    fs = load(npy, npz)
    n = len(fs)
    h, w = fs.images.shape[1:3]
    poses = record_poses(fs)
    found = sum(p is not None for p in poses)
    camera = CameraSpec(width=w, height=h).model()
    ego_still = EgoState(camera, 0.0, 0.0)

    lines = [
        f"{n} frames ({found} with a pose; poses recorded once by our tracker) of the "
        f"benchmark frame set, {args.repeats} timed passes after 3 warm-up passes; "
        "time per frame = per-pass sum / frames, median over passes (and the spread "
        "between the fastest and slowest pass). Paper: 8 ms for the tree stage on an "
        "i5-7200U.",
        "",
        "| stage after pose | features | predict | warning + path | total per frame "
        "| pass spread | vs paper's 8 ms |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    sets: list[dict[str, Any]] = []
    for label, predictors, names, with_ego in sets_to_run:
        ego = ego_still if with_ego else None
        for _ in range(3):
            replay(fs, poses, predictors, ego, (w, h))
        passes = [replay(fs, poses, predictors, ego, (w, h)) for _ in range(args.repeats)]
        per = {k: float(np.median([p[k] for p in passes])) * 1e6 / n for k in passes[0]}
        totals = [sum(p.values()) * 1e6 / n for p in passes]
        total = float(np.median(totals))
        spread = (max(totals) - min(totals)) / total
        sets.append(
            {
                "set": label,
                "predictors": [f"{name}/{mode.value}" for name, mode in names],
                "features_us": per["features"],
                "predict_us": per["predict"],
                "warning_path_us": per["warning + path"],
                "total_us": total,
                "pass_spread_pct": 100 * spread,
                "faster_than_paper_x": PAPER_TREE_MS * 1e3 / total,
            }
        )
        lines.append(
            f"| {label} | {per['features']:.1f} µs | {per['predict']:.1f} µs "
            f"| {per['warning + path']:.1f} µs | {total:.1f} µs | {100 * spread:.0f} % "
            f"| {PAPER_TREE_MS * 1e3 / total:.0f}x faster |"
        )

    tree = make_predictor("tree", Mode.IMAGE)
    assert isinstance(tree, TreePredictor)
    feats = recorded_features(fs, poses, h)
    worst = worst_case_prediction_ops(tree)
    mean, lo, hi = mean_prediction_ops(tree, feats, HORIZON)
    stage_mean = float(
        np.mean([stage_ops(prediction_ops(tree, f, HORIZON)).total.total for f in feats])
    )
    stage_worst = stage_ops(worst).total
    lines += [
        "",
        f"Operation counts of the ID3 tree in image mode (monopic/tree/opcount.py; paper: "
        f"{PAPER_CALCULATIONS_PER_PREDICTION} calculations per prediction):",
        "",
        "| count | one prediction (bins + tree + placement) | whole stage after pose |",
        "| --- | ---: | ---: |",
        f"| worst case over inputs | {worst.total.describe()} | {stage_worst.describe()} |",
        f"| mean over the {len(feats)} recorded frames (min-max) | {mean:.1f} ({lo}-{hi}) "
        f"| {stage_mean:.1f} |",
    ]
    intent_ops = None
    if args.intent_tree is not None:
        intent_ops = _intent_ops(intent, poses, fs, h, ego_still)
        lines += [
            "",
            f"Operation counts of the ground intent tree `{args.intent_tree}` (the same "
            "counting: bins, one test per node visited, placement and rules):",
            "",
            "| count | one prediction |",
            "| --- | ---: |",
            f"| worst case over inputs | {intent_ops['worst']} |",
            f"| mean over the {intent_ops['frames']} recorded frames with a ground point "
            f"(min-max) | {intent_ops['mean']:.1f} ({intent_ops['min']}-{intent_ops['max']}) |",
        ]
    table = "\n".join(lines)
    print(table)
    results = {
        "frames": n,
        "frames_with_pose": found,
        "repeats": args.repeats,
        "paper_tree_ms": PAPER_TREE_MS,
        "sets": sets,
        "tree_ops": {
            "paper_calculations": PAPER_CALCULATIONS_PER_PREDICTION,
            "worst_prediction": worst.total.total,
            "worst_prediction_by_kind": asdict(worst.total),
            "worst_stage": stage_worst.total,
            "worst_stage_by_kind": asdict(stage_worst),
            "mean_prediction": mean,
            "min_prediction": lo,
            "max_prediction": hi,
            "mean_stage": stage_mean,
            "recorded_frames": len(feats),
        },
        "intent_tree": None
        if intent_ops is None
        else {"file": str(args.intent_tree), **intent_ops},
    }
    recorder.finish(results, table, write=not args.no_append)


def recorded_features(fs, poses: list, h: int, ego: EgoState | None = None) -> list:
    """The feature record of every frame with one, a fresh extractor per sequence."""
    feats = []
    extractor = FeatureExtractor()
    for i, pose in enumerate(poses):
        if i == 0 or fs.sequence[i] != fs.sequence[i - 1]:
            extractor = FeatureExtractor()
        f = extractor.update(float(fs.timestamp[i]), pose, h, ego)
        if f is not None:
            feats.append(f)
    return feats


def _intent_ops(intent: Any, poses: list, fs: Any, h: int, ego: EgoState) -> dict[str, Any]:
    """Worst-case and recorded-frame operation counts of a ground intent tree."""
    from monopic.tree.intent import worst_case_ops

    counts = [
        intent.decide(f, HORIZON).ops.total
        for f in recorded_features(fs, poses, h, ego)
        if f.ground is not None
    ]
    return {
        "worst": worst_case_ops(intent.model).total,
        "mean": float(np.mean(counts)) if counts else float("nan"),
        "min": min(counts, default=0),
        "max": max(counts, default=0),
        "frames": len(counts),
    }


if __name__ == "__main__":
    main()
