"""Listeners that turn a run's frames into its result columns (sim.runs.result), rounded.

Values are rounded where they are written so result lines stay compact; a missing or
non-finite value is None.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monopic.pipeline import FrameResult
from sim.runs.loop import Listener, LoopFrame
from sim.runs.result import DecisionColumns, PipelineColumns, TruthColumns
from sim.world.ground_truth import GroundTruth

STAGES = ("pose", "detect", "landmarks", "features", "predict", "warning", "total")


def rounded(value: float | None, digits: int) -> float | None:
    """Rounded for compact lines; None for missing or non-finite values."""
    if value is None:
        return None
    value = float(value)
    return round(value, digits) if math.isfinite(value) else None


def rounded_point(values: Any, digits: int) -> list[float | None] | None:
    if values is None:
        return None
    out = [rounded(v, digits) for v in values]
    return None if all(v is None for v in out) else out


@dataclass
class TruthRecorder(Listener):
    """The truth's columns, frame by frame."""

    columns: TruthColumns = field(default_factory=TruthColumns)

    def frame(self, frame: LoopFrame) -> None:
        self.add(frame.truth)

    def add(self, truth: GroundTruth) -> None:
        c, p = self.columns, truth.pedestrian  # the scenario's pedestrian
        c.t.append(rounded(truth.time, 4))
        c.ttc.append(rounded(p.time_to_collision, 3))
        c.collision.append(int(p.collision))
        c.contact.append(int(p.contact))
        c.case.append(int(p.case))
        c.phi.append(rounded(p.phi, 2))
        c.range.append(rounded(float(np.linalg.norm(p.position_robot)), 2))
        c.forward.append(rounded(p.position_robot[0], 2))
        c.lateral.append(rounded(p.position_robot[1], 2))
        c.height.append(rounded(p.apparent_height, 1))
        c.in_frame.append(int(p.in_frame))
        c.visible.append(rounded(p.visible_fraction, 2))
        c.occluded.append(int(p.occluded))
        c.foot.append(rounded_point(p.foot_px, 1))
        c.future.append(rounded_point(p.future_position_robot, 3))
        c.robot_speed.append(rounded(truth.robot.speed, 3))
        c.head_yaw.append(rounded(math.degrees(p.head_yaw_shoulders), 1))
        c.head_yaw_camera.append(rounded(math.degrees(p.head_yaw_camera), 1))
        c.intent.append(p.intent.value)
        c.case_now.append(int(p.case_now))


@dataclass
class PipelineRecorder(Listener):
    """One on-board pipeline's columns and its stage times (ms), frame by frame."""

    pipeline: str
    columns: PipelineColumns = field(default_factory=PipelineColumns)
    ms: dict[str, list[float | None]] = field(default_factory=lambda: {s: [] for s in STAGES})
    frames: int = 0

    def frame(self, frame: LoopFrame) -> None:
        self.add(frame.results.get(self.pipeline))

    def add(self, result: FrameResult | None) -> None:
        """One frame's result (None: the pipeline was not run on this frame)."""
        c, k = self.columns, self.frames
        self.frames += 1
        feats = result.features if result is not None else None
        c.found.append(int(result is not None and result.pose.found))
        c.phi.append(rounded(feats.phi, 2) if feats else None)
        c.foot.append(rounded_point(feats.foot, 1) if feats else None)
        c.height.append(rounded(feats.apparent_height, 1) if feats else None)
        c.detector_runs.append(result.pose.detector_runs if result is not None else 0)
        for stage in STAGES:
            ms = result.stage_ms.get(stage) if result is not None else None
            self.ms[stage].append(rounded(ms, 2))
        for d in result.decisions if result is not None else ():
            cols = c.decisions.setdefault(d.predictor, DecisionColumns())
            for col in _columns(cols):  # frames before this predictor's first decision
                col.extend([None] * (k - len(col)))
            cols.warn.append(int(d.warning.collision))
            cols.case.append(int(d.prediction.case))
            cols.foot.append(rounded_point(d.prediction.foot, 1))
            cols.ground.append(rounded_point(d.prediction.ground, 3))
            cols.ttc.append(rounded(d.warning.time_to_contact, 3))
            if d.prediction.intent is not None or cols.intent:  # only predictors stating one
                cols.intent.extend([None] * (k - len(cols.intent)))
                cols.intent.append(d.prediction.intent)

    def finished(self) -> PipelineColumns:
        """The columns, every predictor's padded to the frames run."""
        for cols in self.columns.decisions.values():
            for col in _columns(cols):
                col.extend([None] * (self.frames - len(col)))
            if cols.intent:
                cols.intent.extend([None] * (self.frames - len(cols.intent)))
        return self.columns


def _columns(cols: DecisionColumns) -> tuple[list[Any], ...]:
    return (cols.warn, cols.case, cols.foot, cols.ground, cols.ttc)
