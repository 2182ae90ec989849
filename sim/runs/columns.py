"""Listeners that turn a run's frames into its result columns (sim.runs.result), rounded.

Values are rounded where they are written so result lines stay compact; a missing or
non-finite value is None.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monopic.pipeline import Decision, FrameResult, worst_for
from sim.runs.loop import Listener, LoopFrame
from sim.runs.result import (
    DecisionColumns,
    ExposureColumns,
    PersonColumns,
    PipelineColumns,
    TrackColumns,
    TruthColumns,
)
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
    """The truth's columns, frame by frame: the scripted person's, and with several people
    every person's and who was first on a collision course."""

    columns: TruthColumns = field(default_factory=TruthColumns)
    people: list[PersonColumns] = field(default_factory=list)
    first_threat: str | None = None
    # Every person's columns even with one person: the people tracker's warnings are
    # matched to people by their boxes (sim.analysis.people).
    every_person: bool = False
    exposure: ExposureColumns | None = None  # a real camera's, frame by frame

    def frame(self, frame: LoopFrame) -> None:
        self.add(frame.truth)
        if frame.truth.camera is not None:
            self.add_exposure(frame.truth)
        if len(frame.truth.people) > 1 or self.every_person:
            self.add_people(frame.truth)

    def add_exposure(self, truth: GroundTruth) -> None:
        state = truth.camera
        assert state is not None
        e = self.exposure = self.exposure or ExposureColumns()
        e.exposure_ms.append(rounded(1000.0 * state.exposure_s, 4))
        e.gain.append(rounded(state.gain, 3))
        e.subframes.append(int(state.subframes))
        e.signal.append(rounded(state.signal, 4))

    def add_people(self, truth: GroundTruth) -> None:
        if not self.people:
            self.people = [PersonColumns(p.name, k == 0) for k, p in enumerate(truth.people)]
        for c, p in zip(self.people, truth.people, strict=True):
            c.collision.append(int(p.collision))
            c.contact.append(int(p.contact))
            c.ttc.append(rounded(p.time_to_collision, 3))
            c.case.append(int(p.case))
            c.forward.append(rounded(p.position_robot[0], 2))
            c.lateral.append(rounded(p.position_robot[1], 2))
            c.in_frame.append(int(p.in_frame))
            c.box.append(rounded_point(p.box, 1))
            seen = p.visibility
            c.visible_box.append(None if seen is None else rounded_point(seen.box, 1))
            c.visible.append(None if seen is None else rounded(seen.visible, 3))
            hidden = {} if seen is None else seen.hidden_by
            c.hidden_by_people.append(rounded(hidden.get("person"), 3))
            c.hidden_by_cars.append(rounded(hidden.get("parked car"), 3))
            c.hidden_by_scene.append(rounded(hidden.get("scene"), 3))
            c.outside_frame.append(None if seen is None else rounded(seen.outside_frame, 3))
        if self.first_threat is None:  # the first frame anyone is on course; scripted first
            self.first_threat = next((p.name for p in truth.people if p.collision), None)

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
    # Set for a pipeline with the people tracker: its tracks, and each predictor's
    # columns are those of that predictor's worst person (monopic.pipeline.worst_for).
    tracks: TrackColumns | None = None

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
        for d in self._decisions(result):
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

    def _decisions(self, result: FrameResult | None) -> list[Decision]:
        """The robot's decision per predictor; with the people tracker, each predictor's
        worst person's, whose identity goes into the track columns."""
        if result is None:
            if self.tracks is not None:
                self.tracks.boxes.append([])
            return []
        if self.tracks is None:
            return list(result.decisions)
        self.tracks.boxes.append(
            [[p.person_id, *(rounded(v, 1) for v in p.box)] for p in result.people]
        )
        keys = list(dict.fromkeys(d.predictor for p in result.people for d in p.decisions))
        decisions = []
        for key in keys:
            person = worst_for(result.people, key)
            d = person.decision(key) if person is not None else None
            if d is None:
                continue
            column = self.tracks.warned_for.setdefault(key, [])
            column.extend([None] * (self.frames - 1 - len(column)))
            column.append(person.person_id if d.warning.collision else None)  # type: ignore[union-attr]
            decisions.append(d)
        return decisions

    def finished(self) -> PipelineColumns:
        """The columns, every predictor's padded to the frames run."""
        for cols in self.columns.decisions.values():
            for col in _columns(cols):
                col.extend([None] * (self.frames - len(col)))
            if cols.intent:
                cols.intent.extend([None] * (self.frames - len(cols.intent)))
        if self.tracks is not None:
            for column in self.tracks.warned_for.values():
                column.extend([None] * (self.frames - len(column)))
        return self.columns


def _columns(cols: DecisionColumns) -> tuple[list[Any], ...]:
    return (cols.warn, cols.case, cols.foot, cols.ground, cols.ttc)
