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

And as a line of its own (benchmark `simulator_camera`), what a real camera's sensor
(sim.sensor, sim.world.shutter) costs against the ideal camera (CameraSpec.sensor None):
World.step with rendering at 768x432 on one core with IMX273 (auto exposure) beside the
ideal camera, under the sun and overcast (1,000 lux: longer exposures), the two worlds
stepped in turns frame by frame, p50 and p95 and their ratio against the goal (within
CAMERA_GOAL_X), with the real camera's parts (linear light, readout, image motion); the
readout and linear_light alone on a rendered frame's light; the sub-frame blur's cost on
the car scale at FAST_SPEED with a fixed BLUR_EXPOSURE_MS exposure, its draws a frame
and the frame time with the draws capped at each of BLUR_DRAWS; and the floor of a blur
from a per-pixel motion field: a segmentation render and a depth read per frame, next to
the render. `--camera-only` runs that part alone.

And as a line of its own (benchmark `simulator_night`), what a night frame costs: the Euro
NCAP CPNA point at 40 km/h, impact 50 % (sim.scenario.ncap, nominal draw) by day and at
night through the car's camera (imx273), and at night through the ideal camera (one draw,
the lights alone) and through imx273 with its draws capped at one (the exposure's motion
blur off), the worlds stepped in turns as the camera part does; step p50/p95, draws a
frame, exposure and gain, the ratio of each against the day frame. `--night-only` runs
that part alone.

The `--...-only` options choose parts (several may be given); with none, every part runs.

    .venv/bin/python -m bench.simulator [--frames 60] [--runs 6] [--people-only]
        [--crowd-only] [--people-runs-only] [--camera-only] [--night-only] [--no-append]
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
CAMERA_TITLE = "Simulator: a real camera's frame (sensor, motion blur) against the ideal camera's"
CAMERA_GOAL_X = 1.5  # the goal: the real camera's frame time within 1.5x the ideal camera's
CAMERA_PARTS = ("render", "truth", "linear", "readout", "motion")
NIGHT_TITLE = "Simulator: a night frame (low beams, lamps, 1 lux) against the day frame"
FAST_SPEED = 13.9  # m/s (50 km/h): the car in town, where a long exposure smears most
BLUR_EXPOSURE_MS = 30.0  # IMX273's longest exposure, fixed: the blur rows' long exposure
BLUR_DRAWS = (1, 2, 4, 8)  # the sub-frame caps (SensorSpec.max_subframes) timed side by side
READOUT_REPEATS = 40  # calls of the readout and of linear_light timed alone
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
    from monopic.cases import Case
    from sim.scenario.cases import CasePlacement
    from sim.scenario.walkers import WALKERS

    placement = CasePlacement(Case(case), duration=frames / REALTIME_FPS, seed=seed)
    sc = placement.scenario(behaviour=WALKERS[model]())
    return sc if shadows else overcast(sc)


