"""Where the landmark model's time goes on this CPU, and how far it is from the limit.

Four parts, all in one process so that machine load hits every figure alike:

1. Multiply-accumulates per frame of each landmark model (lite, full, heavy), read from
   onnxruntime's own profile of a run with only basic graph optimisations (no fusion, no
   NCHWc layout: the true, unpadded tensor shapes of every Conv: output elements x input
   channels per group x kernel).
2. A per-operator profile of each model as the pipeline runs it (onnxruntime's profiler,
   shipped session options): time by kind of operator (pointwise, depthwise and dense
   convolutions, layout reorders, resize, add, ...), with the rate each kind reaches, and
   which kernels and layouts onnxruntime picked (convolutions in the blocked NCHWc layout,
   activations fused into them, reorders between layouts).
3. The shipped session beside variants, alternated round by round (A B C ... C B A):
   without the NCHWc layout (graph optimisation level "extended"), and as an ORT-format
   model holding the already optimised graph (`session.save_model_format` ORT); extra
   ONNX files given with --candidate join the comparison (an int8 model, say).
4. The limit: the rate this core reaches on a dense 3x3 convolution (bench/data,
   written by tools/models/dense_conv.py: 256 -> 256 channels at 32x32, float32 and
   int8), timed in the same rounds, and the whole pipeline per tracked frame on the
   shipped clip. The bound is MACs / dense rate; the tables give the landmark model's
   and the pipeline's time as a multiple of it.

Every figure is a median over rounds at the load printed with it (this VM is shared).

    .venv/bin/python -m bench.landmark_profile [--threads 1 2] [--rounds 15]
        [--candidate FILE.onnx ...] [--no-append]
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import onnxruntime as ort

from bench.recorder import Recorder
from monopic.pose.sessions import LANDMARK_MODELS, make_session, model_path

HERE = Path(__file__).resolve().parent

ROOT = HERE.parent
DENSE = {
    "fp32": HERE / "data" / "dense_conv_fp32.onnx",
    "int8": HERE / "data" / "dense_conv_int8.onnx",
}
DENSE_SHAPE = (1, 256, 32, 32)
DENSE_MACS = 256 * 256 * 9 * 32 * 32
CLIP = ROOT / "tests" / "data" / "walk_clip.mp4"
FIXTURE = ROOT / "tests" / "data" / "pose_reference.npz"
TITLE = "Landmark model: per-operator profile, variants, MACs and the dense-convolution bound"
CALLS_PER_ROUND = 8


def landmark_input() -> np.ndarray:
    """A real crop (the fixture's person, 256x256) as the model sees it."""
    with np.load(FIXTURE) as data:
        u8 = data["pose_landmark_full.input"][0]
    return (u8.astype(np.float32) / 255.0)[None]


def profiled(path: Path, opts: ort.SessionOptions, feed: dict[str, np.ndarray], runs: int) -> list:
    """onnxruntime's profile events of `runs` runs after 3 warm-up runs."""
    with tempfile.TemporaryDirectory() as tmp:
        opts.enable_profiling = True
        opts.profile_file_prefix = str(Path(tmp) / "prof")
        sess = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
        for _ in range(3 + runs):
            sess.run(None, feed)
        events = json.loads(Path(sess.end_profiling()).read_text())
    return [e for e in events if e.get("cat") == "Node" and e["name"].endswith("_kernel_time")]


def _shapes(arg: list[dict[str, list[int]]]) -> list[list[int]]:
    return [next(iter(d.values())) for d in arg]


def conv_kind(weight: list[int]) -> str:
    """pointwise (1x1), depthwise (one input channel per group) or dense kxk."""
    if weight[2] == weight[3] == 1:
        return "pointwise conv"
    if weight[1] == 1:
        return "depthwise conv"
    return f"dense {weight[2]}x{weight[3]} conv"


def conv_macs(args: dict[str, Any]) -> int:
    out = _shapes(args["output_type_shape"])[0]
    w = _shapes(args["input_type_shape"])[1]
    return int(np.prod(out)) * w[1] * w[2] * w[3]


def macs_per_frame(path: Path) -> tuple[int, dict[str, int]]:
    """Conv MACs from a profile of the unfused graph (plain NCHW, unpadded shapes), by kind."""
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = 1
    opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_BASIC
    events = profiled(path, opts, {"image": landmark_input()}, 1)
    first = {}
    for e in events:
        first.setdefault(e["name"], e)
    by_kind: dict[str, int] = collections.Counter()
    for e in first.values():
        if e["args"]["op_name"] == "Conv":
            by_kind[conv_kind(_shapes(e["args"]["input_type_shape"])[1])] += conv_macs(e["args"])
    return sum(by_kind.values()), dict(by_kind)


@dataclass
class Profile:
    rows: list[dict[str, Any]]  # by kind: ms per run, share, MACs, GMAC/s, nodes
    convs: int
    nchwc_convs: int
    fused_activations: int
    reorders: int
    total_ms: float


def op_profile(path: Path, threads: int, runs: int) -> Profile:
    """Median kernel time per node over `runs` runs, grouped by kind (shipped options)."""
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = threads
    opts.inter_op_num_threads = 1
    events = profiled(path, opts, {"image": landmark_input()}, runs)
    durs: dict[str, list[float]] = collections.defaultdict(list)
    args: dict[str, dict[str, Any]] = {}
    for e in events:
        durs[e["name"]].append(e["dur"])
        args[e["name"]] = e["args"]
    agg: dict[str, list[float]] = collections.defaultdict(lambda: [0.0, 0.0, 0.0])
    convs = nchwc = fused = reorders = 0
    for name, d in durs.items():
        a = args[name]
        op = a["op_name"]
        node = name.removesuffix("_kernel_time")
        if op == "Conv":
            w = _shapes(a["input_type_shape"])[1]
            kind, macs = conv_kind(w), conv_macs(a)
            if len(a["input_type_shape"]) > 3:
                kind += " + residual add"  # NCHWc fuses the Add of a residual into the conv
            convs += 1
            nchwc += node.endswith("_nchwc")
            fused += not node.startswith("Conv_")  # took the fused activation's / Add's name
        else:
            kind, macs = op, 0.0
            reorders += op in ("ReorderInput", "ReorderOutput")
        agg[kind][0] += float(np.median(d)) / 1e3
        agg[kind][1] += macs
        agg[kind][2] += 1
    total = sum(v[0] for v in agg.values())
    rows = [
        {
            "kind": k,
            "nodes": int(n),
            "ms": ms,
            "share_pct": 100 * ms / total,
            "macs": int(macs),
            "gmac_per_s": macs / ms / 1e6 if macs else None,
        }
        for k, (ms, macs, n) in sorted(agg.items(), key=lambda kv: -kv[1][0])
    ]
    return Profile(rows, convs, nchwc, fused, reorders, total)


def variants(full: Path, threads: int, candidates: list[Path], work: Path) -> dict[str, Any]:
    """Sessions to alternate: shipped, spinning, no NCHWc, ORT format, and the candidates."""
    out: dict[str, Any] = {"shipped": make_session(full, threads, spin=False)}
    if threads > 1:
        # They spin within a run only (TrackerConfig.spin); the history's older lines under
        # "spinning intra-op threads" measured threads that also spun between runs.
        out["threads spinning within runs"] = make_session(full, threads, spin=True)
    ext = ort.SessionOptions()
    ext.intra_op_num_threads = threads
    ext.inter_op_num_threads = 1
    ext.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_EXTENDED
    out["no NCHWc (optimisation level extended)"] = ort.InferenceSession(
        str(full), ext, providers=["CPUExecutionProvider"]
    )
    ort_file = work / f"landmark_full_t{threads}.ort"
    save = ort.SessionOptions()
    save.optimized_model_filepath = str(ort_file)
    save.add_session_config_entry("session.save_model_format", "ORT")
    ort.InferenceSession(str(full), save, providers=["CPUExecutionProvider"])
    out["ORT format (optimised graph saved)"] = make_session(ort_file, threads, spin=False)
    for path in candidates:
        out[path.name] = make_session(path, threads, spin=False)
    return out


def timed(fn: Any, feed: dict[str, np.ndarray], calls: int) -> float:
    """Median ms of `calls` calls."""
    t = []
    for _ in range(calls):
        t0 = time.perf_counter()
        fn(None, feed)
        t.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(t))


