"""The whole pipeline for one camera stream: frame -> pose -> features -> prediction -> warning.

It sees pixels, timestamps and, when known, the robot's own state; nothing about the
pedestrian. One instance per stream (it keeps the track's state).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from monopic.features.extractor import FeatureExtractor
from monopic.frame import Frame
from monopic.pose.region import Region
from monopic.pose.tracker import PoseResult, PoseTracker, TrackerConfig
from monopic.predict.base import Features, Mode, Prediction, Predictor
from monopic.predict.rules import RulePredictor
from monopic.timing import StageTimer
from monopic.variants.path import PathProjection, project_path
from monopic.variants.warning import CollisionWarning, Warning


class Variant(StrEnum):
    """The paper's three demos."""

    WARNING = "warning"
    PATH = "path"
    DIRECTION = "direction"


@dataclass(frozen=True)
class PipelineConfig:
    horizon: float = 1.0
    mode: Mode = Mode.IMAGE
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    warning: CollisionWarning = field(default_factory=CollisionWarning)

    def __post_init__(self) -> None:
        if not self.horizon > 0:
            raise ValueError(f"horizon must be positive seconds, got {self.horizon}")


@dataclass(frozen=True)
class FrameResult:
    """Everything the pipeline produced for one frame (pose may be absent)."""

    frame_index: int
    timestamp: float
    pose: PoseResult
    features: Features | None
    prediction: Prediction | None
    warning: Warning | None
    path: PathProjection | None
    stage_ms: dict[str, float]
    image_size: tuple[int, int]


class Pipeline:
    def __init__(self, config: PipelineConfig | None = None, predictor: Predictor | None = None):
        self.config = config or PipelineConfig()
        self.predictor = predictor or RulePredictor(mode=self.config.mode)
        if self.predictor.mode is not self.config.mode:
            raise ValueError(
                f"predictor {self.predictor.name} works in {self.predictor.mode} mode, "
                f"the pipeline in {self.config.mode} mode"
            )
        self.tracker = PoseTracker(self.config.tracker)
        self.features = FeatureExtractor()

    def process(self, frame: Frame, region: Region | None = None) -> FrameResult:
        """Run every stage on one frame; `region` overrides detection (ablations only)."""
        h, w = frame.image.shape[:2]
        timer = StageTimer()
        pose = self.tracker.process(frame.image, region)
        timer.lap("pose")
        feats = self.features.update(frame.timestamp, pose.pose, h, frame.ego)
        timer.lap("features")
        prediction = warning = path = None
        if feats is not None and (self.config.mode is Mode.IMAGE or feats.ground is not None):
            prediction = self.predictor.predict(feats, self.config.horizon)
            timer.lap("predict")
            warning = self.config.warning.assess(
                feats, prediction, self.config.mode, (w, h), frame.ego
            )
            path = project_path(feats, prediction, warning.zone)
            timer.lap("warning")
        stage_ms = dict(timer.laps)
        stage_ms["detect"] = pose.detect_ms
        stage_ms["landmarks"] = pose.landmark_ms
        stage_ms["total"] = sum(
            stage_ms.get(k, 0.0) for k in ("pose", "features", "predict", "warning")
        )
        return FrameResult(
            frame.index, frame.timestamp, pose, feats, prediction, warning, path, stage_ms, (w, h)
        )
