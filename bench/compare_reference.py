"""Our pipeline against the paper's reference (MediaPipe 0.10.14 Pose + the authors' cascade).

Same frames (bench/frameset.py: the shipped clip and rendered cases at 3, 6 and 10 m,
768x432), same thread count (onnxruntime intra-op threads for ours, XNNPACK threads for
MediaPipe's, each process also pinned to that many cores), runs alternated in ABBA order
(ours, ref, ref, ours, ...) so drifting machine load hits both alike. Every run is a fresh
worker process that warms up on the first frames and then times one pass over all of
them. Reported: per-frame latency per stage (p50/p95) with the ratio ours/reference, on
all frames and on the frames where both found the pedestrian (the same work); landmark
error against the ground truth on the frames both found; CPU-seconds per frame and per
hour at 15 fps (process CPU time of the timed pass: the energy proxy). The results go to
bench/history.jsonl as one line (bench/history.py) unless --no-append.

With --people a third side runs between the two: ours following everyone in view
(`people`: PipelineConfig(people=PeopleConfig()), the same options otherwise), so the
one-pedestrian tracker's and everyone's ratios to the reference come from the same
minutes (order ours, people, ref, ref, people, ours, ...); "both found" is then the frames
all three found, and the landmark error's paired interval stays ours against the reference.

    .venv/bin/python -m bench.compare_reference [--rounds 2] [--threads 1 2] [--no-append]
        [--model full|full-int8] [--detector float|int8] [--window-detector float|int8]
        [--spin] [--search tiles|whole-frame] [--people]

The CPU-time goals are judged on the fastest choices, `--rounds 5 --model full-int8 --spin
--window-detector int8` (`make bench` runs both; docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bench.frameset import FrameSet, build, load
from bench.goals import RATIO_GOAL
from bench.paired import paired_median_difference
from bench.recorder import Recorder
from bench.reference_env import ensure

HERE = Path(__file__).resolve().parent

ROOT = HERE.parent
OURS, PEOPLE, REF = "ours", "people", "reference"
SHOULDERS, HIPS = (11, 12), (23, 24)
FPS = 15.0
TITLE = "Ours vs the reference pipeline (MediaPipe 0.10.14 + rule cascade)"
Row = dict[str, Any]  # one row of a results table in the history line


@dataclass
class Run:
    """One worker process's output: per-frame rows and its summary."""

    side: str
    threads: int
    rows: list[dict]
    summary: dict
    load_before: float
    load_after: float


@dataclass
class Collected:
    runs: list[Run] = field(default_factory=list)

    def of(self, side: str, threads: int) -> list[Run]:
        return [r for r in self.runs if r.side == side and r.threads == threads]

    def sides(self) -> list[str]:
        return [x for x in (OURS, PEOPLE, REF) if any(r.side == x for r in self.runs)]


def worker_command(side: str, ref_python: Path) -> tuple[list[str], dict[str, str]]:
    """A worker as a module run from the top folder (run_worker's cwd), so that the
    reference venv, which has not installed the project, imports bench and monopic's
    pure-Python modules from the checkout."""
    if side == OURS:
        return [sys.executable, "-m", "bench.pipeline_worker"], {}
    if side == PEOPLE:
        return [sys.executable, "-m", "bench.pipeline_worker", "--people"], {}
    return [str(ref_python), "-m", "bench.reference_worker"], {"GLOG_minloglevel": "2"}


def run_worker(
    side: str,
    frames: Path,
    threads: int,
    warmup: int,
    ref_python: Path,
    pin: bool,
    model: str = "full",
    runtime: str = "cpu",
    detector: str = "float",
    spin: bool = False,
    search: str = "tiles",
    window_detector: str | None = None,
) -> Run:
    cmd, extra_env = worker_command(side, ref_python)
    cmd += ["--frames", str(frames), "--threads", str(threads), "--warmup", str(warmup)]
    # The reference runs MediaPipe's float model of the same complexity: full-int8 is a
    # quantisation of its full model.
    cmd += ["--model", model if side != REF else model.removesuffix("-int8")]
    if side != REF:  # the reference runs MediaPipe's own (float) detector
        cmd += ["--runtime", runtime, "--detector", detector, "--search", search]
        if window_detector is not None:
            cmd += ["--window-detector", window_detector]
        cmd += ["--spin"] * spin
    if pin:
        cmd.append("--pin")
    env = dict(os.environ, **extra_env)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[var] = str(threads)
    env.pop("PYTHONPATH", None)
    load_before = os.getloadavg()[0]
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr[-3000:]}")
    lines = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    rows = [ln for ln in lines if "i" in ln]
    summary = next(ln["summary"] for ln in lines if "summary" in ln)
    return Run(side, threads, rows, summary, load_before, os.getloadavg()[0])


