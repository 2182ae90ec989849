"""One run: a scenario stepped through World, its frames through the real pipeline, side by side.

The pipeline sees only each Frame (pixels, timestamp, the robot's own state); the runner
alone holds the ground truth and writes both into one record per frame. The one
deliberate exception is the ablation: a second pipeline fed the true crop around the
pedestrian (`region=`), so that pose errors and decision errors can be told apart.

A run's result is one JSON-ready dict (a line of the sweep's results file): the
scenario's parameters, then per-frame columns (truth, each pipeline's features and every
predictor's decisions). Measured times live under "timing" only, so everything else is
identical whichever machine or executor ran it.
"""

from __future__ import annotations

import math
import os
import platform
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from monopic.pipeline import FrameResult
from monopic.pose.region import Region
from sim.runs.pipelines import make_pipeline
from sim.runs.run_spec import RunSpec
from sim.scenario.spec import Scenario
from sim.world.ground_truth import GroundTruth
from sim.world.render import RenderContext
from sim.world.world import World

SCHEMA = 1
STAGES = ("pose", "detect", "landmarks", "features", "predict", "warning", "total")
HIP_LANDMARKS = (23, 24)
SHOULDER_LANDMARKS = (11, 12)


def truth_region(truth: GroundTruth) -> Region | None:
    """The true crop, as MediaPipe would align it: centred on the hips, along the body axis."""
    if not truth.in_frame:
        return None
    px = truth.landmarks_px
    hip = px[list(HIP_LANDMARKS)].mean(axis=0)
    shoulder = px[list(SHOULDER_LANDMARKS)].mean(axis=0)
    height = truth.apparent_height
    axis = shoulder - hip
    norm = float(np.linalg.norm(axis))
    if not (np.all(np.isfinite(hip)) and math.isfinite(height) and height > 4 and norm > 0):
        return None
    top = hip + axis / norm * 0.5 * height
    region = Region.from_keypoints((float(hip[0]), float(hip[1])), (float(top[0]), float(top[1])))
    return region if region.valid else None


def _r(value: float | None, digits: int) -> float | None:
    """Rounded for compact lines; None for missing or non-finite values."""
    if value is None:
        return None
    value = float(value)
    return round(value, digits) if math.isfinite(value) else None


def _pt(values: Any, digits: int) -> list[float | None] | None:
    if values is None:
        return None
    out = [_r(v, digits) for v in values]
    return None if all(v is None for v in out) else out


class PipelineLog:
    """Per-frame columns of one pipeline's outputs (decisions by predictor key)."""

    def __init__(self) -> None:
        self.found: list[int] = []
        self.phi: list[float | None] = []
        self.foot: list[Any] = []
        self.height: list[float | None] = []
        self.detector_runs: list[int] = []
        self.ms: dict[str, list[float | None]] = {s: [] for s in STAGES}
        self.decisions: dict[str, dict[str, list[Any]]] = {}
        self.frames = 0

    def add(self, result: FrameResult | None) -> None:
        """One frame's result (None: the pipeline was not run on this frame)."""
        k = self.frames
        self.frames += 1
        feats = result.features if result is not None else None
        self.found.append(int(result is not None and result.pose.found))
        self.phi.append(_r(feats.phi, 2) if feats else None)
        self.foot.append(_pt(feats.foot, 1) if feats else None)
        self.height.append(_r(feats.apparent_height, 1) if feats else None)
        self.detector_runs.append(result.pose.detector_runs if result is not None else 0)
        for stage in STAGES:
            ms = result.stage_ms.get(stage) if result is not None else None
            self.ms[stage].append(_r(ms, 2))
        for d in result.decisions if result is not None else ():
            cols = self.decisions.setdefault(
                d.predictor, {"warn": [], "case": [], "foot": [], "ground": [], "ttc": []}
            )
            for col in cols.values():  # frames before this predictor's first decision
                col.extend([None] * (k - len(col)))
            cols["warn"].append(int(d.warning.collision))
            cols["case"].append(int(d.prediction.case))
            cols["foot"].append(_pt(d.prediction.foot, 1))
            cols["ground"].append(_pt(d.prediction.ground, 3))
            cols["ttc"].append(_r(d.warning.time_to_contact, 3))

    def outputs(self) -> dict[str, Any]:
        for cols in self.decisions.values():
            for col in cols.values():
                col.extend([None] * (self.frames - len(col)))
        return {
            "found": self.found,
            "phi": self.phi,
            "foot": self.foot,
            "height": self.height,
            "detector_runs": self.detector_runs,
            "decisions": self.decisions,
        }


class TruthLog:
    """Per-frame columns of the ground truth the metrics need."""

    def __init__(self) -> None:
        self.cols: dict[str, list[Any]] = {
            k: []
            for k in (
                "t", "ttc", "collision", "contact", "case", "phi", "range", "forward",
                "lateral", "height", "in_frame", "visible", "occluded", "foot", "future",
                "robot_speed",
            )
        }  # fmt: skip

    def add(self, truth: GroundTruth) -> None:
        c = self.cols
        c["t"].append(_r(truth.time, 4))
        c["ttc"].append(_r(truth.time_to_collision, 3))
        c["collision"].append(int(truth.collision))
        c["contact"].append(int(truth.contact))
        c["case"].append(int(truth.case))
        c["phi"].append(_r(truth.phi, 2))
        c["range"].append(_r(float(np.linalg.norm(truth.position_robot)), 2))
        c["forward"].append(_r(truth.position_robot[0], 2))
        c["lateral"].append(_r(truth.position_robot[1], 2))
        c["height"].append(_r(truth.apparent_height, 1))
        c["in_frame"].append(int(truth.in_frame))
        c["visible"].append(_r(truth.visible_fraction, 2))
        c["occluded"].append(int(truth.occluded))
        c["foot"].append(_pt(truth.foot_px, 1))
        c["future"].append(_pt(truth.future_position_robot, 3))
        c["robot_speed"].append(_r(truth.robot.speed, 3))