def overcast(sc: Any) -> Any:
    """The scenario under the overcast preset: the same sun behind clouds (no shadow pass
    in the render, and 1,000 lux instead of the clear sky's 32,000 for a real sensor)."""
    from dataclasses import replace

    from sim.scenario.lighting import PRESETS

    sun = sc.scene.lighting.sun
    cloudy = PRESETS["overcast"].with_sun(sun.azimuth_deg, sun.elevation_deg)
    return replace(sc, scene=replace(sc.scene, lighting=cloudy))


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
    """Seconds spent in the calls of the functions it wraps, since the last `reset`, and
    what the last of those calls returned (None if none returned since)."""

    def __init__(self) -> None:
        self.s = 0.0
        self.last: Any = None

    def reset(self) -> None:
        self.s = 0.0
        self.last = None

    def wrap(self, fn: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = time.perf_counter()
            try:
                self.last = fn(*args, **kwargs)
                return self.last
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

    with timed(
        (
            (world_module.World, "render", "render"),
            (world_module.World, "_ground_truth", "truth"),
            (pedestrian_module, "visibility", "visibility"),
            (pedestrian_module, "occluded_landmarks", "landmark_rays"),
        )
    ) as watches:
        yield watches


@contextmanager
def timed(targets: Sequence[tuple[object, str, str]]) -> Iterator[dict[str, Stopwatch]]:
    """A Stopwatch per part, each wrapped around its (owner, attribute) while inside."""
    watches = {part: Stopwatch() for _, _, part in targets}
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


def with_sensor(sc: Any, sensor: Any) -> Any:
    """The scenario with its robot's camera given `sensor` (None: the ideal camera)."""
    from dataclasses import replace

    camera = replace(sc.robot.camera, sensor=sensor)
    return replace(sc, robot=replace(sc.robot, camera=camera))


def fast_scenario(frames: int, sensor: Any = None) -> Any:
    """The car scale (sim.scenario.families CAR: 1.8 m wide, camera 1.3 m up, 45 degrees
    vertical) driving at FAST_SPEED under the overcast preset (where long exposures belong),
    case 5's person crossing far enough ahead that the car never reaches the crossing
    (nothing in the run stops it); `frames` frames at 15 fps."""
    from monopic.cases import Case
    from sim.scenario.cases import CasePlacement
    from sim.scenario.families import CAR

    duration = frames / REALTIME_FPS
    placement = CasePlacement(
        Case(5), distance=FAST_SPEED * duration / 2 + 15.0, robot_speed=FAST_SPEED,
        duration=duration,
    )  # fmt: skip
    return with_sensor(overcast(placement.scenario(robot=CAR.robot)), sensor)


def blur_sensor(most: int | None = None) -> Any:
    """IMX273 with a fixed BLUR_EXPOSURE_MS exposure at gain 1; `most` caps the sub-frame
    draws (None: the preset's max_subframes)."""
    from dataclasses import replace

    from sim.sensor.spec import IMX273

    spec = replace(IMX273, exposure_ms=BLUR_EXPOSURE_MS, gain=1.0)
    return spec if most is None else replace(spec, max_subframes=most)


@contextmanager
def camera_parts() -> Iterator[dict[str, Stopwatch]]:
    """A Stopwatch per part of a real camera's World.step (CAMERA_PARTS): World.render (every
    draw of the exposure), World._ground_truth, the shutter's linear_light (8-bit render to
    linear light, once per draw), Sensor.read (noise, gain, digitiser, tone curve) and
    Scene.image_motion (how many draws; its `last` is the image motion in pixels)."""
    from sim.sensor.sensor import Sensor
    from sim.world import shutter as shutter_module
    from sim.world import world as world_module
    from sim.world.scene import Scene

    with timed(
        (
            (world_module.World, "render", "render"),
            (world_module.World, "_ground_truth", "truth"),
            (shutter_module, "linear_light", "linear"),
            (Sensor, "read", "readout"),
            (Scene, "image_motion", "motion"),
        )
    ) as watches:
        yield watches


CameraRecord = dict[str, list[float]]
AfterStep = Callable[[str, Any], None]


def step_in_turns(
    specs: dict[str, Any],
    frames: int,
    watches: dict[str, Stopwatch],
    out: dict[str, CameraRecord],
    after: AfterStep | None = None,
) -> None:
    """World.step with rendering of each scenario in `specs`, the worlds stepped in turns
    frame by frame (the first of each frame's turns rotating), so a busy spell of the host
    hits every world alike; appends to `out[name]` each step's time and parts after the
    first WARM_STEPS, then calls `after(name, world)` outside the timing.

    Each world makes its own GL context: two renderers lent one context and drawn in turns
    draw into each other's buffers (a frame of one world came back wrong by up to 240
    levels), while a world alone in a kept context draws exactly what a world with its own
    context draws.
    """
    from sim.world.world import World

    with ExitStack() as stack:
        worlds = {name: stack.enter_context(World(sc)) for name, sc in specs.items()}
        dt = {name: sc.dt for name, sc in specs.items()}
        for world in worlds.values():
            world.reset()
        names = list(worlds)
        for k in range(frames - 1):  # as World.run: reset, then frames - 1 steps
            first = k % len(names)
            for name in names[first:] + names[:first]:
                for watch in watches.values():
                    watch.reset()
                t0 = time.perf_counter()
                step = worlds[name].step()
                wall = time.perf_counter() - t0
                if k < WARM_STEPS:
                    continue
                rec = out.setdefault(name, {})
                rec.setdefault("step", []).append(1e3 * wall)
                for part, watch in watches.items():
                    rec.setdefault(part, []).append(1e3 * watch.s)
                cam = step.truth.camera
                if cam is not None:
                    rec.setdefault("draws", []).append(cam.subframes)
                    rec.setdefault("exposure", []).append(1e3 * cam.exposure_s)
                    rec.setdefault("gain", []).append(cam.gain)
                    motion = watches["motion"].last
                    if motion is not None:  # image motion over the exposure, px
                        share = min(cam.exposure_s / dt[name], 1.0)
                        rec.setdefault("blur_px", []).append(motion * share)
                if after is not None:
                    after(name, worlds[name])


def camera_summary(rec: CameraRecord) -> dict[str, Any]:
    """One world's steps: p50 and p95 of the step, p50 of each part, the draws a frame and,
    for a real camera, its exposure, gain and image motion over the exposure."""
    import numpy as np

    out: dict[str, Any] = {"frames": len(rec["step"])}
    out["step_p50_ms"] = float(np.percentile(rec["step"], 50))
    out["step_p95_ms"] = float(np.percentile(rec["step"], 95))
    for part in CAMERA_PARTS:
        out[f"{part}_p50_ms"] = float(np.percentile(rec[part], 50))
    draws = rec.get("draws", [1])
    out["draws_mean"] = float(np.mean(draws))
    out["draws_min"], out["draws_max"] = int(min(draws)), int(max(draws))
    for key, name in (("exposure", "exposure_p50_ms"), ("gain", "gain_p50"),
                      ("blur_px", "blur_p50_px")):  # fmt: skip
        out[name] = float(np.percentile(rec[key], 50)) if rec.get(key) else None
    return out


def child_camera(
    frames: int,
    rounds: int = 2,
    draws: Sequence[int] = BLUR_DRAWS,
    repeats: int = READOUT_REPEATS,
) -> dict[str, Any]:
    """The ideal camera against IMX273 (auto exposure) under the sun and overcast, with the
    segmentation render timed on the ideal camera's sun frames; the sub-frame blur's cost
    on the car scale with a fixed long exposure and the draws capped at each of `draws`;
    the readout and linear_light alone on a rendered frame's light (`repeats` calls each).

    Rounds alternate the order of the lightings; within a lighting the worlds step in
    turns (step_in_turns).
    """
    import mujoco
    import numpy as np

    from sim.sensor.photometry import electrons_per_second
    from sim.sensor.readout import NoisePool, Readout, linear_light
    from sim.sensor.spec import IMX273

    if frames <= WARM_STEPS + 1:
        raise ValueError(f"frames must be more than {WARM_STEPS + 1}, got {frames}")
    pairs: dict[str, dict[str, CameraRecord]] = {"sun": {}, "overcast": {}}
    blur: dict[str, CameraRecord] = {}
    seg: dict[str, list[float]] = {"masks": [], "depth_read": [], "render_again": []}
    kept: dict[str, np.ndarray] = {}

    def segmentation(name: str, world: Any) -> None:
        """After an ideal sun step: the same state drawn again in colour, then its
        segmentation render (every person's mask) and that draw's depth buffer read."""
        if name != "ideal":
            return
        renderer = world.renderer
        t0 = time.perf_counter()
        kept["image"] = renderer.render()
        t1 = time.perf_counter()
        world.person_masks()
        t2 = time.perf_counter()
        depth = kept.setdefault(
            "depth", np.empty((renderer.height, renderer.width), dtype=np.float32)
        )
        # SceneRenderer keeps its MuJoCo context to itself: its depth buffer is read here
        # through its private fields, as a motion-field blur would have to read it.
        renderer._context.make_current()
        mujoco.mjr_readPixels(None, depth, renderer._rect, renderer._mjr)
        t3 = time.perf_counter()
        seg["render_again"].append(1e3 * (t1 - t0))
        seg["masks"].append(1e3 * (t2 - t1))
        seg["depth_read"].append(1e3 * (t3 - t2))

    lux: dict[str, float] = {}
    with camera_parts() as watches:
        for r in range(rounds):
            lights = ("sun", "overcast") if r % 2 == 0 else ("overcast", "sun")
            for light in lights:
                base = scenario(5, frames, shadows=light == "sun")
                lux[light] = base.scene.lighting.illuminance_lux
                specs = {"ideal": base, "real": with_sensor(base, IMX273)}
                after = segmentation if light == "sun" else None
                step_in_turns(specs, frames, watches, pairs[light], after)
            specs = {"ideal": fast_scenario(frames), "auto": fast_scenario(frames, blur_sensor())}
            specs |= {str(n): fast_scenario(frames, blur_sensor(n)) for n in draws}
            step_in_turns(specs, frames, watches, blur)

    # The readout on the light of a rendered sun frame, at the exposure IMX273 chose there.
    sun = camera_summary(pairs["sun"]["real"])
    image = kept["image"]
    lit = linear_light(image)
    readout = Readout(IMX273)
    rate = electrons_per_second(IMX273, lux["sun"])
    exposure_s, gain = sun["exposure_p50_ms"] / 1e3, sun["gain_p50"]
    normals = NoisePool(np.random.default_rng(0))  # as a Sensor draws it once per run
    read_ms, linear_ms = [], []
    for _ in range(repeats):  # alternated, so both see the same host
        t0 = time.perf_counter()
        linear_light(image)
        t1 = time.perf_counter()
        readout.read(lit, rate, exposure_s, gain, normals)
        t2 = time.perf_counter()
        linear_ms.append(1e3 * (t1 - t0))
        read_ms.append(1e3 * (t2 - t1))

    res: dict[str, Any] = {"rounds": rounds, "lux": lux}
    for light, worlds in pairs.items():
        row = {name: camera_summary(rec) for name, rec in worlds.items()}
        ratios = np.array(worlds["real"]["step"]) / np.array(worlds["ideal"]["step"])
        row["paired_ratio_p50_x"] = float(np.percentile(ratios, 50))
        res[light] = row
    res["segmentation"] = {
        f"{k}_{q}_ms": float(np.percentile(v, p)) for k, v in seg.items()
        for q, p in (("p50", 50), ("p95", 95))
    }  # fmt: skip
    res["blur"] = {name: camera_summary(rec) for name, rec in blur.items()}
    res["blur_exposure_ms"] = BLUR_EXPOSURE_MS
    res["blur_speed_mps"] = FAST_SPEED
    res["readout"] = {
        "shape": list(lit.shape),
        "repeats": repeats,
        "exposure_ms": 1e3 * exposure_s,
        "gain": gain,
        "read_p50_ms": float(np.percentile(read_ms, 50)),
        "read_p95_ms": float(np.percentile(read_ms, 95)),
        "linear_light_p50_ms": float(np.percentile(linear_ms, 50)),
        "linear_light_p95_ms": float(np.percentile(linear_ms, 95)),
    }
    res["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return res


def night_scenarios(frames: int) -> dict[str, Any]:
    """The CPNA point by day and at night (imx273), at night through the ideal camera and
    through imx273 with one draw a frame, each cut to `frames` frames."""
    from dataclasses import replace

    from sim.scenario.ncap import Draw, GridPoint, load_car, load_protocol, scenario_for

    protocol, car = (
        load_protocol(ROOT / "scenarios/ncap/protocol.toml"),
        load_car(ROOT / "scenarios/ncap/car.toml"),
    )
    day, night = (
        scenario_for(protocol, car, GridPoint(test, "AEB", 40.0, 0.5), Draw.nominal())
        for test in ("cpna", "cpna-night")
    )
    cut = {name: replace(sc, duration=frames * sc.dt) for name, sc in
           (("day", day), ("night", night))}  # fmt: skip
    sensor = night.robot.camera.sensor
    cut["night_ideal"] = with_sensor(cut["night"], None)
    cut["night_one_draw"] = with_sensor(cut["night"], replace(sensor, max_subframes=1))
    return cut


def child_night(frames: int, rounds: int = 2) -> dict[str, Any]:
    """The night frame against the day frame (night_scenarios), stepped in turns."""
    import numpy as np

    if frames <= WARM_STEPS + 1:
        raise ValueError(f"frames must be more than {WARM_STEPS + 1}, got {frames}")
    recs: dict[str, CameraRecord] = {}
    with camera_parts() as watches:
        for _ in range(rounds):
            step_in_turns(night_scenarios(frames), frames, watches, recs)
    res: dict[str, Any] = {"rounds": rounds}
    for name, rec in recs.items():
        row = camera_summary(rec)
        ratios = np.array(rec["step"]) / np.array(recs["day"]["step"])
        row["paired_ratio_p50_x"] = float(np.percentile(ratios, 50))
        res[name] = row
    res["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return res


def night_report(got: dict[str, Any], frames: int) -> tuple[dict[str, Any], str]:
    """The night child's figures as history results and a Markdown table."""
    timed = frames - 1 - WARM_STEPS
    lines = [
        "Scenario: the Euro NCAP CPNA point at 40 km/h, impact 50 %, nominal draw "
        "(sim.scenario.ncap), 768x432, World.step with rendering on one core, the worlds "
        f"stepped in turns frame by frame, {timed} timed steps per world and round, "
        f"{got['rounds']} rounds. Night: low beams (2 cones), the nearside night road's "
        "lamps (5 lit, at most 5 shining a frame), 1 lux.",
        "",
        "| world | step p50 ms | step p95 ms | x day (paired p50) | render p50 ms | draws a "
        "frame (mean, max) | exposure p50 ms | gain p50 |",
        "|" + " --- |" * 8,
    ]
    results: dict[str, Any] = {}
    for name in ("day", "night", "night_ideal", "night_one_draw"):
        r = got[name]
        results[name] = r
        exposure = "-" if r["exposure_p50_ms"] is None else f"{r['exposure_p50_ms']:.2g}"
        gain = "-" if r["gain_p50"] is None else f"{r['gain_p50']:.0f}"
        lines.append(
            f"| {name} | {r['step_p50_ms']:.1f} | {r['step_p95_ms']:.1f} | "
            f"{r['paired_ratio_p50_x']:.2f} | {r['render_p50_ms']:.1f} | "
            f"{r['draws_mean']:.1f}, {r['draws_max']} | {exposure} | {gain} |"
        )
    results["maxrss_mb"] = got["maxrss_mb"]
    return results, "\n".join(lines)


def camera_report(got: dict[str, Any], frames: int) -> tuple[dict[str, Any], str]:
    """The camera child's figures as history results and a Markdown table."""
    import numpy as np

    timed_steps = frames - 1 - WARM_STEPS
    lines = [
        f"Scenario: bench/simulator.py `scenario(5)`, case 5 at 8 m (robot 2 m/s), 768x432; "
        f"the ideal camera (CameraSpec.sensor None) against IMX273 (auto exposure); World.step "
        f"with rendering on one core, the two worlds stepped in turns frame by frame (who goes "
        f"first alternating, each world with its own GL context), {timed_steps} timed steps "
        f"per world and round, {got['rounds']} round{'s' if got['rounds'] != 1 else ''}. "
        "The real camera's parts: "
        "sim.world.shutter.linear_light (once per draw), Sensor.read (noise, gain, digitiser, "
        "tone curve) and Scene.image_motion (which sets the draws).",
        "",
        "| lighting | real: exposure p50, gain, draws | ideal p50 | ideal p95 | real p50 "
        "| real p95 | real / ideal (p50s) | paired p50 | linear light | readout | image motion |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    results: dict[str, Any] = {"frames_per_world": frames, "rounds": got["rounds"],
                               "goal_x": CAMERA_GOAL_X, "pairs": []}  # fmt: skip
    verdicts = []
    for light in ("sun", "overcast"):
        ideal, real = got[light]["ideal"], got[light]["real"]
        ratio = real["step_p50_ms"] / ideal["step_p50_ms"]
        paired = got[light]["paired_ratio_p50_x"]
        results["pairs"].append(
            {
                "lighting": light,
                "illuminance_lux": got["lux"][light],
                "frames": ideal["frames"],
                "ideal_frame_p50_ms": ideal["step_p50_ms"],
                "ideal_frame_p95_ms": ideal["step_p95_ms"],
                "ideal_render_p50_ms": ideal["render_p50_ms"],
                "real_frame_p50_ms": real["step_p50_ms"],
                "real_frame_p95_ms": real["step_p95_ms"],
                "real_render_p50_ms": real["render_p50_ms"],
                "real_linear_light_p50_ms": real["linear_p50_ms"],
                "real_readout_p50_ms": real["readout_p50_ms"],
                "real_image_motion_p50_ms": real["motion_p50_ms"],
                "real_exposure_p50_ms": real["exposure_p50_ms"],
                "real_gain_p50": real["gain_p50"],
                "real_blur_p50_px": real["blur_p50_px"],
                "real_draws_mean": real["draws_mean"],
                "real_draws_max": real["draws_max"],
                "real_over_ideal_x": ratio,
                "paired_ratio_p50_x": paired,
            }
        )
        lines.append(
            f"| {light}, {got['lux'][light]:,.0f} lux | {real['exposure_p50_ms']:.2f} ms, "
            f"x{real['gain_p50']:.1f}, {real['draws_min']}-{real['draws_max']} "
            f"| {ideal['step_p50_ms']:.1f} ms | {ideal['step_p95_ms']:.1f} ms "
            f"| {real['step_p50_ms']:.1f} ms | {real['step_p95_ms']:.1f} ms | {ratio:.2f}x "
            f"| {paired:.2f}x | {real['linear_p50_ms']:.1f} ms | {real['readout_p50_ms']:.1f} ms "
            f"| {real['motion_p50_ms']:.2f} ms |"
        )
        verdicts.append(f"{light} {ratio:.2f}x ({'met' if ratio <= CAMERA_GOAL_X else 'not met'})")
    lines += ["", f"The real camera within {CAMERA_GOAL_X:g}x the ideal's frame time: "
              + "; ".join(verdicts) + "."]  # fmt: skip

    ro = got["readout"]
    results["readout"] = ro
    h, w, c = ro["shape"]
    lines += [
        "",
        f"Alone ({ro['repeats']} calls each, alternated): Readout.read on a {w}x{h}x{c} float32 "
        f"light image (a sun frame's light, IMX273 at {ro['exposure_ms']:.2f} ms, "
        f"x{ro['gain']:.1f}) p50 {ro['read_p50_ms']:.1f} ms (p95 {ro['read_p95_ms']:.1f}); "
        f"linear_light (8-bit to float32 by lookup) p50 {ro['linear_light_p50_ms']:.1f} ms "
        f"(p95 {ro['linear_light_p95_ms']:.1f}).",
    ]

    blur = got["blur"]
    forced = sorted(int(k) for k in blur if k.isdigit())
    ideal = blur["ideal"]
    lines += [
        "",
        f"Motion blur by sub-frames: the car scale (sim.scenario.families CAR) at "
        f"{got['blur_speed_mps']:g} m/s, overcast, IMX273 with a fixed "
        f"{got['blur_exposure_ms']:g} ms exposure at gain 1 (bench/simulator.py fast_scenario, "
        f"blur_sensor); the draws capped at each of {', '.join(map(str, forced))} beside the "
        f"preset's cap (draws from the image motion); all stepped in turns. Image motion over "
        f"the exposure p50 {blur['auto']['blur_p50_px']:.0f} px.",
        "",
        "| camera | draws a frame (mean; range) | frame p50 | frame p95 | render p50 "
        "| vs ideal (p50s) |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
        f"| ideal | 1 | {ideal['step_p50_ms']:.1f} ms | {ideal['step_p95_ms']:.1f} ms "
        f"| {ideal['render_p50_ms']:.1f} ms | 1.00x |",
    ]
    blur_rows = [{"camera": "ideal", "max_subframes": None, **_blur_row(ideal, ideal)}]
    for key in [*map(str, forced), "auto"]:
        row = blur[key]
        cap = f"at most {key}" if key != "auto" else "the preset's cap"
        blur_rows.append({"camera": key, "max_subframes": int(key) if key.isdigit() else None,
                          **_blur_row(row, ideal)})  # fmt: skip
        lines.append(
            f"| {got['blur_exposure_ms']:g} ms, {cap} | {row['draws_mean']:.2f} "
            f"({row['draws_min']}-{row['draws_max']}) | {row['step_p50_ms']:.1f} ms "
            f"| {row['step_p95_ms']:.1f} ms | {row['render_p50_ms']:.1f} ms "
            f"| {row['step_p50_ms'] / ideal['step_p50_ms']:.2f}x |"
        )
    results["blur"] = {"exposure_ms": got["blur_exposure_ms"], "speed_mps": got["blur_speed_mps"],
                       "rows": blur_rows}  # fmt: skip
    if len(forced) >= 2:
        x = [blur[str(n)]["draws_mean"] for n in forced]
        per_draw = float(np.polyfit(x, [blur[str(n)]["step_p50_ms"] for n in forced], 1)[0])
        renders = [blur[str(n)]["render_p50_ms"] for n in forced]
        render_per_draw = float(np.polyfit(x, renders, 1)[0])
        results["blur"]["per_draw_ms"] = per_draw
        results["blur"]["render_per_draw_ms"] = render_per_draw
        lines += [
            "",
            f"Each draw beyond the first: {per_draw:.1f} ms a frame, of which the render "
            f"{render_per_draw:.1f} ms (least-squares slopes over the capped rows).",
        ]

    sg = got["segmentation"]
    sun_ideal = got["sun"]["ideal"]
    floor = sg["masks_p50_ms"] + sg["depth_read_p50_ms"]
    results["segmentation"] = sg | {
        "step_render_p50_ms": sun_ideal["render_p50_ms"],
        "floor_p50_ms": floor,
        "floor_over_render_x": floor / sun_ideal["render_p50_ms"],
    }
    lines += [
        "",
        "The floor of a blur from a per-pixel motion field (MuJoCo gives none: a segmentation "
        "render and a depth read every frame), on the ideal camera's sun frames, after each "
        "timed step, of the same state:",
        "",
        "| per frame | p50 | p95 |",
        "| --- | ---: | ---: |",
        f"| colour render within World.step | {sun_ideal['render_p50_ms']:.1f} ms | |",
        f"| the same state drawn again in colour (SceneRenderer.render) "
        f"| {sg['render_again_p50_ms']:.1f} ms | {sg['render_again_p95_ms']:.1f} ms |",
        f"| segmentation render (World.person_masks) | {sg['masks_p50_ms']:.1f} ms "
        f"| {sg['masks_p95_ms']:.1f} ms |",
        f"| depth read of that draw (mjr_readPixels) | {sg['depth_read_p50_ms']:.1f} ms "
        f"| {sg['depth_read_p95_ms']:.1f} ms |",
        "",
        f"Segmentation and depth: {floor:.1f} ms a frame, "
        f"{floor / sun_ideal['render_p50_ms']:.2f}x the colour render, whatever moves.",
    ]
    results["peak_rss_mb"] = got["maxrss_mb"]
    return results, "\n".join(lines)


def _blur_row(row: dict[str, Any], ideal: dict[str, Any]) -> dict[str, Any]:
    return {
        "draws_mean": row["draws_mean"],
        "draws_min": row["draws_min"],
        "draws_max": row["draws_max"],
        "frame_p50_ms": row["step_p50_ms"],
        "frame_p95_ms": row["step_p95_ms"],
        "render_p50_ms": row["render_p50_ms"],
        "blur_p50_px": row["blur_p50_px"],
        "vs_ideal_x": row["step_p50_ms"] / ideal["step_p50_ms"],
    }


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
        "--camera-only", action="store_true",
        help="only a real camera's frame (sensor, motion blur) against the ideal camera's "
        "(its own history line)",
    )  # fmt: skip
    ap.add_argument(
        "--night-only", action="store_true",
        help="only a night frame (low beams, lamps, 1 lux) against the day frame (its own "
        "history line)",
    )  # fmt: skip
    ap.add_argument(
        "--child",
        choices=("render", "run", "sweep", "people", "crowd", "people_runs", "camera", "night"),
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
        elif args.child == "camera":
            out = child_camera(args.frames, args.rounds)
        elif args.child == "night":
            out = child_night(args.frames, args.rounds)
        elif args.child == "run":
            out = child_run(
                args.frames, bool(args.ablation), bool(args.shadows), args.model, args.runtime
            )
        else:
            out = child_sweep(args.frames, args.runs, args.workers)
        print(json.dumps(out))
        return

    parts = chosen_parts(args)
    if "people_runs" in parts:
        recorder = Recorder("simulator_people_runs", PEOPLE_RUNS_TITLE)
        counts = [n for n in args.people if n in RUN_PEOPLE] or list(RUN_PEOPLE)
        got = spawn_child("people_runs", True, frames=args.frames, rounds=args.rounds,
                          people=counts)  # fmt: skip
        results, table = people_runs_report(got, args.frames)
        print(table)
        recorder.finish(results, table, write=not args.no_append)
    if "main" in parts:
        main_rows(args)
    if "crowd" in parts:
        recorder = Recorder("simulator_crowd", CROWD_TITLE)
        results, table = crowd_report(spawn_child("crowd", True, frames=args.frames), args.frames)
        print(table)
        recorder.finish(results, table, write=not args.no_append)
    if "people" in parts:
        recorder = Recorder("simulator_people", PEOPLE_TITLE)
        people = spawn_child("people", True, frames=args.frames)
        results, table = people_report(people, args.frames)
        print(table)
        recorder.finish(results, table, write=not args.no_append)
    for part, title, report in (("camera", CAMERA_TITLE, camera_report),
                                ("night", NIGHT_TITLE, night_report)):  # fmt: skip
        if part in parts:
            recorder = Recorder(f"simulator_{part}", title)
            got = spawn_child(part, True, frames=args.frames, rounds=args.rounds)
            results, table = report(got, args.frames)
            print(table)
            recorder.finish(results, table, write=not args.no_append)


ONLY = ("people_runs", "crowd", "people", "camera", "night")  # the parts an `--X-only` option names


def chosen_parts(args: argparse.Namespace) -> set[str]:
    """The parts to run: those the `--X-only` options name, or every part (the render,
    whole-run and sweep rows, `main`, among them) when none is given."""
    named = {part for part in ONLY if getattr(args, f"{part}_only")}
    return named or {"main", *ONLY}


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