def pct(values: list[float] | np.ndarray, q: float) -> float:
    a = np.asarray(values, dtype=float)
    return float(np.percentile(a, q)) if a.size else float("nan")


def landmark_errors(fs: FrameSet, run: Run, frames: np.ndarray) -> dict[str, list[np.ndarray]]:
    """Pixel errors against the truth on `frames` (indices), by landmark group, one array
    per frame (empty where the side found nobody or the group is not visible)."""
    out: dict[str, list[np.ndarray]] = {"shoulders": [], "hips": [], "all visible": []}
    by_i = {r["i"]: r for r in run.rows}
    for i in frames:
        lm = by_i[int(i)]["lm"]
        vis = fs.visible[i]
        if lm is None:
            d, vis = np.zeros(len(vis)), np.zeros(len(vis), dtype=bool)
        else:
            d = np.linalg.norm(np.asarray(lm) - fs.landmarks[i], axis=1)
        out["shoulders"].append(np.array([d[k] for k in SHOULDERS if vis[k]]))
        out["hips"].append(np.array([d[k] for k in HIPS if vis[k]]))
        out["all visible"].append(d[vis])
    return out


def pooled_median(per_frame: list[np.ndarray]) -> float:
    return pct(np.concatenate(per_frame) if per_frame else np.array([]), 50)


def found_mask(run: Run, n: int) -> np.ndarray:
    m = np.zeros(n, dtype=bool)
    for r in run.rows:
        m[r["i"]] = r["lm"] is not None
    return m


def fmt(v: float, unit: str = "") -> str:
    return "-" if not np.isfinite(v) else f"{v:.2f}{unit}"


def latency_table(
    col: Collected, threads: list[int], both: np.ndarray, rows: list[Row]
) -> list[str]:
    """p50/p95 per stage and side for each thread count; ratios are side / reference.

    Appends one row per (threads, frames, stage, side) to `rows`.
    """
    sides = col.sides()
    ours = [x for x in sides if x != REF]
    head = " | ".join(f"{x} p50 | {x} p95" for x in sides)
    ratios = " | ".join(f"{x}/ref p50 | {x}/ref p95" for x in ours)
    lines = [
        f"| threads | frames | stage | {head} | {ratios} |",
        "| --- | --- | --- |" + " ---: |" * (2 * len(sides) + 2 * len(ours)),
    ]
    for t in threads:
        for label, mask in (("all", None), ("both found", both)):
            # On frames where nobody is found there is no stage after pose to compare.
            for stage in ("total", "pose") if mask is None else ("total", "pose", "post"):
                p: dict[str, tuple[float, float]] = {}
                for side in sides:
                    v = [
                        r["ms"] if stage == "total" else r["stages"][stage]
                        for run in col.of(side, t)
                        for r in run.rows
                        if mask is None or mask[r["i"]]
                    ]
                    p[side] = (pct(v, 50), pct(v, 95))
                name = {"total": "whole frame", "pose": "pose", "post": "after pose"}[stage]
                for x in sides:
                    rows.append(
                        {
                            "threads": t,
                            "frames": label,
                            "stage": name,
                            "side": x,
                            "p50_ms": p[x][0],
                            "p95_ms": p[x][1],
                            "ratio_p50_x": None if x == REF else p[x][0] / p[REF][0],
                            "ratio_p95_x": None if x == REF else p[x][1] / p[REF][1],
                        }
                    )
                cells = " | ".join(f"{p[x][0]:.2f} ms | {p[x][1]:.2f} ms" for x in sides)
                rat = " | ".join(
                    f"{p[x][0] / p[REF][0]:.2f} | {p[x][1] / p[REF][1]:.2f}" for x in ours
                )
                lines.append(f"| {t} | {label} | {name} | {cells} | {rat} |")
    return lines


