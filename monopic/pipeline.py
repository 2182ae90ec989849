"""The whole pipeline for one camera stream: frame -> pose -> features -> prediction -> warning.

It sees pixels, timestamps and, when known, the robot's own state; nothing about the
pedestrian. One instance per stream (it keeps the track's state).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

from monopic.features.extractor import DEFAULT_GROUND_COLUMN, FeatureExtractor, GroundColumn
from monopic.features.record import Features
from monopic.frame import Frame
from monopic.pose.region import Region
from monopic.pose.search import GroundBand
from monopic.pose.tracker import PoseResult, PoseTracker, TrackerConfig
from monopic.predict.base import Mode, Prediction, Predictor
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
    ground_column: GroundColumn = DEFAULT_GROUND_COLUMN  # the ground point's image column

    def __post_init__(self) -> None:
        if not self.horizon > 0:
            raise ValueError(f"horizon must be positive seconds, got {self.horizon}")


@dataclass(frozen=True)
class Decision:
    """One predictor's verdict on a frame: prediction, warning and projected path."""

    predictor: str  # "name/mode", e.g. "rules/image"
    mode: Mode
    prediction: Prediction
    warning: Warning
    path: PathProjection


@dataclass(frozen=True)
class FrameResult:
    """Everything the pipeline produced for one frame (pose may be absent).

    `decisions` holds one entry per predictor that could decide (ground-mode predictors
    need the camera model and a foot point below the horizon); the first predictor is
    the primary one, exposed as `prediction`, `warning` and `path`.
    """

    frame_index: int
    timestamp: float
    pose: PoseResult
    features: Features | None
    decisions: tuple[Decision, ...]
    stage_ms: dict[str, float]
    image_size: tuple[int, int]
    primary: str = ""

    def decision(self, key: str) -> Decision | None:
        return next((d for d in self.decisions if d.predictor == key), None)

    @property
    def prediction(self) -> Prediction | None:
        d = self.decision(self.primary)
        return d.prediction if d else None

    @property
    def warning(self) -> Warning | None:
        d = self.decision(self.primary)
        return d.warning if d else None

    @property
    def path(self) -> PathProjection | None:
        d = self.decision(self.primary)
        return d.path if d else None


def predictor_key(predictor: Predictor) -> str:
    return f"{predictor.name}/{predictor.mode}"


class Pipeline:
    """Pose and features once per frame, then every predictor side by side.

    Running several predictors (and both modes) on the same pose is how sweeps compare
    them fairly: the expensive stage is shared, the decisions differ only by the method.
    """

    def __init__(
        self,
        config: PipelineConfig | None = None,
        predictors: Predictor | Sequence[Predictor] | None = None,
    ):
        self.config = config or PipelineConfig()
        if predictors is None:
            predictors = [RulePredictor(mode=self.config.mode)]
        elif not isinstance(predictors, Sequence):
            predictors = [predictors]
        if not predictors:
            raise ValueError("a pipeline needs at least one predictor")
        self.predictors = list(predictors)
        keys = [predictor_key(p) for p in self.predictors]
        if len(set(keys)) != len(keys):
            raise ValueError(f"predictors must differ by name or mode, got {keys}")
        self.tracker = PoseTracker(self.config.tracker)
        self.features = FeatureExtractor(
            robot_width=self.config.warning.robot.width, ground_column=self.config.ground_column
        )

    @property
    def primary(self) -> str:
        return predictor_key(self.predictors[0])

    def process(self, frame: Frame, region: Region | None = None) -> FrameResult:
        """Run every stage on one frame; `region` overrides detection (ablations only)."""
        h, w = frame.image.shape[:2]
        timer = StageTimer()
        band = GroundBand.from_camera(frame.ego.camera) if frame.ego is not None else None
        pose = self.tracker.process(frame.image, region, band, frame.timestamp)
        timer.lap("pose")
        feats = self.features.update(frame.timestamp, pose.pose, h, frame.ego)
        timer.lap("features")
        decisions = []
        for predictor in self.predictors if feats is not None else ():
            if predictor.mode is Mode.GROUND and feats.ground is None:
                continue
            prediction = predictor.predict(feats, self.config.horizon)
            timer.lap("predict")
            warning = self.config.warning.assess(
                feats, prediction, predictor.mode, (w, h), frame.ego
            )
            path = project_path(feats, prediction, warning.zone)
            timer.lap("warning")
            decisions.append(
                Decision(predictor_key(predictor), predictor.mode, prediction, warning, path)
            )
        stage_ms = dict(timer.laps)
        stage_ms["detect"] = pose.detect_ms
        stage_ms["landmarks"] = pose.landmark_ms
        stage_ms["total"] = sum(
            stage_ms.get(k, 0.0) for k in ("pose", "features", "predict", "warning")
        )
        return FrameResult(
            frame.index, frame.timestamp, pose, feats, tuple(decisions), stage_ms, (w, h),
            self.primary,
        )  # fmt: skip
