"""Render time of this checkout against another commit's, frame by frame, taking turns.

A change to the scene or the renderer is judged by the ratio of render times on the same
frames. On this shared host the speed moves by 15-40 % over an hour (BENCHMARKS.md), so
two runs one after the other say little: here two processes, one per checkout, each hold
a world at the same frame and render it in turns (A B, then B A), pinned to the same
core with the sweep workers' environment, and each pair gives one ratio.

    .venv/bin/python -m bench.render_ab [--before HEAD] [--renders 200] [--no-append]

`--before` is any git revision; its tree is checked out in a temporary worktree.
"""

from __future__ import annotations

import argparse
import inspect
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from bench.recorder import Recorder

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

TITLE = "Render time, this checkout against another commit, paired frame by frame"
# (scenario file, frame rendered): a small-scale case, a car-scale family, a near miss.
SCENES = (
    ("scenarios/cases/case5_perpendicular_right.toml", 10),
    ("scenarios/families/car/cpnco50.toml", 10),
    ("scenarios/families/small/nearmiss_kerb_stop.toml", 40),
)
CORE = 1


def serve(scenario: str, frame: int) -> None:
    """Child: render `scenario` at `frame` once per line on stdin. Run with its checkout as
    the working folder (`python -c`, whose import path starts there), so that the `sim`
    it imports is that checkout's."""
    import sys
    import time
    from pathlib import Path

    from sim.scenario.files import load
    from sim.world.world import World

    with World(load(Path(scenario)).base) as world:
        world.reset()
        for _ in range(frame):
            world.step()
        world.render()  # GL set-up and shader compilation
        print("ready", flush=True)
        for _ in sys.stdin:
            t0 = time.perf_counter()
            world.render()
            print(time.perf_counter() - t0, flush=True)


def paired(roots: tuple[str, str], scenario: str, frame: int, renders: int) -> np.ndarray:
    """(renders, 2) seconds per render of each checkout, taken in turns."""
    from sim.runs.executors import WORKER_ENV

    env = dict(os.environ, **WORKER_ENV)
    env.pop("PYTHONPATH", None)  # the working folder decides which checkout is imported
    code = f"{inspect.getsource(serve)}\nserve({scenario!r}, {frame})\n"
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", code],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env=env,
            cwd=root,
            preexec_fn=lambda: os.sched_setaffinity(0, {CORE}),
        )
        for root in roots
    ]
    try:
        for p, root in zip(procs, roots, strict=True):
            line = p.stdout.readline().strip() if p.stdout else ""
            if line != "ready":
                raise SystemExit(f"render_ab: {scenario} did not start in {root}")
        times = np.empty((renders, 2))
        for i in range(renders):
            for k in (0, 1) if i % 2 == 0 else (1, 0):
                assert procs[k].stdin and procs[k].stdout
                procs[k].stdin.write("go\n")
                procs[k].stdin.flush()
                times[i, k] = float(procs[k].stdout.readline())
        return times
    finally:
        for p in procs:
            if p.stdin:
                p.stdin.close()
            p.wait()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default="HEAD", help="git revision to compare against")
    parser.add_argument("--renders", type=int, default=200, help="renders per scene and side")
    parser.add_argument("--no-append", action="store_true", help="do not write the history")
    args = parser.parse_args()
    if args.renders < 2:
        raise SystemExit(f"render_ab: --renders must be at least 2, got {args.renders}")
    rev = subprocess.run(
        ["git", "rev-parse", "--short", args.before],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    if rev.returncode != 0:
        raise SystemExit(f"render_ab: --before {args.before!r} is not a git revision here")
    before = rev.stdout.strip()
    recorder = Recorder("render_ab", TITLE)
    rows, results = [], {"before": before, "renders": args.renders, "scenes": []}
    with tempfile.TemporaryDirectory() as tmp:
        tree = str(Path(tmp) / "before")
        subprocess.run(
            ["git", "worktree", "add", "--detach", "-q", tree, before], cwd=ROOT, check=True
        )
        try:
            for scenario, frame in SCENES:
                t = paired((tree, str(ROOT)), scenario, frame, args.renders)
                ratio = t[:, 1] / t[:, 0]
                q1, q2, q3 = np.percentile(ratio, [25, 50, 75])
                a_ms, b_ms = 1e3 * np.median(t, axis=0)
                print(f"{scenario}: {a_ms:.1f} -> {b_ms:.1f} ms, ratio {q2:.3f}", flush=True)
                results["scenes"].append(
                    {
                        "scenario": scenario,
                        "frame": frame,
                        "before_ms": a_ms,
                        "after_ms": b_ms,
                        "ratio_x": q2,
                        "ratio_q1_x": q1,
                        "ratio_q3_x": q3,
                    }
                )
                rows.append(
                    f"| {scenario} (frame {frame}) | {a_ms:.1f} ms | {b_ms:.1f} ms "
                    f"| **{q2:.3f}** ({q1:.3f}-{q3:.3f}) |"
                )
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", tree], cwd=ROOT, check=False)
    table = "\n".join(
        [
            f"Render of one 768x432 frame (World.render), {args.renders} renders a side, "
            f"one core, this checkout against {before}.",
            "",
            "| scene | before (median) | this checkout | ratio, paired (quartiles) |",
            "| --- | ---: | ---: | ---: |",
            *rows,
        ]
    )
    print(table)
    recorder.finish(results, table, write=not args.no_append)
    return 0


if __name__ == "__main__":
    sys.exit(main())
