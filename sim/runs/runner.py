"""One sweep run: a scenario through the run loop, the real pipeline and its ablation side by side.

The pipeline sees only each Frame (pixels, timestamp, the robot's own state); the runner
alone holds the ground truth and writes both into one record (sim.runs.result.RunResult,
a line of the sweep's results file). The one deliberate exception is the ablation: a
second pipeline fed the true crop around the pedestrian, so that pose errors and
decision errors can be told apart.
"""

from __future__ import annotations

import math
import os
import platform
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from monopic.pose.region import Region
from monopic.pose.tracker import TrackerConfig
from sim.runs.columns import PipelineRecorder, TruthRecorder
from sim.runs.loop import Listener, OnBoard, Progress, StepTimes, run_loop
from sim.runs.pipelines import make_pipeline
from sim.runs.result import (
    ABLATION,
    MAIN,
    CameraSummary,
    Machine,
    RunResult,
    ScenarioSummary,
    Timing,
    TrackColumns,
)
from sim.runs.run_spec import EVERYONE, RunSpec
from sim.scenario.spec import Scenario
from sim.world.ground_truth import GroundTruth
from sim.world.render import RenderContext
from sim.world.world import World

HIP_LANDMARKS = (23, 24)
SHOULDER_LANDMARKS = (11, 12)


def truth_region(truth: GroundTruth) -> Region | None:
    """The true crop, as MediaPipe would align it: centred on the hips, along the body axis."""
    if not truth.pedestrian.in_frame:
        return None
    px = truth.pedestrian.landmarks_px
    hip = px[list(HIP_LANDMARKS)].mean(axis=0)
    shoulder = px[list(SHOULDER_LANDMARKS)].mean(axis=0)
    height = truth.pedestrian.apparent_height
    axis = shoulder - hip
    norm = float(np.linalg.norm(axis))
    if not (np.all(np.isfinite(hip)) and math.isfinite(height) and height > 4 and norm > 0):
        return None
    top = hip + axis / norm * 0.5 * height
    region = Region.from_keypoints((float(hip[0]), float(hip[1])), (float(top[0]), float(top[1])))
    return region if region.valid else None


def scenario_summary(s: Scenario) -> ScenarioSummary:
    cam = s.robot.camera
    return ScenarioSummary(
        name=s.name,
        case=int(s.case) if s.case is not None else None,
        robot_speed=s.robot.speed,
        robot_width=s.robot.width,
        robot_length=s.robot.length,
        horizon=s.horizon,
        dt=s.dt,
        duration=s.duration,
        camera=CameraSummary(
            width=cam.width,
            height=cam.height,
            vertical_fov_deg=cam.vertical_fov_deg,
            mount_height=cam.mount_height,
            pitch_deg=cam.pitch_deg,
        ),
        pedestrian_height=s.pedestrian.looks.height,
        pedestrian_speed=s.pedestrian.speed,
        occluders=len(s.scene.occluders),
        behaviour=s.pedestrian.behaviour.model,
        cues=s.pedestrian.behaviour.cues,
        lighting=s.scene.lighting.name,
    )


def machine() -> Machine:
    """What ran it, for the report's 'ran on' line."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next(
                (ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), cpu
            )
    except OSError:
        pass
    return Machine(host=platform.node(), cpu=cpu, cores=os.cpu_count())


def run(
    spec: RunSpec,
    on_frame: Callable[[int], None] | None = None,
    render_context: RenderContext | None = None,
    tracker: TrackerConfig | None = None,
) -> RunResult:
    """Run one scenario through the pipeline(s); returns its result record.

    A worker running many scenarios lends each the same `render_context` (sim.world.render).
    `tracker` replaces the sweep's default tracker (bench/simulator.py times runtimes).
    """
    scenario = spec.scenario
    start = time.perf_counter()
    tree = Path(spec.intent_tree) if spec.intent_tree else None
    main = make_pipeline(scenario, intent_tree=tree, tracker=tracker, follows=spec.tracker)
    onboard = [OnBoard(MAIN, main)]
    if spec.ablation:
        ablation = make_pipeline(scenario, ablation=True, intent_tree=tree, tracker=tracker)
        onboard.append(OnBoard(ABLATION, ablation, truth_region))
    everyone = spec.tracker == EVERYONE
    truth = TruthRecorder(every_person=everyone)
    recorders = {board.name: PipelineRecorder(board.name) for board in onboard}
    if everyone:
        recorders[MAIN].tracks = TrackColumns()
    times = StepTimes()
    listeners: list[Listener] = [truth, *recorders.values(), times]
    recording_path = None
    with World(scenario, render=True, render_context=render_context) as world:
        recording = _start_recording(spec, world)
        if recording is not None:
            from sim.runs.record import Recorder

            listeners.append(Recorder(recording))
        if on_frame is not None:
            listeners.append(Progress(on_frame))
        try:
            end = run_loop(
                world, onboard, listeners, frames=scenario.frames,
                stop_at_contact=spec.stop_at_contact,
            )  # fmt: skip
        except BaseException:
            # A failed run is reported and the worker goes on: its partial recording goes.
            if recording is not None:
                recording.abort()
            raise
        if recording is not None:
            if spec.record == "all" or recording.went_wrong():
                recording.close()
                recording_path = recording_name(spec)
            else:
                recording.abort()
    return RunResult(
        id=spec.id,
        sweep=spec.sweep,
        family=spec.family or scenario.family,
        file=spec.file,
        kind=spec.kind,
        scale=spec.scale,
        params=spec.params,
        seed=scenario.seed,
        code=spec.code or None,
        scenario=scenario_summary(scenario),
        frames=end.frames,
        contact_time=end.contact_time,
        recording=recording_path,
        truth=truth.columns,
        people=truth.people,
        first_threat=truth.first_threat,
        pipelines={name: r.finished() for name, r in recorders.items()},
        tracker=EVERYONE if everyone else "",
        tracks={n: r.tracks for n, r in recorders.items() if r.tracks is not None},
        camera=_camera_of(scenario),
        exposure=truth.exposure,
        timing=Timing(
            wall_s=round(time.perf_counter() - start, 3),
            sim_ms=[round(v, 2) for v in times.ms],
            ms={name: r.ms for name, r in recorders.items()},
            machine=machine(),
        ),
    )


def _camera_of(scenario: Scenario) -> str:
    """The line's `camera`: a real camera's sensor preset, "" for the ideal camera."""
    sensor = scenario.robot.camera.sensor
    return "" if sensor is None else sensor.name


def _start_recording(spec: RunSpec, world: World):
    """The run's .rrd recording when the spec asks for one (imported lazily: rerun-heavy)."""
    if spec.record == "none":
        return None
    if spec.record not in ("failed", "all"):
        raise ValueError(f"record must be none, failed or all, got {spec.record!r}")
    from sim.recording.sim_recording import SimRecording

    folder = Path(spec.record_dir or "recordings")
    path = Path(spec.record_file) if spec.record_file else folder / recording_name(spec)
    path.parent.mkdir(parents=True, exist_ok=True)
    return SimRecording(path, world)


def recording_name(spec: RunSpec) -> str:
    """The run's recording, relative to the sweep's recordings folder (ids nest by family),
    or the file a rerun was asked to write."""
    return spec.record_file or f"{spec.id}.rrd"
