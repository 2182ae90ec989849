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

Then, as a line of its own in the history (benchmark `simulator_people`), the frame with
1, 5, 10 and 20 people in view (PEOPLE): World.step with rendering at 768x432 on one core,
split into the render (and its shadow pass: the same crowd under the overcast preset, which
has no shadow pass, rendered alongside), the truth (World's per-frame ground truth of every
body) and, within the truth, the hidden share: `visibility()` (one mj_multiRay per person)
and `occluded_landmarks` (33 mj_ray calls per person), each timed by a perf_counter wrapped
around it in the child (`timed_parts`). `--people-only` runs that part alone.

And as a line of its own (benchmark `simulator_crowd`), the crowd model's cost: a crowd of
5, 10 and 20 (scenarios/families/small/crowd/crowd_crossing.toml's, the scripted person
beside it) worked out for a run of `--frames` frames (sim.scenario.crowd_motion.crowd_tracks,
as a World's reset does once a run), split into JuPedSim's own steps (Simulation.iterate)
and the rest (steering the planned people, reading positions, the members' Tracks); per
frame at 15 fps, beside the frame a World renders with those people (World.step with
rendering). `--crowd-only` runs that part alone.

And as a line of its own (benchmark `simulator_people_runs`), what a sweep run costs with
1, 5 and 10 people (RUN_PEOPLE; `crowd` above): whole runs through sim.runs.runner.run on
one core (no ablation, GL context kept, after a warm-up), with the one-pedestrian tracker
and with the people tracker (`tracker = "everyone"`), seconds per run and per frame. The
sweep's dry run (sim.runs.estimate) takes its per-person cost from this line.
`--people-runs-only` runs that part alone.

    .venv/bin/python -m bench.simulator [--frames 60] [--runs 6] [--people-only]
        [--crowd-only] [--people-runs-only] [--no-append]
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
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from typing import Any
from unittest import mock

from bench.history import ROOT
from bench.recorder import Recorder

REALTIME_FPS = 15.0
CASES = (1, 2, 3, 4, 5, 6, 8)  # walking cases; still (9) has no motion to predict
RUN_CASES = (5, 3, 5, 3)  # the whole-run rows: two cases twice, so one noisy run moves no median
TITLE = "Simulator: render time, scenario run on one core, sweep throughput"
PEOPLE_TITLE = "Simulator: render and truth per frame with 1 to 20 people in view"
PEOPLE = (1, 5, 10, 20)  # people in view: the scripted person and PEOPLE - 1 bystanders
PEOPLE_STRETCH_X = 0.6  # the stretch goal: 10 people's frame rate over 1 person's
CROWD_TITLE = "Simulator: the crowd model's time per frame with 5 to 20 people"
CROWD_SIZES = (5, 10, 20)  # crowd members (along the pavements; 3 of them crossing)
CROWD_FILE = ROOT / "scenarios/families/small/crowd/crowd_crossing.toml"
PEOPLE_RUNS_TITLE = (
    "Simulator: a sweep run's time with 1, 5 and 10 people, one tracker and everyone"
)
RUN_PEOPLE = (1, 5, 10)
TRACKER_NAMES = ("one", "everyone")  # sim.runs.run_spec.TRACKERS
WARM_STEPS = 2  # steps of each world not timed (the new scene's first draws)
# The bystanders in the order they join (x, y, heading in degrees, speed in m/s), in the world
# frame: the robot starts at the origin heading east (+x) at 2 m/s, the road is along x
# with its edges at y = -3.5 and 3.5 and a 3 m pavement beyond each. Walkers in a row keep
# one direction and speed, so none meets another; all are at x >= 13, clear of the
# scripted person crossing at x = 8, and within the camera's view (half-angle 48 degrees)
# while the robot covers its first 8 m (60 frames).
BYSTANDERS: tuple[tuple[float, float, float, float], ...] = (
    (14.0, 4.6, 0.0, 1.3),  # north pavement, walking east
    (18.0, -4.6, 180.0, 1.2),  # south pavement, walking west
    (17.0, 6.0, -90.0, 0.0),  # north pavement by the facades, standing
    (15.0, -6.0, 90.0, 0.0),  # south pavement by the facades, standing
    (24.0, 2.7, 180.0, 1.4),  # along the road, north lane by the kerb, walking west
    (16.0, -2.7, 0.0, 1.1),  # along the road, south lane by the kerb, walking east
    (22.0, 4.6, 0.0, 1.3),
    (26.0, -4.6, 180.0, 1.2),
    (25.0, 6.0, -90.0, 0.0),
    (23.0, -6.0, 90.0, 0.0),
    (20.0, -3.7, 90.0, 0.0),  # at the south kerb, facing the road
    (33.0, 6.0, -90.0, 0.0),
    (31.0, -6.0, 90.0, 0.0),
    (30.0, 4.6, 0.0, 1.3),
    (34.0, -4.6, 180.0, 1.2),
    (36.0, 2.7, 180.0, 1.4),
    (28.0, -2.7, 0.0, 1.1),
    (41.0, 6.0, -90.0, 0.0),
    (39.0, -6.0, 90.0, 0.0),
)


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


def crowd(people: int, frames: int, shadows: bool = True) -> Any:
    """`scenario(5, frames, shadows=shadows)` (the scripted person crossing 8 m ahead) with the
    first `people - 1` BYSTANDERS, named b1, b2, ..."""
    from dataclasses import replace

    from sim.scenario.spec import PedestrianSpec

    if not 1 <= people <= len(BYSTANDERS) + 1:
        raise ValueError(f"people must be 1 to {len(BYSTANDERS) + 1}, got {people}")
    others = tuple(
        PedestrianSpec(x, y, heading, speed, name=f"b{k}")
        for k, (x, y, heading, speed) in enumerate(BYSTANDERS[: people - 1], start=1)
    )
    return replace(scenario(5, frames, shadows=shadows), bystanders=others)


class Stopwatch:
    """Seconds spent in the calls of the functions it wraps, since the last `reset`."""

    def __init__(self) -> None:
        self.s = 0.0

    def reset(self) -> None:
        self.s = 0.0

    def wrap(self, fn: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.s += time.perf_counter() - t0

        return timed


PARTS = ("render", "truth", "visibility", "landmark_rays")


@contextmanager
def timed_parts() -> Iterator[dict[str, Stopwatch]]:
    """A Stopwatch per part of World.step, wrapped around (and, on leaving, unwrapped from):
    World.render (the frame), World._ground_truth (every body's truth), and the two
    hidden-share functions as sim.world.entities.pedestrian calls them (`visibility`,
    `occluded_landmarks`). A wrapper costs about a microsecond a call."""
    from sim.world import world as world_module
    from sim.world.entities import pedestrian as pedestrian_module

    watches = {part: Stopwatch() for part in PARTS}
    targets = (
        (world_module.World, "render", "render"),
        (world_module.World, "_ground_truth", "truth"),
        (pedestrian_module, "visibility", "visibility"),
        (pedestrian_module, "occluded_landmarks", "landmark_rays"),
    )
    with ExitStack() as stack:
        for owner, attr, part in targets:
            wrapped = watches[part].wrap(getattr(owner, attr))
            stack.enter_context(mock.patch.object(owner, attr, wrapped))
        yield watches


def child_people(frames: int, counts: Sequence[int] = PEOPLE, rounds: int = 2) -> dict[str, Any]:
    """World.step with rendering at 768x432 for each crowd of `counts` people, under the
    scenario's sun and overcast (no shadow pass), timed by part (timed_parts); p50 per frame.

    Rounds alternate the order (counts up then down, sun then overcast and back), so the
    host's drift hits every setting alike; the worlds share one GL context, and each
    world's first WARM_STEPS steps are not timed.
    """
    import numpy as np

    from sim.world.render import KeptRenderContext
    from sim.world.world import World

    if frames <= WARM_STEPS + 1:
        raise ValueError(f"frames must be more than {WARM_STEPS + 1}, got {frames}")
    keys = ("step", *PARTS, "in_frame", "seen")
    got: dict[tuple[int, bool], dict[str, list[float]]] = {
        (n, sh): {k: [] for k in keys} for n in counts for sh in (True, False)
    }
    with KeptRenderContext() as kept, timed_parts() as watches:
        context = kept.fitting(768, 432)
        for r in range(rounds):
            order = list(counts) if r % 2 == 0 else list(counts)[::-1]
            lights = (True, False) if r % 2 == 0 else (False, True)
            for n in order:
                for shadows in lights:
                    out = got[(n, shadows)]
                    with World(crowd(n, frames, shadows), render_context=context) as world:
                        world.reset()
                        for k in range(frames - 1):  # as World.run: reset, then frames - 1
                            for watch in watches.values():
                                watch.reset()
                            t0 = time.perf_counter()
                            step = world.step()
                            wall = time.perf_counter() - t0
                            if k < WARM_STEPS:
                                continue
                            out["step"].append(1e3 * wall)
                            for part, watch in watches.items():
                                out[part].append(1e3 * watch.s)
                            people = step.truth.people
                            out["in_frame"].append(sum(p.body.in_frame for p in people))
                            out["seen"].append(
                                float(np.mean([p.visibility.visible for p in people]))
                            )
    res: dict[str, Any] = {}
    for (n, shadows), out in got.items():
        row: dict[str, Any] = {
            f"{k}_p50_ms": float(np.percentile(out[k], 50)) for k in ("step", *PARTS)
        }
        row["step_p95_ms"] = float(np.percentile(out["step"], 95))
        rest = np.array(out["step"]) - np.array(out["render"]) - np.array(out["truth"])
        row["rest_p50_ms"] = float(np.percentile(rest, 50))
        row["frames"] = len(out["step"])
        row["in_frame_min"] = int(min(out["in_frame"]))
        row["seen_mean"] = float(np.mean(out["seen"]))
        res.setdefault(str(n), {})["sun" if shadows else "overcast"] = row
    res["rounds"] = rounds
    res["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return res


def crowd_scenario(members: int, frames: int) -> Any:
    """crowd_crossing.toml's scenario with `members` in its crowd (3 crossing) and a run of
    `frames` frames at 15 fps."""
    from dataclasses import replace

    from sim.scenario.crowd import crowd_looks
    from sim.scenario.files import load

    base = load(CROWD_FILE).scenario({}, "bench")
    assert base.crowd is not None
    across = min(3, members)
    crowd = replace(base.crowd, along=members - across, across=across,
                    looks=crowd_looks(members, 0.1))  # fmt: skip
    return replace(base, crowd=crowd, duration=frames / REALTIME_FPS)


def child_crowd(frames: int, sizes: Sequence[int] = CROWD_SIZES, rounds: int = 3) -> dict[str, Any]:
    """Per crowd size: the crowd's Tracks for a run (median of `rounds`), JuPedSim's
    iterate timed apart, and World.step with rendering of that crowd (p50, 20 frames)."""
    import jupedsim
    import numpy as np

    from sim.scenario.crowd_motion import DT, crowd_tracks
    from sim.scenario.motion import people_tracks
    from sim.world.world import World

    watch = Stopwatch()
    res: dict[str, Any] = {}
    with mock.patch.object(jupedsim.Simulation, "iterate", watch.wrap(jupedsim.Simulation.iterate)):
        for n in sizes:
            s = crowd_scenario(n, frames)
            t_end = s.duration + 5.0  # a World's lookahead beyond the run, about
            planned = list(people_tracks(replace_crowd(s), s.seed, t_end).values())
            total, model = [], []
            for r in range(rounds):
                watch.reset()
                t0 = time.perf_counter()
                crowd_tracks(s, planned, r, t_end)
                total.append(time.perf_counter() - t0)
                model.append(watch.s)
            frames_worked = t_end * REALTIME_FPS
            steps = []
            with World(s) as world:
                world.reset()
                for k in range(min(frames, 22) - 1):
                    t0 = time.perf_counter()
                    world.step()
                    if k >= WARM_STEPS:
                        steps.append(time.perf_counter() - t0)
            res[str(n)] = {
                "total_ms_per_frame": 1e3 * float(np.median(total)) / frames_worked,
                "jupedsim_ms_per_frame": 1e3 * float(np.median(model)) / frames_worked,
                "jupedsim_ms_per_iteration": 1e3 * float(np.median(model)) / (t_end / DT),
                "world_step_p50_ms": 1e3 * float(np.percentile(steps, 50)),
                "seconds_worked": t_end,
            }
    res["rounds"] = rounds
    return res


def replace_crowd(s: Any) -> Any:
    """The scenario without its crowd (its planned people alone)."""
    from dataclasses import replace

    return replace(s, crowd=None)


def crowd_report(got: dict[str, Any], frames: int) -> tuple[dict[str, Any], str]:
    """The crowd child's figures as history results and a Markdown table."""
    sizes = sorted(int(k) for k in got if k.isdigit())
    lines = [
        f"Crowd: {CROWD_FILE.relative_to(ROOT)} with 5-20 members and its scripted person, "
        f"worked out for a run of {frames} frames and a World's lookahead (sim.scenario."
        f"crowd_motion.crowd_tracks, once per run at reset), median of {got['rounds']}; "
        "per frame at 15 fps. One core, the sweep workers' environment.",
        "",
        "| crowd | JuPedSim steps per frame | whole crowd model per frame | per JuPedSim step "
        "| World.step with rendering (p50) | model / step |",
        "| ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for n in sizes:
        r = got[str(n)]
        lines.append(
            f"| {n} | {r['jupedsim_ms_per_frame']:.2f} ms | {r['total_ms_per_frame']:.2f} ms "
            f"| {r['jupedsim_ms_per_iteration']:.3f} ms | {r['world_step_p50_ms']:.0f} ms "
            f"| {r['total_ms_per_frame'] / r['world_step_p50_ms']:.3f} |"
        )
    return {"frames": frames, "crowd": {k: v for k, v in got.items() if k.isdigit()}}, "\n".join(
        lines
    )


def people_report(people: dict[str, Any], frames: int) -> tuple[dict[str, Any], str]:
    """The people child's figures as history results and a Markdown table."""
    counts = sorted(int(k) for k in people if k.isdigit())
    fps = {n: 1e3 / people[str(n)]["sun"]["step_p50_ms"] for n in counts}
    lines = [
        f"Scenario: sim.scenario.cases.CasePlacement case 5 at 8 m (robot 2 m/s), with "
        f"bystanders standing and walking on the pavements and along the road "
        f"(bench/simulator.py BYSTANDERS); World.step with rendering at 768x432 on one core, "
        f"{frames - 1 - WARM_STEPS} timed steps per world, {people['rounds']} rounds; p50 per "
        "frame of each part (the parts' p50s need not add up to the frame's). Shadow pass: the "
        "render under the scenario's sun less the render of the same crowd overcast (no shadow "
        "pass). Hidden share: visibility() (one mj_multiRay per person) and occluded_landmarks "
        "(33 mj_ray calls per person), both within the truth.",
        "",
        "| people (in frame at least; mean share seen) | frame p50 | fps | vs 1 person | render "
        "| of which shadow pass | truth | hidden share: visibility() "
        "| hidden share: landmark rays | rest (motion, posing) | frame overcast |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    rows = []
    for n in counts:
        sun, cloud = people[str(n)]["sun"], people[str(n)]["overcast"]
        shadow = sun["render_p50_ms"] - cloud["render_p50_ms"]
        vs_one = fps[n] / fps[counts[0]]
        rows.append(
            {
                "people": n,
                "in_frame_min": sun["in_frame_min"],
                "seen_mean": sun["seen_mean"],
                "frames": sun["frames"],
                "frame_p50_ms": sun["step_p50_ms"],
                "frame_p95_ms": sun["step_p95_ms"],
                "fps": fps[n],
                "vs_one_x": vs_one,
                "render_p50_ms": sun["render_p50_ms"],
                "shadow_pass_ms": shadow,
                "truth_p50_ms": sun["truth_p50_ms"],
                "visibility_p50_ms": sun["visibility_p50_ms"],
                "landmark_rays_p50_ms": sun["landmark_rays_p50_ms"],
                "rest_p50_ms": sun["rest_p50_ms"],
                "overcast_frame_p50_ms": cloud["step_p50_ms"],
                "overcast_render_p50_ms": cloud["render_p50_ms"],
                "overcast_truth_p50_ms": cloud["truth_p50_ms"],
            }
        )
        lines.append(
            f"| {n} ({sun['in_frame_min']}; {sun['seen_mean']:.2f}) | {sun['step_p50_ms']:.1f} ms "
            f"| {fps[n]:.1f} | {vs_one:.2f}x | {sun['render_p50_ms']:.1f} ms | {shadow:.1f} ms "
            f"| {sun['truth_p50_ms']:.1f} ms | {sun['visibility_p50_ms']:.1f} ms "
            f"| {sun['landmark_rays_p50_ms']:.1f} ms | {sun['rest_p50_ms']:.1f} ms "
            f"| {cloud['step_p50_ms']:.1f} ms |"
        )
    results: dict[str, Any] = {
        "frames_per_world": frames,
        "rounds": people["rounds"],
        "rows": rows,
        "stretch_goal_x": PEOPLE_STRETCH_X,
        "peak_rss_mb": people["maxrss_mb"],
    }
    if 1 in fps and 10 in fps:
        ratio = fps[10] / fps[1]
        cloudy = people["1"]["overcast"]["step_p50_ms"] / people["10"]["overcast"]["step_p50_ms"]
        results["fps_10_over_1_x"] = ratio
        results["overcast_fps_10_over_1_x"] = cloudy
        lines += [
            "",
            f"10 people's frame rate over 1 person's: {ratio:.2f} (stretch goal "
            f"{PEOPLE_STRETCH_X:g}: {'met' if ratio >= PEOPLE_STRETCH_X else 'not met'}); "
            f"overcast (no shadow pass) {cloudy:.2f}.",
        ]
    top = rows[-1]
    hidden = top["visibility_p50_ms"] + top["landmark_rays_p50_ms"]
    lines += [
        "",
        f"At {top['people']} people the hidden share takes {hidden:.1f} ms a frame "
        f"({hidden / top['truth_p50_ms']:.0%} of the truth, "
        f"{hidden / top['frame_p50_ms']:.0%} of the frame); the render "
        f"{top['render_p50_ms'] / top['frame_p50_ms']:.0%} of the frame.",
    ]
    return results, "\n".join(lines)


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


def child_people_runs(
    frames: int, counts: Sequence[int] = RUN_PEOPLE, rounds: int = 2
) -> dict[str, Any]:
    """Whole runs of `crowd(n, frames)` for each count and tracker, `rounds` times in
    alternation (so a busy spell of the machine hits every setting alike), after one
    warm-up run per tracker; seconds per run and per frame."""
    from monopic.pose.tracker import TrackerConfig
    from sim.runs.run_spec import RunSpec
    from sim.runs.runner import run
    from sim.world.render import KeptRenderContext

    tracker = TrackerConfig(threads=1)
    out: dict[str, Any] = {"rounds": rounds}
    with KeptRenderContext() as kept:
        context = kept.fitting(768, 432)
        for follows in TRACKER_NAMES:
            warm = RunSpec(id="warm", scenario=crowd(2, 10), ablation=False,
                           stop_at_contact=False, tracker=follows)  # fmt: skip
            run(warm, render_context=context, tracker=tracker)
        for _ in range(rounds):
            for n in counts:
                for follows in TRACKER_NAMES:
                    spec = RunSpec(id=f"p{n}", scenario=crowd(n, frames), ablation=False,
                                   stop_at_contact=False, tracker=follows)  # fmt: skip
                    t0 = time.perf_counter()
                    result = run(spec, render_context=context, tracker=tracker)
                    wall = time.perf_counter() - t0
                    row = out.setdefault(f"{n}/{follows}", {"wall_s": [], "frames": result.frames})
                    row["wall_s"].append(wall)
    out["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def people_runs_report(got: dict[str, Any], frames: int) -> tuple[dict[str, Any], str]:
    """The people-runs child's figures as history results and a Markdown table."""
    rows = []
    lines = [
        f"Scenario: bench/simulator.py `crowd(n)`: case 5 at 8 m (robot 2 m/s) with n - 1 "
        f"bystanders, {frames} frames at 15 fps, 768x432, no ablation; sim.runs.runner.run on "
        f"one core, GL context kept; median of {got['rounds']} runs, taken in alternation.",
        "",
        "| people | tracker | s per run | ms per frame | vs 1 person, same tracker "
        "| everyone vs one |",
        "| ---: | --- | ---: | ---: | ---: | ---: |",
    ]
    per_frame = {}
    for key, row in got.items():
        if "/" not in key:
            continue
        n, follows = key.split("/")
        per_frame[(int(n), follows)] = statistics.median(row["wall_s"]) / row["frames"]
    counts = sorted({n for n, _ in per_frame})
    for n in counts:
        for follows in TRACKER_NAMES:
            if (n, follows) not in per_frame:
                continue
            ms = 1e3 * per_frame[(n, follows)]
            row = got[f"{n}/{follows}"]
            vs_one = per_frame[(n, follows)] / per_frame[(counts[0], follows)]
            vs_tracker = per_frame[(n, follows)] / per_frame[(n, "one")]
            rows.append({"people": n, "tracker": follows, "frames": row["frames"],
                         "wall_s": row["wall_s"], "run_s": statistics.median(row["wall_s"]),
                         "frame_ms": ms, "vs_one_person_x": vs_one,
                         "vs_one_tracker_x": vs_tracker})  # fmt: skip
            lines.append(
                f"| {n} | {follows} | {statistics.median(row['wall_s']):.1f} | {ms:.1f} "
                f"| {vs_one:.2f}x | {vs_tracker:.2f}x |"
            )
    return {"frames_per_run": frames, "rows": rows, "peak_rss_mb": got["maxrss_mb"]}, "\n".join(
        lines
    )


def spawn_child(kind: str, pin: bool, **kw: Any) -> dict[str, Any]:
    from sim.runs.executors import WORKER_ENV

    env = dict(os.environ, **WORKER_ENV)
    cmd = [sys.executable, "-m", "bench.simulator", "--child", kind]
    for k, v in kw.items():
        cmd += [f"--{k}", *(map(str, v) if isinstance(v, list | tuple) else [str(v)])]
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
    ap.add_argument(
        "--people-only", action="store_true",
        help="only the frame with 1 to 20 people in view (its own history line)",
    )  # fmt: skip
    ap.add_argument(
        "--crowd-only", action="store_true",
        help="only the crowd model's time per frame with 5 to 20 people (its own history line)",
    )  # fmt: skip
    ap.add_argument(
        "--people-runs-only", action="store_true",
        help="only a sweep run's time with 1, 5 and 10 people (its own history line)",
    )  # fmt: skip
    ap.add_argument(
        "--child",
        choices=("render", "run", "sweep", "people", "crowd", "people_runs"),
        help=argparse.SUPPRESS,
    )
    ap.add_argument("--people", type=int, nargs="+", default=PEOPLE, help=argparse.SUPPRESS)
    ap.add_argument("--rounds", type=int, default=2, help=argparse.SUPPRESS)
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
        elif args.child == "people":
            out = child_people(args.frames, args.people, args.rounds)
        elif args.child == "crowd":
            out = child_crowd(args.frames)
        elif args.child == "people_runs":
            out = child_people_runs(args.frames, args.people, args.rounds)
        elif args.child == "run":
            out = child_run(
                args.frames, bool(args.ablation), bool(args.shadows), args.model, args.runtime
            )
        else:
            out = child_sweep(args.frames, args.runs, args.workers)
        print(json.dumps(out))
        return

    if args.people_runs_only or not (args.people_only or args.crowd_only):
        recorder = Recorder("simulator_people_runs", PEOPLE_RUNS_TITLE)
        counts = [n for n in args.people if n in RUN_PEOPLE] or list(RUN_PEOPLE)
        got = spawn_child("people_runs", True, frames=args.frames, rounds=args.rounds,
                          people=counts)  # fmt: skip
        results, table = people_runs_report(got, args.frames)
        print(table)
        recorder.finish(results, table, write=not args.no_append)
        if args.people_runs_only:
            return
    if not (args.people_only or args.crowd_only):
        main_rows(args)
    if not args.people_only:
        recorder = Recorder("simulator_crowd", CROWD_TITLE)
        results, table = crowd_report(spawn_child("crowd", True, frames=args.frames), args.frames)
        print(table)
        recorder.finish(results, table, write=not args.no_append)
    if args.crowd_only:
        return
    recorder = Recorder("simulator_people", PEOPLE_TITLE)
    people = spawn_child("people", True, frames=args.frames)
    results, table = people_report(people, args.frames)
    print(table)
    recorder.finish(results, table, write=not args.no_append)


def main_rows(args: argparse.Namespace) -> None:
    """The render, whole-run and sweep rows: the `simulator` line of the history."""
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