def clip_frames() -> list[Any]:
    from monopic.video import VideoSource

    return list(VideoSource(str(CLIP)))


def pipeline_pass(frames: list[Any], threads: int) -> list[float]:
    """ms per frame of the whole pipeline over the clip, tracked frames only."""
    from monopic.pipeline import Pipeline, PipelineConfig
    from monopic.pose.tracker import TrackerConfig

    pipeline = Pipeline(PipelineConfig(tracker=TrackerConfig(threads=threads)))
    out = []
    for frame in frames:
        t0 = time.perf_counter()
        r = pipeline.process(frame)
        ms = 1e3 * (time.perf_counter() - t0)
        if r.pose.found and r.pose.detector_runs == 0:
            out.append(ms)
    return out


def measure(threads: int, rounds: int, candidates: list[Path], frames: list[Any]) -> dict[str, Any]:
    """Alternated rounds: every variant, both dense convs and one pipeline pass per round."""
    feed = {"image": landmark_input()}
    dense_x = {"x": np.random.default_rng(0).random(DENSE_SHAPE, dtype=np.float32)}
    with tempfile.TemporaryDirectory() as tmp:
        sessions = variants(model_path(LANDMARK_MODELS["full"]), threads, candidates, Path(tmp))
        dense = {k: make_session(p, threads, spin=False) for k, p in DENSE.items()}
        items: list[tuple[str, Any, dict[str, np.ndarray]]] = [
            *((k, s.run, feed) for k, s in sessions.items()),
            *((f"dense 3x3 conv {k}", s.run, dense_x) for k, s in dense.items()),
        ]
        for _, fn, x in items:
            timed(fn, x, 5)  # warm-up
        pipeline_pass(frames[:10], threads)
        samples: dict[str, list[float]] = {k: [] for k, _, _ in items}
        pipeline_ms: list[float] = []
        loads = []
        for r in range(rounds):
            loads.append(os.getloadavg()[0])
            for name, fn, x in items if r % 2 == 0 else items[::-1]:
                samples[name].append(timed(fn, x, CALLS_PER_ROUND))
            if r % 3 == 0:
                pipeline_ms += pipeline_pass(frames, threads)
    return {
        "ms": {k: float(np.median(v)) for k, v in samples.items()},
        "p10_ms": {k: float(np.percentile(v, 10)) for k, v in samples.items()},
        "pipeline_p50_ms": float(np.median(pipeline_ms)),
        "pipeline_frames": len(pipeline_ms),
        "load_min": min(loads),
        "load_max": max(loads),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--profile-runs", type=int, default=30)
    ap.add_argument("--candidate", type=Path, nargs="*", default=[], help="more .onnx to time")
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    for path in args.candidate:
        if not path.is_file():
            raise SystemExit(f"landmark_profile: --candidate {path}: no such file")
    recorder = Recorder("landmark_profile", TITLE)
    start = time.perf_counter()
    lines: list[str] = []
    results: dict[str, Any] = {"models": [], "profile": [], "threads": []}

    # 1 + 2: MACs and per-operator profiles, one thread (the kernels, not the pool).
    macs: dict[str, int] = {}
    profiles: dict[str, Profile] = {}
    for name, file in LANDMARK_MODELS.items():
        path = model_path(file)
        macs[name], by_kind = macs_per_frame(path)
        profiles[name] = op_profile(path, 1, args.profile_runs)
        p = profiles[name]
        results["models"].append(
            {
                "model": name,
                "file": file,
                "macs": macs[name],
                "macs_by_kind": by_kind,
                "convs": p.convs,
                "nchwc_convs": p.nchwc_convs,
                "fused_activations": p.fused_activations,
                "reorders": p.reorders,
                "kernel_ms_1_thread": p.total_ms,
            }
        )
        for row in p.rows:
            results["profile"].append({"model": name, "threads": 1, **row})
    lines += [
        f"Landmark models (onnxruntime {ort.__version__}, CPU execution provider; input "
        "1x256x256x3, every shape fixed): multiply-accumulates per frame of the convolutions "
        "(unpadded shapes), and the kernels onnxruntime picks with the shipped options "
        "(graph optimisation level all: NCHWc layout).",
        "",
        "| model | MMAC per frame | pointwise | depthwise | dense | convs | in NCHWc | "
        "activation or add fused | layout reorders | kernel time, 1 thread |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for row in results["models"]:
        k = row["macs_by_kind"]
        dense = sum(v for kk, v in k.items() if kk.startswith("dense"))
        lines.append(
            f"| {row['model']} | {row['macs'] / 1e6:.0f} | {k.get('pointwise conv', 0) / 1e6:.0f} "
            f"| {k.get('depthwise conv', 0) / 1e6:.0f} | {dense / 1e6:.1f} | {row['convs']} "
            f"| {row['nchwc_convs']} | {row['fused_activations']} | {row['reorders']} "
            f"| {row['kernel_ms_1_thread']:.2f} ms |"
        )
    lines += [
        "",
        f"Per-operator profile of the full model, 1 thread (median kernel time of each node "
        f"over {args.profile_runs} runs, summed by kind; MACs with NCHWc's padded channels):",
        "",
        "| operator | nodes | ms per run | share | MMAC | GMAC/s |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for row in profiles["full"].rows:
        rate = "" if row["gmac_per_s"] is None else f"{row['gmac_per_s']:.1f}"
        lines.append(
            f"| {row['kind']} | {row['nodes']} | {row['ms']:.3f} | {row['share_pct']:.1f} % "
            f"| {row['macs'] / 1e6:.1f} | {rate} |"
        )

    for path in args.candidate:  # e.g. an int8 model: which kernels it runs, and how long
        p = op_profile(path, 1, args.profile_runs)
        results["profile"] += [{"model": path.name, "threads": 1, **row} for row in p.rows]
        lines += [
            "",
            f"Per-operator profile of `{path.name}`, 1 thread ({p.total_ms:.2f} ms kernel "
            f"time per run against {profiles['full'].total_ms:.2f} ms for the full model "
            "in the same minutes; quantised kernels take prepacked weights, so no MACs):",
            "",
            "| operator | nodes | ms per run | share |",
            "| --- | ---: | ---: | ---: |",
            *(
                f"| {row['kind']} | {row['nodes']} | {row['ms']:.3f} | {row['share_pct']:.1f} % |"
                for row in p.rows
            ),
        ]

    # 3 + 4: variants, the dense-conv rate and the pipeline, alternated.
    frames = clip_frames()
    lines += [
        "",
        f"Alternated rounds ({args.rounds} per thread count, {CALLS_PER_ROUND} calls of each "
        "per round, median of the round medians; the pipeline: every tracked frame of the "
        "shipped clip, one pass every third round). Bound = MACs / dense 3x3 rate.",
        "",
        "| threads | load | session | ms per run | vs shipped |",
        "| --- | --- | --- | ---: | ---: |",
    ]
    limits = []
    for t in args.threads:
        m = measure(t, args.rounds, args.candidate, frames)
        base = m["ms"]["shipped"]
        load = f"{m['load_min']:.1f}-{m['load_max']:.1f}"
        for name, ms in m["ms"].items():
            ratio = f"{ms / base:.2f}" if not name.startswith("dense") else "-"
            lines.append(f"| {t} | {load} | {name} | {ms:.2f} | {ratio} |")
        pipe = m["pipeline_p50_ms"]
        lines.append(f"| {t} | {load} | whole pipeline, tracked frame | {pipe:.2f} | - |")
        fp32 = DENSE_MACS / m["ms"]["dense 3x3 conv fp32"] / 1e6  # GMAC/s
        int8 = DENSE_MACS / m["ms"]["dense 3x3 conv int8"] / 1e6
        bound = macs["full"] / fp32 / 1e6  # ms
        limits.append(
            {
                "threads": t,
                "dense_fp32_gmac_per_s": fp32,
                "dense_int8_gmac_per_s": int8,
                "bound_fp32_ms": bound,
                "bound_int8_ms": macs["full"] / int8 / 1e6,
                "landmark_ms": base,
                "pipeline_ms": m["pipeline_p50_ms"],
                "landmark_x_bound": base / bound,
                "pipeline_x_bound": m["pipeline_p50_ms"] / bound,
                "load_min": m["load_min"],
                "load_max": m["load_max"],
            }
        )
        results["threads"].append({"threads": t, **m})
    results["limit"] = limits
    lines += [
        "",
        f"The limit for the full model ({macs['full'] / 1e6:.0f} MMAC per frame): the dense "
        "3x3 convolution's rate on this core, the time the model's MACs would take at that "
        "rate, and our time as a multiple of it (1.0 = at the bound).",
        "",
        "| threads | dense fp32 | dense int8 | bound fp32 | landmark model | x bound "
        "| whole pipeline | x bound | bound int8 |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in limits:
        lines.append(
            f"| {r['threads']} | {r['dense_fp32_gmac_per_s']:.0f} GMAC/s "
            f"| {r['dense_int8_gmac_per_s']:.0f} GMAC/s | {r['bound_fp32_ms']:.2f} ms "
            f"| {r['landmark_ms']:.2f} ms | {r['landmark_x_bound']:.1f} "
            f"| {r['pipeline_ms']:.2f} ms | {r['pipeline_x_bound']:.1f} "
            f"| {r['bound_int8_ms']:.2f} ms |"
        )
    lines.append("")
    lines.append(f"{time.perf_counter() - start:.0f} s in all.")
    table = "\n".join(lines)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