def scenario_summary(s: Scenario) -> dict[str, Any]:
    cam = s.robot.camera
    return {
        "name": s.name,
        "case": int(s.case) if s.case is not None else None,
        "robot_speed": s.robot.speed,
        "robot_width": s.robot.width,
        "robot_length": s.robot.length,
        "horizon": s.horizon,
        "dt": s.dt,
        "duration": s.duration,
        "camera": {
            "width": cam.width,
            "height": cam.height,
            "vertical_fov_deg": cam.vertical_fov_deg,
            "mount_height": cam.mount_height,
            "pitch_deg": cam.pitch_deg,
        },
        "pedestrian_height": s.pedestrian.looks.height,
        "pedestrian_speed": s.pedestrian.speed,
        "occluders": len(s.scene.occluders),
    }


def machine() -> dict[str, Any]:
    """What ran it, for the report's 'ran on' line."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next(
                (ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), cpu
            )
    except OSError:
        pass
    return {"host": platform.node(), "cpu": cpu, "cores": os.cpu_count()}


def run(
    spec: RunSpec,
    on_frame: Callable[[int], None] | None = None,
    render_context: RenderContext | None = None,
) -> dict[str, Any]:
    """Run one scenario through the pipeline(s); returns its result line (a dict).

    A worker running many scenarios lends each the same `render_context` (sim.world.render).
    """
    scenario = spec.scenario
    start = time.perf_counter()
    main = make_pipeline(scenario)
    ablation = make_pipeline(scenario, ablation=True) if spec.ablation else None
    truth_log, main_log = TruthLog(), PipelineLog()
    crop_log = PipelineLog() if ablation is not None else None
    sim_ms: list[float] = []
    contact_time = None
    recording_path = None
    with World(scenario, render=True, render_context=render_context) as world:
        recording = _start_recording(spec, world)
        t0 = time.perf_counter()
        step = world.reset()
        for k in range(scenario.frames):
            if k > 0:
                t0 = time.perf_counter()
                step = world.step()
            sim_ms.append((time.perf_counter() - t0) * 1e3)
            assert step.frame is not None
            truth_log.add(step.truth)
            result = main.process(step.frame)
            main_log.add(result)
            if recording is not None:
                recording.log_step(step, result)
            if ablation is not None and crop_log is not None:
                region = truth_region(step.truth)
                crop_log.add(ablation.process(step.frame, region) if region else None)
            if on_frame is not None:
                on_frame(k)
            if step.truth.contact:
                contact_time = step.truth.time
                if spec.stop_at_contact:
                    break
        if recording is not None:
            if spec.record == "all" or recording.went_wrong():
                recording.close()
                recording_path = recording_name(spec)
            else:
                recording.abort()
    pipelines = {"main": main_log.outputs()}
    timing_ms = {"main": main_log.ms}
    if crop_log is not None:
        pipelines["gtcrop"] = crop_log.outputs()
        timing_ms["gtcrop"] = crop_log.ms
    return {
        "schema": SCHEMA,
        "id": spec.id,
        "sweep": spec.sweep,
        "family": spec.family or scenario.family,
        "file": spec.file,
        "kind": spec.kind,
        "scale": spec.scale,
        "params": spec.params,
        "seed": scenario.seed,
        "code": spec.code or None,
        "scenario": scenario_summary(scenario),
        "frames": len(truth_log.cols["t"]),
        "contact_time": contact_time,
        "recording": recording_path,
        "truth": truth_log.cols,
        "pipelines": pipelines,
        "timing": {
            "wall_s": round(time.perf_counter() - start, 3),
            "sim_ms": [round(v, 2) for v in sim_ms],
            "ms": timing_ms,
            "machine": machine(),
        },
    }


def _start_recording(spec: RunSpec, world: World):
    """The run's .rrd recording when the spec asks for one (imported lazily: rerun-heavy)."""
    if spec.record == "none":
        return None
    if spec.record not in ("failed", "all"):
        raise ValueError(f"record must be none, failed or all, got {spec.record!r}")
    from sim.recording.sim_recording import SimRecording

    path = Path(spec.record_dir or "recordings") / recording_name(spec)
    path.parent.mkdir(parents=True, exist_ok=True)
    return SimRecording(path, world)


def recording_name(spec: RunSpec) -> str:
    """The run's recording, relative to the sweep's recordings folder (ids nest by family)."""
    return f"{spec.id}.rrd"


def deterministic_part(result: dict[str, Any]) -> dict[str, Any]:
    """The result without measured times: equal whichever executor or machine ran it."""
    return {k: v for k, v in result.items() if k != "timing"}
