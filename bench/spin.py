"""Do onnxruntime's threads pay for spinning? Each pose model at 2 threads, sleeping or spinning.

With a multi-threaded session whose idle threads sleep (the default), every
operator of a run wakes them, and on the landmark model's ~160 small operators that
costs about what the second thread saves. `TrackerConfig(spin=True)` lets them spin
within a run and stops them when it returns (monopic.pose.sessions.make_session). This
times both settings for each shipped model, alternated round by round in one process, with
`--gap-ms` of Python work between runs as the pipeline has (warp, filters, features), so
threads that spin between runs would show their cost in the CPU column. With `--busy N`,
N busy loops run beside it (other work on the cores): where spinning costs instead.

    .venv/bin/python -m bench.spin [--threads 2] [--rounds 8] [--runs 40] [--busy 0]
        [--gap-ms 1.5] [--no-append]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time

import numpy as np

from bench.recorder import Recorder
from monopic.pose.sessions import (
    DETECTOR_MODELS,
    LANDMARK_MODELS,
    make_session,
    model_path,
)

MODELS = {
    "full-int8 landmarks": LANDMARK_MODELS["full-int8"],
    "full landmarks (float)": LANDMARK_MODELS["full"],
    "detector (float)": DETECTOR_MODELS["float"],
}
SETTINGS = {"sleep (default)": False, "spin within runs": True}


def busy_loop(stop) -> None:  # noqa: ANN001 - a multiprocessing Event
    """Other work on a core: counts until told to stop."""
    n = 0
    while not stop.is_set():
        n += 1


def python_work(seconds: float) -> None:
    """The pipeline's own work between two model runs: small numpy calls, one thread."""
    end = time.perf_counter() + seconds
    a = np.ones(64)
    while time.perf_counter() < end:
        a = a * 1.000001


def time_runs(session, feed: dict, runs: int, gap_s: float) -> tuple[float, float]:
    """Median wall ms of a run, and process CPU ms per run net of the gap's own CPU."""
    walls = []
    c0 = time.process_time()
    for _ in range(runs):
        t0 = time.perf_counter()
        session.run(None, feed)
        walls.append(time.perf_counter() - t0)
        python_work(gap_s)
    cpu = (time.process_time() - c0) / runs - gap_s
    return 1e3 * float(np.median(walls)), 1e3 * cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=2, help="intra-op threads (>= 2)")
    ap.add_argument("--rounds", type=int, default=8, help="alternated rounds")
    ap.add_argument("--runs", type=int, default=40, help="timed runs per setting per round")
    ap.add_argument("--gap-ms", type=float, default=1.5, help="Python work between runs")
    ap.add_argument("--busy", type=int, default=0, help="busy loops beside the sessions")
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    if args.threads < 2:
        sys.exit(
            f"spin.py: --threads must be 2 or more (one thread has no pool), got {args.threads}"
        )
    recorder = Recorder("spin", "Pose models at 2 threads: threads sleeping or spinning")
    rng = np.random.default_rng(0)
    sessions, feeds = {}, {}
    for label, file in MODELS.items():
        for setting, spin in SETTINGS.items():
            sessions[label, setting] = make_session(model_path(file), args.threads, spin=spin)
        inp = sessions[label, "sleep (default)"].get_inputs()[0]
        shape = [d if isinstance(d, int) else 1 for d in inp.shape]
        feeds[label] = {inp.name: rng.random(shape, dtype=np.float32)}
    stop = mp.Event()
    loops = [mp.Process(target=busy_loop, args=(stop,), daemon=True) for _ in range(args.busy)]
    for p in loops:
        p.start()
    times: dict[tuple[str, str], list[tuple[float, float]]] = {k: [] for k in sessions}
    try:
        for rnd in range(args.rounds):
            for label in MODELS:
                order = list(SETTINGS) if rnd % 2 == 0 else list(SETTINGS)[::-1]
                for setting in order:
                    session = sessions[label, setting]
                    time_runs(session, feeds[label], 3, args.gap_ms / 1e3)  # warm
                    times[label, setting].append(
                        time_runs(session, feeds[label], args.runs, args.gap_ms / 1e3)
                    )
            print(f"round {rnd + 1}/{args.rounds}", file=sys.stderr)
    finally:
        stop.set()
        for p in loops:
            p.join()
    rows = []
    lines = [
        f"{args.threads} intra-op threads; {args.rounds} alternated rounds of {args.runs} runs "
        f"per setting, {args.gap_ms} ms of Python work between runs; {args.busy} busy loops "
        "beside (other work on the cores); medians over rounds.",
        "",
        "| model | sleeping threads | spinning within runs | spin / sleep | CPU per run, "
        "sleep / spin |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for label in MODELS:
        sleep = np.median(np.array(times[label, "sleep (default)"]), axis=0)
        spin = np.median(np.array(times[label, "spin within runs"]), axis=0)
        rows.append(
            {
                "model": label,
                "sleep_ms": float(sleep[0]),
                "spin_ms": float(spin[0]),
                "spin_over_sleep_x": float(spin[0] / sleep[0]),
                "sleep_cpu_ms": float(sleep[1]),
                "spin_cpu_ms": float(spin[1]),
            }
        )
        lines.append(
            f"| {label} | {sleep[0]:.2f} ms | {spin[0]:.2f} ms | {spin[0] / sleep[0]:.2f} "
            f"| {sleep[1]:.2f} / {spin[1]:.2f} ms |"
        )
    table = "\n".join(lines)
    print(table)
    results = {
        "threads": args.threads,
        "rounds": args.rounds,
        "runs": args.runs,
        "gap_ms": args.gap_ms,
        "busy_loops": args.busy,
        "models": rows,
    }
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
