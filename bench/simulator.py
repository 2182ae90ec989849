"""The simulator's own speed: render time, a whole scenario run on one core, sweep throughput.

Each measurement runs in a fresh child process with the sweep workers' environment
(sim.runs.executors.WORKER_ENV: one Mesa thread, one BLAS thread; onnxruntime gets one thread
from sim.runs.runner): render time per frame at 768x432 (World.step with and without
rendering), frames per second of a whole scenario run (sim.runs.runner.run: render +
pipeline with all five predictors + bookkeeping) pinned to one core with and without
the ground-truth-crop ablation pipeline, and sweep throughput through sim.runs.executors'
spawned workers (1 and 2), with the peak RSS of a worker (ru_maxrss of the
reaped children). The results go to bench/history.jsonl (bench/history.py) unless
--no-append.

    .venv/bin/python -m bench.simulator [--frames 60] [--runs 6] [--no-append]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from typing import Any

from bench.history import ROOT
from bench.recorder import Recorder

REALTIME_FPS = 15.0
CASES = (1, 2, 3, 4, 5, 6, 8)  # walking cases; still (9) has no motion to predict
RUN_CASES = (5, 3, 5, 3)  # the whole-run rows: two cases twice, so one noisy run moves no median
TITLE = "Simulator: render time, scenario run on one core, sweep throughput"


def scenario(
    case: int, frames: int, seed: int = 0, shadows: bool = True, model: str = "rail"
) -> Any:
    """A case at the default 8 m with the robot driving at 2 m/s, `frames` frames at 15 fps.

    `shadows=False` is the overcast lighting (no shadow pass in the render); `model` the
    pedestrian's behaviour (a human walker's truth has a Track piece every 10 ms).
    """
    from dataclasses import replace

    from monopic.cases import Case
    from sim.scenario.cases import CasePlacement
    from sim.scenario.lighting import PRESETS
    from sim.scenario.walkers import WALKERS

    placement = CasePlacement(Case(case), duration=frames / REALTIME_FPS, seed=seed)
    sc = placement.scenario(behaviour=WALKERS[model]())
    if shadows:
        return sc
    sun = sc.scene.lighting.sun  # the same sun behind clouds
    overcast = PRESETS["overcast"].with_sun(sun.azimuth_deg, sun.elevation_deg)
    return replace(sc, scene=replace(sc.scene, lighting=overcast))


def child_render(frames: int) -> dict[str, Any]:
    """World.step with and without rendering, one core; first frame (GL setup) excluded."""
    import numpy as np

    from sim.runs.loop import StepTimes, run_loop
    from sim.world.world import World

    out: dict[str, Any] = {}
    for model in ("rail", "human", "rail", "human"):  # alternated, the second pair kept
        for render in (False, True):
            sc = scenario(5, frames, model=model)
            times = StepTimes()
            with World(sc, render=render) as world:
                run_loop(world, (), [times], frames=frames, stop_at_contact=False)
            key = ("render" if render else "no_render") + ("_human" if model == "human" else "")
            out[key] = times.ms[1:]  # steps, not the reset
    res = {}
    for k, v in out.items():
        a = np.array(v[2:])
        res[k] = {"p50": float(np.percentile(a, 50)), "p95": float(np.percentile(a, 95))}
    res["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return res


def child_run(
    frames: int, ablation: bool, shadows: bool = True, model: str = "rail", runtime: str = "cpu"
) -> dict[str, Any]:
    """One whole scenario through sim.runs.runner.run, after one warm-up run; frames per second.

    As in a sweep worker, the runs share one GL context (sim.world.render.KeptRenderContext), so
    llvmpipe's shader compilation is paid once by the warm-up, not by every run.
    """
    from monopic.pose.tracker import TrackerConfig
    from sim.runs.run_spec import RunSpec
    from sim.runs.runner import run
    from sim.world.render import KeptRenderContext

    tracker = TrackerConfig(threads=1, runtime=runtime)
    warm = RunSpec(id="warm", scenario=scenario(1, 10), ablation=ablation, stop_at_contact=False)
    results = []
    with KeptRenderContext() as kept:
        context = kept.fitting(768, 432)
        run(warm, render_context=context, tracker=tracker)
        for case in RUN_CASES:
            spec = RunSpec(
                id=f"case{case}", scenario=scenario(case, frames, shadows=shadows, model=model),
                ablation=ablation, stop_at_contact=False,
            )  # fmt: skip
            cpu0, t0 = time.process_time(), time.perf_counter()
            result = run(spec, render_context=context, tracker=tracker)
            wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
            results.append({"frames": result.frames, "wall_s": wall, "cpu_s": cpu})
    return {
        "runs": results,
        "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def child_sweep(frames: int, runs: int, workers: int) -> dict[str, Any]:
    """`runs` scenario runs through sim.runs.executors.local_executor with `workers` processes."""
    from sim.runs.executors import local_executor
    from sim.runs.run_spec import RunSpec

    specs = [
        RunSpec(
            id=f"bench/{k:02d}",
            scenario=scenario(CASES[k % len(CASES)], frames, seed=k),
            ablation=False,
            stop_at_contact=False,
        )
        for k in range(runs)
    ]
    rows: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    local_executor(workers)(specs, rows.append)
    wall = time.perf_counter() - t0
    errors = [r["error"] for r in rows if "error" in r]
    if errors:
        raise RuntimeError(errors[0])
    return {
        "wall_s": wall,
        "runs": len(rows),
        "frames": sum(r["frames"] for r in rows),
        "run_wall_s": [r["timing"]["wall_s"] for r in rows],
        "worker_maxrss_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
    }


def spawn_child(kind: str, pin: bool, **kw: Any) -> dict[str, Any]:
    from sim.runs.executors import WORKER_ENV

    env = dict(os.environ, **WORKER_ENV)
    cmd = [sys.executable, "-m", "bench.simulator", "--child", kind]
    for k, v in kw.items():
        cmd += [f"--{k}", str(v)]
    if pin:
        cmd.append("--pin")
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=60, help="frames per scenario run (15 fps)")
    ap.add_argument("--runs", type=int, default=6, help="runs per sweep throughput test")
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    ap.add_argument("--child", choices=("render", "run", "sweep"), help=argparse.SUPPRESS)
    ap.add_argument("--pin", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--ablation", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--shadows", type=int, default=1, help=argparse.SUPPRESS)
    ap.add_argument("--workers", type=int, default=1, help=argparse.SUPPRESS)
    ap.add_argument("--model", default="rail", help=argparse.SUPPRESS)
    ap.add_argument("--runtime", default="cpu", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        if args.pin:
            os.sched_setaffinity(0, sorted(os.sched_getaffinity(0))[:1])
        if args.child == "render":
            out = child_render(args.frames)
        elif args.child == "run":
            out = child_run(
                args.frames, bool(args.ablation), bool(args.shadows), args.model, args.runtime
            )
        else:
            out = child_sweep(args.frames, args.runs, args.workers)
        print(json.dumps(out))
        return

    recorder = Recorder("simulator", TITLE)
    load0 = os.getloadavg()[0]
    start = time.perf_counter()
    render = spawn_child("render", True, frames=args.frames)
    settings = [(0, 1, "rail", "cpu"), (0, 1, "human", "cpu"), (1, 1, "rail", "cpu")]
    settings.append((0, 0, "rail", "cpu"))
    from monopic.pose.sessions import runtime_unavailable

    why_not = runtime_unavailable("openvino")  # no extra, or not an Intel CPU
    if why_not is not None:
        print(f"skipping the openvino rows: {why_not}", file=sys.stderr)
    else:
        settings += [(0, 1, "rail", "openvino"), (0, 1, "human", "openvino")]
    runs = {
        (ab, sh, model, rt): spawn_child(
            "run", True, frames=args.frames, ablation=ab, shadows=sh, model=model, runtime=rt
        )
        for ab, sh, model, rt in settings
    }
    sweeps = {
        w: spawn_child("sweep", False, frames=args.frames, runs=args.runs, workers=w)
        for w in (1, 2)
    }
    load1 = os.getloadavg()[0]
    r, nr = render["render"], render["no_render"]
    rh, nrh = render["render_human"], render["no_render_human"]
    lines = [
        f"Scenarios: sim.scenario.cases.CasePlacement, 8 m, robot 2 m/s, {args.frames} frames "
        f"at 15 fps, 768x432; child processes with sim.runs.executors.WORKER_ENV; load average "
        f"{load0:.1f} before, {load1:.1f} after, on {os.cpu_count()} cores; "
        f"{time.perf_counter() - start:.0f} s in all.",
        "",
        "| World.step, one core | p50 | p95 |",
        "| --- | ---: | ---: |",
        f"| with rendering (768x432) | {r['p50']:.1f} ms | {r['p95']:.1f} ms |",
        f"| without rendering (truth only) | {nr['p50']:.1f} ms | {nr['p95']:.1f} ms |",
        f"| render alone (difference of p50) | {r['p50'] - nr['p50']:.1f} ms | |",
        f"| with rendering, human walker | {rh['p50']:.1f} ms | {rh['p95']:.1f} ms |",
        f"| without rendering, human walker (truth only) | {nrh['p50']:.1f} ms "
        f"| {nrh['p95']:.1f} ms |",
        "",
        "| whole scenario run on one core (sim.runs.runner.run, GL context kept) | frames "
        "| fps (median of 4 runs) "
        "| CPU-s per frame | vs real time at 15 fps | peak RSS |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    results: dict[str, Any] = {
        "frames_per_run": args.frames,
        "sweep_runs": args.runs,
        "world_step": {
            "render_p50_ms": r["p50"],
            "render_p95_ms": r["p95"],
            "no_render_p50_ms": nr["p50"],
            "no_render_p95_ms": nr["p95"],
            "render_alone_p50_ms": r["p50"] - nr["p50"],
            "human_render_p50_ms": rh["p50"],
            "human_render_p95_ms": rh["p95"],
            "human_no_render_p50_ms": nrh["p50"],
            "human_no_render_p95_ms": nrh["p95"],
        },
        "scenario_runs": [],
        "sweeps": [],
    }
    for (ab, sh, model, rt), res in runs.items():
        fps = sorted(x["frames"] / x["wall_s"] for x in res["runs"])
        med = statistics.median(fps)
        cpu = sum(x["cpu_s"] for x in res["runs"]) / sum(x["frames"] for x in res["runs"])
        name = "render + pipeline (5 predictors)" + (" + ground-truth-crop ablation" if ab else "")
        name += "" if sh else ", overcast (no shadow pass)"
        name += ", human walker" if model == "human" else ""
        name += ", pose models on openvino" if rt == "openvino" else ""
        results["scenario_runs"].append(
            {
                "name": name,
                "runtime": rt,
                "ablation": bool(ab),
                "shadows": bool(sh),
                "behaviour": model,
                "frames": res["runs"][0]["frames"],
                "runs": len(fps),
                "fps_median": med,
                "fps_min": fps[0],
                "fps_max": fps[-1],
                "cpu_ms_per_frame": 1e3 * cpu,
                "realtime_x": med / REALTIME_FPS,
                "peak_rss_mb": res["maxrss_mb"],
            }
        )
        lines.append(
            f"| {name} | {res['runs'][0]['frames']} | {med:.1f} ({fps[0]:.1f}-{fps[-1]:.1f}) "
            f"| {1e3 * cpu:.1f} ms | {med / REALTIME_FPS:.2f}x "
            f"({'faster' if med >= REALTIME_FPS else 'slower'}) | {res['maxrss_mb']:.0f} MB |"
        )
    lines += [
        "",
        "| sweep (sim.runs.executors.local_executor, no ablation) | runs | wall | runs per minute "
        "| frames per second | speed-up | worker peak RSS |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    base = sweeps[1]["frames"] / sweeps[1]["wall_s"]
    for w, s in sweeps.items():
        fps = s["frames"] / s["wall_s"]
        results["sweeps"].append(
            {
                "workers": w,
                "runs": s["runs"],
                "frames": s["frames"],
                "wall_s": s["wall_s"],
                "runs_per_minute": 60 * s["runs"] / s["wall_s"],
                "fps": fps,
                "speedup_x": fps / base,
                "worker_peak_rss_mb": s["worker_maxrss_mb"],
            }
        )
        lines.append(
            f"| {w} worker{'s' if w > 1 else ''} | {s['runs']} | {s['wall_s']:.1f} s "
            f"| {60 * s['runs'] / s['wall_s']:.1f} | {fps:.1f} | {fps / base:.2f}x "
            f"| {s['worker_maxrss_mb']:.0f} MB |"
        )
    lines.append(
        "\nSweep wall time includes spawning the workers; each run loads the pose models (about "
        "0.1 s) and each worker makes its GL context once."
    )
    table = "\n".join(lines)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