def detail_table(col: Collected, threads: list[int], rows: list[Row]) -> list[str]:
    """Our pose stage split: detector (frames that ran it) and landmark model."""
    lines = [
        "| threads | stage | frames per run | p50 | p95 |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for t in threads:
        for side in (x for x in col.sides() if x != REF):
            runs = col.of(side, t)
            det = [
                r["stages"]["detect"]
                for run in runs
                for r in run.rows
                if r["stages"]["detector_runs"] > 0
            ]
            lmk = [r["stages"]["landmarks"] for run in runs for r in run.rows]
            rounds = max(1, len(runs))
            for name, v in (("detect (acquiring frames)", det), ("landmark model", lmk)):
                rows.append(
                    {
                        "threads": t,
                        "side": side,
                        "stage": name,
                        "frames_per_run": len(v) // rounds,
                        "p50_ms": pct(v, 50),
                        "p95_ms": pct(v, 95),
                    }
                )
                lines.append(
                    f"| {t} | {side}: {name} | {len(v) // rounds} | {pct(v, 50):.2f} ms "
                    f"| {pct(v, 95):.2f} ms |"
                )
    return lines


def agreement_table(col: Collected, threads: list[int], rows: list[Row]) -> tuple[list[str], float]:
    """Median whole-frame latency of every run, and the worst spread between runs."""
    lines = [
        "| threads | side | per-run p50 (ms) | spread |",
        "| --- | --- | --- | ---: |",
    ]
    worst = 0.0
    for t in threads:
        for side in col.sides():
            meds = [pct([r["ms"] for r in run.rows], 50) for run in col.of(side, t)]
            spread = (max(meds) - min(meds)) / float(np.median(meds)) if len(meds) > 1 else 0.0
            worst = max(worst, spread)
            rows.append({"threads": t, "side": side, "p50_ms": meds, "spread_pct": 100 * spread})
            lines.append(
                f"| {t} | {side} | {', '.join(f'{m:.2f}' for m in meds)} | {100 * spread:.0f} % |"
            )
    return lines, worst


def both_found(col: Collected, t: int, n: int) -> np.ndarray:
    """Frames every side's first run at `t` threads returned a pose on: the same work."""
    return np.logical_and.reduce([found_mask(col.of(side, t)[0], n) for side in col.sides()])


def cpu_table(col: Collected, threads: list[int], n: int, rows: list[Row]) -> list[str]:
    """Process CPU time per frame over the whole pass (the energy proxy), and per frame on
    the frames both sides found (the same work: it leaves out our tile search for
    pedestrians the reference never finds, and the reference's detector-only frames)."""
    lines = [
        "| threads | side | CPU-s per frame | CPU-s per frame, both found | wall s per frame "
        "| CPU-s per hour at 15 fps | cores busy at 15 fps | OS threads | peak RSS |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for t in threads:
        both = both_found(col, t, n)
        for side in col.sides():
            runs = col.of(side, t)
            cpu = float(np.median([r.summary["cpu_s"] / r.summary["frames"] for r in runs]))
            cpu_both = float("nan")
            if both.any():
                same = [np.mean([r["cpu_ms"] for r in run.rows if both[r["i"]]]) for run in runs]
                cpu_both = float(np.median(same))
            wall = float(np.median([r.summary["wall_s"] / r.summary["frames"] for r in runs]))
            rss = max(r.summary["maxrss_mb"] for r in runs)
            threads_seen = max(r.summary["os_threads"] for r in runs)
            rows.append(
                {
                    "threads": t,
                    "side": side,
                    "cpu_ms_per_frame": 1e3 * cpu,
                    "cpu_ms_per_both_found_frame": cpu_both if both.any() else None,
                    "wall_ms_per_frame": 1e3 * wall,
                    "cpu_s_per_hour_at_15fps": cpu * FPS * 3600,
                    "cores_busy_at_15fps": cpu * FPS,
                    "os_threads": threads_seen,
                    "peak_rss_mb": rss,
                }
            )
            lines.append(
                f"| {t} | {side} | {1e3 * cpu:.1f} ms | {fmt(cpu_both, ' ms')} "
                f"| {1e3 * wall:.1f} ms "
                f"| {cpu * FPS * 3600:.0f} s | {cpu * FPS:.2f} | {threads_seen} | {rss:.0f} MB |"
            )
    return lines


def error_table(
    fs: FrameSet, col: Collected, t: int, rows: list[Row]
) -> tuple[list[str], list[str]]:
    """Landmark error by frame group on the frames every side found; found shares beside.

    Where both sides found the same frames, the difference ours - reference comes with a
    95 % block-bootstrap interval (bench/paired.py) and a verdict: better or worse only
    when the interval excludes zero. Returns the table and the groups where ours is worse;
    appends one row per (group, landmarks) to `rows` (verdict null where not judged).
    """
    sides = col.sides()
    runs = {x: col.of(x, t)[0] for x in sides}
    n = len(fs)
    found = {x: found_mask(r, n) for x, r in runs.items()}
    every = np.logical_and.reduce([found[x] for x in sides])
    in_frame = fs.visible.any(axis=1)
    groups = [("shipped clip (decoded mp4)", fs.sequence == 0)]
    for d in sorted({float(x) for x in fs.distance if np.isfinite(x)}):
        groups.append((f"rendered, {d:g} m", fs.distance == d))
    groups.append(("rendered, all", np.isfinite(fs.distance)))
    found_head = " | ".join(f"found {x}" for x in sides)
    err_head = " | ".join(f"median err {x}" for x in sides)
    lines = [
        f"| frames | n | {found_head} | all found | landmarks | {err_head} "
        f"| {OURS} - {REF} [95 % interval] | verdict |",
        "| --- | ---: |"
        + " ---: |" * len(sides)
        + " ---: | --- |"
        + " ---: |" * len(sides)
        + " ---: | --- |",
    ]
    worse: list[str] = []
    for name, g in groups:
        g = g & in_frame
        common = np.flatnonzero(g & every)
        if len(common):
            errs = {x: landmark_errors(fs, runs[x], common) for x in sides}
            shown = str(len(common))
        else:  # nobody in common: each side on its own finds, marked as such
            errs = {x: landmark_errors(fs, runs[x], np.flatnonzero(g & found[x])) for x in sides}
            shown = "0 (errors: own finds)"
        shares = " | ".join(f"{100 * found[x][g].mean():.0f} %" for x in sides)
        for k, key in enumerate(("shoulders", "hips", "all visible")):
            head = (
                f"| {name} | {int(g.sum())} | {shares} | {shown} "
                if k == 0
                else "| | |" + " |" * len(sides) + " "
            )
            cells = " | ".join(fmt(pooled_median(errs[x][key]), " px") for x in sides)
            paired, verdict = "-", "-"
            row: Row = {
                "group": name,
                "frames": int(g.sum()),
                "common_frames": len(common),
                "found_pct": {x: 100 * float(found[x][g].mean()) for x in sides},
                "landmarks": key,
                "median_error_px": {x: pooled_median(errs[x][key]) for x in sides},
                "difference_px": None,
                "low_px": None,
                "high_px": None,
                "verdict": None,
            }
            if len(common) and OURS in errs and REF in errs:
                diff = paired_median_difference(
                    errs[OURS][key], errs[REF][key], fs.sequence[common]
                )
                paired = f"{diff.difference:+.2f} [{diff.low:+.2f}, {diff.high:+.2f}] px"
                verdict = diff.verdict
                row |= {
                    "difference_px": diff.difference,
                    "low_px": diff.low,
                    "high_px": diff.high,
                    "verdict": verdict,
                }
                if verdict == "worse":
                    worse.append(f"{name} {key}")
            rows.append(row)
            lines.append(f"{head}| {key} | {cells} | {paired} | {verdict} |")
    return lines, worse


def people_table(
    col: Collected, threads: list[int], both: np.ndarray, rows: list[Row]
) -> list[str]:
    """Everyone's tracker against the one-pedestrian tracker, each to the reference from
    the same runs: p50 on frames all sides found (the goal's figure), p50 and p95 on all
    frames, and CPU-seconds per frame; `people/ours` is the change the people tracker
    brings to each ratio."""
    lines = [
        "| threads | figure | ours/ref | people/ref | people/ours |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for t in threads:
        figures: dict[str, dict[str, float]] = {}
        for side in (OURS, PEOPLE, REF):
            runs = col.of(side, t)
            found = [r["ms"] for run in runs for r in run.rows if both[r["i"]]]
            every = [r["ms"] for run in runs for r in run.rows]
            cpu = float(np.median([r.summary["cpu_s"] / r.summary["frames"] for r in runs]))
            figures[side] = {
                "p50, frames all found": pct(found, 50),
                "p50, all frames": pct(every, 50),
                "p95, all frames": pct(every, 95),
                "CPU-s per frame": cpu,
            }
        for name in figures[OURS]:
            ours, people, ref = (figures[x][name] for x in (OURS, PEOPLE, REF))
            rows.append(
                {
                    "threads": t,
                    "figure": name,
                    "ours_to_reference_x": ours / ref,
                    "people_to_reference_x": people / ref,
                    "people_to_ours_x": people / ours,
                }
            )
            lines.append(
                f"| {t} | {name} | {ours / ref:.2f} | {people / ref:.2f} | {people / ours:.2f} |"
            )
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=2, help="ABBA rounds per thread count")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--warmup", type=int, default=30)
    ap.add_argument("--no-pin", action="store_true", help="do not confine workers to N cores")
    ap.add_argument(
        "--runtime",
        choices=("cpu", "openvino"),
        default="cpu",
        help="our side's onnxruntime execution provider (monopic.pose.sessions.RUNTIMES)",
    )
    ap.add_argument(
        "--model",
        choices=("full", "full-int8"),
        default="full",
        help="our side's landmark model (the reference runs MediaPipe's full model); "
        "bench/model_choices.py compares lite and heavy",
    )
    ap.add_argument(
        "--detector",
        choices=("float", "int8"),
        default="float",
        help="our side's person detector (the reference runs MediaPipe's)",
    )
    ap.add_argument(
        "--window-detector",
        choices=("float", "int8"),
        default=None,
        help="our side's detector on the search's zooms and tiles, smaller than the frame "
        "(default: --detector's; the whole frame keeps --detector's)",
    )
    ap.add_argument(
        "--spin",
        action="store_true",
        help="our side's onnxruntime threads spin-wait within a run, as XNNPACK's "
        "pthreadpool does before it sleeps "
        "(monopic.pose.sessions.make_session)",
    )
    ap.add_argument(
        "--search",
        choices=("tiles", "whole-frame"),
        default="tiles",
        help="our side's search while no one is tracked: the tile cascade that finds far "
        "pedestrians (default), or the whole frame only, as the reference searches",
    )
    ap.add_argument(
        "--people",
        action="store_true",
        help="a third side: ours following everyone in view (PeopleConfig()), beside the "
        "one-pedestrian tracker, against the same reference runs",
    )
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    from monopic.pose.sessions import runtime_unavailable

    why_not = runtime_unavailable(args.runtime)  # e.g. openvino on an AMD CPU
    if why_not is not None:
        sys.exit(f"compare_reference: --runtime {args.runtime}: {why_not}")
    recorder = Recorder("compare_reference", TITLE)
    npy, npz = build()
    fs = load(npy, npz)
    ref_python = ensure()
    sides = (OURS, PEOPLE, REF) if args.people else (OURS, REF)
    col = Collected()
    start = time.perf_counter()
    loads = []
    for rnd in range(args.rounds):
        for t in args.threads:
            order = sides if rnd % 2 == 0 else sides[::-1]
            for side in order:
                run = run_worker(
                    side,
                    npy,
                    t,
                    args.warmup,
                    ref_python,
                    not args.no_pin,
                    model=args.model,
                    runtime=args.runtime,
                    detector=args.detector,
                    spin=args.spin,
                    search=args.search,
                    window_detector=args.window_detector,
                )
                loads += [run.load_before, run.load_after]
                col.runs.append(run)
                print(
                    f"round {rnd + 1} threads {t} {side}: "
                    f"{1e3 * run.summary['wall_s'] / run.summary['frames']:.1f} ms/frame",
                    file=sys.stderr,
                )
    n = len(fs)
    t0 = args.threads[0]
    both = both_found(col, t0, n)
    results: dict[str, Any] = {
        "frames": n,
        "width_px": int(fs.images.shape[2]),
        "height_px": int(fs.images.shape[1]),
        "sequences": fs.sequences,
        "sides": list(sides),
        "threads": args.threads,
        "rounds": args.rounds,
        "warmup_frames": args.warmup,
        "pinned": not args.no_pin,
        "runtime": args.runtime,
        "model": args.model,
        "detector": args.detector,
        "window_detector": args.window_detector,
        "spin": args.spin,
        "search": args.search,
        "people": args.people,
        "load_min": min(loads),
        "load_max": max(loads),
        "latency": [],
        "pose_split": [],
        "per_run": [],
        "cpu": [],
        "landmark_error_threads": t0,
        "landmark_error": [],
    }
    agree, worst = agreement_table(col, args.threads, results["per_run"])
    results["worst_spread_pct"] = 100 * worst
    # The goal: whole-frame p50 at most half the reference's on the same work.
    verdict = []
    for t in args.threads:
        f = pct([r["ms"] for run in col.of(REF, t) for r in run.rows if both[r["i"]]], 50)
        for side in (x for x in sides if x != REF):
            o = pct([r["ms"] for run in col.of(side, t) for r in run.rows if both[r["i"]]], 50)
            verdict.append(
                f"{t} thread{'s' if t > 1 else ''}, {side}/ref = {o / f:.2f} "
                f"({'meets' if o / f <= RATIO_GOAL else 'misses'} the <= {RATIO_GOAL} goal)"
            )
    errors, worse = error_table(fs, col, t0, results["landmark_error"])
    versus: list[str] = []
    if args.people:
        results["people_vs_ours"] = []
        versus = [
            "",
            "Everyone's tracker (people) against the one-pedestrian tracker (ours), each "
            "to the reference in the same runs (< 1: faster; people/ours > 1: the people "
            "tracker slower):",
            "",
            *people_table(col, args.threads, both, results["people_vs_ours"]),
        ]
    seqs = ", ".join(fs.sequences)
    lines = [
        f"{n} frames 768x432 in {len(fs.sequences)} sequences ({seqs}); "
        f"sides {', '.join(sides)} (ours on onnxruntime's {args.runtime} execution provider, "
        f"landmark model {args.model}, {args.detector} detector"
        f"{f' ({args.window_detector} on zooms and tiles)' if args.window_detector else ''}"
        f"{', threads spinning within runs' if args.spin else ''}"
        f"{', searching the whole frame only' if args.search == 'whole-frame' else ''}); "
        f"{args.rounds} ABBA rounds per thread count, {args.warmup} warm-up frames per run; "
        f"workers pinned to N cores: {not args.no_pin}; "
        f"load average during the runs {min(loads):.1f}-{max(loads):.1f} on "
        f"{os.cpu_count()} cores; {time.perf_counter() - start:.0f} s in all.",
        "",
        "Latency per frame (ratio < 1: faster than the reference; 'both found' = frames "
        "where every side returned a pose, i.e. the same work):",
        "",
        *latency_table(col, args.threads, both, results["latency"]),
        "",
        "Our pose stage split:",
        "",
        *detail_table(col, args.threads, results["pose_split"]),
        "",
        f"Run-to-run agreement of the whole-frame p50 (worst spread {100 * worst:.0f} %):",
        "",
        *agree,
        "",
        "Energy proxy (process CPU time of the timed pass; median over runs):",
        "",
        *cpu_table(col, args.threads, n, results["cpu"]),
        "",
        f"Landmark error vs ground truth, {t0} thread(s), frames all sides found (median over "
        "landmark instances; 'all visible' = the 33 mapped landmarks in the image and, "
        "on rendered frames, not occluded):",
        "",
        *errors,
        *versus,
        "",
        "Goal (whole frame p50 on frames all found): " + "; ".join(verdict) + ".",
        "Goal (landmark error equal or better, every group the interval can judge): "
        + ("met; worse in no group." if not worse else f"missed; worse in {', '.join(worse)}."),
    ]
    table = "\n".join(lines)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
