"""How long runs will take: frames to render times a per-frame cost, over the workers.

The per-frame cost (seconds of one worker per simulated frame, everything a run does
included) is measured where possible: on the finished runs of the same results file or
dataset (their own wall times on this machine, at their settings). Before any run has
finished it comes from the `simulator` benchmark (bench/simulator.py; its lines in
bench/history.jsonl name the host): a whole run on one core took 79.5 ms
per 768x432 frame with the five predictors (45.6 ms of it MuJoCo's render, the rest the
pipeline), 101.2 ms with the ground-truth-crop ablation. The render share is scaled by
each camera's pixels. A dataset frame (one predictor, but a segmentation render and image
files too) measured the same as a sweep frame without the ablation (90 ms against 90-98 ms
at 768x432 on one core), so datasets use that figure. Frames are an upper
bound: a run ends early at first contact, so collision runs take less. Another machine,
or a loaded one, differs: the measured figure replaces the benchmark's as soon as one run
has finished. Starting costs a fixed time on top, which dominates tiny sweeps: a sweep
spent 8 s before its first run began (spawning workers that import MuJoCo, onnxruntime
and the pipeline, on 2 cores). A dataset starts the same workers and merges at the
end: 5 s beyond its runs' own time on one worker, 6-10 s on two (a 3-run 384x216
dataset).

People cost too: each person beyond the first adds to the world's render and truth, and
with the people tracker (a sweep's `tracker = "everyone"`) to the pipeline, which runs
their landmarks every frame. The per-person figures come from the benchmark's
`simulator_people_runs` line (whole runs with 1, 5 and 10 people under each tracker);
finished runs then scale every run's benchmark cost by how much slower or faster this
machine ran theirs, so a sweep mixing one person and ten is estimated run by run.

The camera's sensor (sim.sensor) is not in the benchmark's figure: a real camera renders
several sub-frames per frame for its motion blur (sim.world.shutter), so before its first
run finishes a real camera's sweep or dataset is estimated as if its camera were ideal,
too short; the measured figure of its finished runs (their wall times) includes it.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from sim.runs.run_spec import EVERYONE, ONE
from sim.scenario.spec import CameraSpec

BENCH_PIXELS = 768 * 432
BENCH_RENDER_S = 0.0456  # MuJoCo render of one 768x432 frame (llvmpipe), one core
BENCH_PIPELINE_S = 0.0795 - BENCH_RENDER_S  # pose, features, five predictors, truth
BENCH_ABLATION_S = 0.1012 - 0.0795  # the ground-truth-crop pipeline on the same frame
BENCH_SOURCE = (
    "the simulator benchmark's 79.5/101.2 ms per 768x432 frame and its per-person figures "
    "(bench/history.jsonl)"
)
# Per person beyond the first, and the people tracker's own cost with one person, as
# shares of a one-person frame (bench/simulator.py --people-runs-only, 2026-12-07 on the
# 2-core AMD EPYC while a sweep ran beside it: 264, 567 and 769 ms a frame with 1, 5 and
# 10 people under the one tracker, 362 and 1080 ms with 1 and 10 under everyone), times
# the quiet whole-run figure above (79.5 ms): 0.212, 0.302 and 0.371 of it.
ONE_PERSON_FRAME_S = 0.0795
BENCH_PERSON_S = {ONE: 0.212 * ONE_PERSON_FRAME_S, EVERYONE: 0.302 * ONE_PERSON_FRAME_S}
BENCH_EVERYONE_S = 0.371 * ONE_PERSON_FRAME_S
SWEEP_START_S = 8.0  # from the command's start to its workers' first runs (measured)
DATASET_START_S = 8.0  # a dataset's workers starting, and its merge (measured)


def bench_frame_seconds(
    camera: CameraSpec, ablation: bool, people: int = 1, tracker: str = ONE
) -> float:
    """One worker's seconds per frame of a run, from the benchmark (module docstring)."""
    render = BENCH_RENDER_S * camera.width * camera.height / BENCH_PIXELS
    base = render + BENCH_PIPELINE_S + (BENCH_ABLATION_S if ablation else 0.0)
    others = max(people - 1, 0) * BENCH_PERSON_S[tracker]
    return base + others + (BENCH_EVERYONE_S if tracker == EVERYONE else 0.0)


@dataclass(frozen=True)
class TimeEstimate:
    """Seconds for `frames` frames at `frame_seconds` each, shared by `workers`."""

    runs: int
    frames: int  # upper bound: a run ends at first contact
    frame_seconds: float  # one worker, per frame (mean over the runs)
    workers: int | None  # None: unknown (a Ray cluster's CPUs)
    source: str  # where frame_seconds comes from
    start_seconds: float = 0.0  # before the first run (workers starting)

    @property
    def worker_seconds(self) -> float:
        return self.frames * self.frame_seconds

    @property
    def seconds(self) -> float | None:
        if self.workers is None:
            return None
        return self.start_seconds + self.worker_seconds / max(1, min(self.workers, self.runs))

    def text(self) -> str:
        """One line: the figure and how it was computed."""
        if self.runs == 0:
            return "nothing to run"
        how = (
            f"up to {self.frames} frames x {self.frame_seconds:.3f} s per frame and worker "
            f"({self.source})"
        )
        if self.seconds is None:
            return f"about {_duration(self.worker_seconds)} of CPU time, over the cluster: {how}"
        used = max(1, min(self.workers or 1, self.runs))
        start = f"{self.start_seconds:.0f} s to start, then " if self.start_seconds else ""
        return f"about {_duration(self.seconds)} on {used} worker{'s' * (used > 1)}: {start}{how}"


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def estimate_time(
    to_run: Iterable[tuple[int, float]],
    measured: Iterable[tuple[int, float] | tuple[int, float, float]],
    workers: int | None,
    measured_where: str,
    start_seconds: float = 0.0,
) -> TimeEstimate:
    """The time of runs given as (frames, benchmark seconds per frame).

    `measured`: (frames, wall seconds) of finished runs, or (frames, wall seconds,
    benchmark seconds per frame). With the benchmark's figure each run still to do costs
    its own benchmark figure times the finished runs' measured over benchmark time (this
    machine's speed, learnt); without it their mean per-frame time replaces the
    benchmark's. `measured_where` names them for the text."""
    todo = list(to_run)
    frames = sum(f for f, _ in todo)
    done = [m for m in measured if m[0] > 0 and m[1] > 0]
    runs_said = f"{len(done)} finished run{'s' * (len(done) > 1)} {measured_where}"
    if done and all(len(m) == 3 for m in done):
        scale = sum(m[1] for m in done) / sum(m[0] * m[2] for m in done)  # type: ignore[misc]
        per = scale * sum(f * s for f, s in todo) / frames if frames else 0.0
        source = (
            f"each run's benchmark figure for its camera and people x {scale:.2f}, "
            f"as measured on {runs_said}"
        )
    elif done:
        per = sum(m[1] for m in done) / sum(m[0] for m in done)
        source = f"measured on {runs_said}"
    else:
        per = sum(f * s for f, s in todo) / frames if frames else 0.0
        source = BENCH_SOURCE + "; no run measured yet"
    return TimeEstimate(len(todo), frames, per, workers, source, start_seconds)
