"""The whole pipeline for one camera stream: frame -> pose -> features -> prediction -> warning.

It sees pixels, timestamps and, when known, the robot's own state; nothing about the
pedestrians. One instance per stream (it keeps the tracks' state).

Two trackers feed it. By default (`PipelineConfig.people` None) the one-pedestrian
tracker, wired like MediaPipe's pose solution: the most confident person, followed until
lost. With `people` set, everyone in view (monopic.people.tracker): features, every
predictor and the warning run per person, and the robot's warning is the worst of
theirs, naming its person. A person whose landmarks wait for the budget keeps their last
decisions (for at most `FeatureExtractor.max_gap`), marked as not fresh.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from monopic.features.extractor import DEFAULT_GROUND_COLUMN, FeatureExtractor, GroundColumn
from monopic.features.record import Features
from monopic.frame import EgoState, Frame
from monopic.horizon import HORIZON_S
from monopic.people.box import Box, pose_box
from monopic.people.tracker import PeopleConfig, PeopleTracker
from monopic.pose.landmarks import Pose
from monopic.pose.region import Region
from monopic.pose.search import GroundBand
from monopic.pose.tracker import PoseResult, PoseTracker, TrackerConfig
from monopic.predict.base import Mode, Prediction, Predictor
from monopic.predict.rules import RulePredictor
from monopic.timing import StageTimer
from monopic.variants.path import PathProjection, project_path
from monopic.variants.warning import CollisionWarning, Risk, Warning


class Variant(StrEnum):
    """The paper's three demos."""

    WARNING = "warning"
    PATH = "path"
    DIRECTION = "direction"


@dataclass(frozen=True)
class PipelineConfig:
    horizon: float = HORIZON_S
    mode: Mode = Mode.IMAGE
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    warning: CollisionWarning = field(default_factory=CollisionWarning)
    ground_column: GroundColumn = DEFAULT_GROUND_COLUMN  # the ground point's image column
    # None: the one-pedestrian tracker; set: everyone in view (monopic.people.tracker).
    people: PeopleConfig | None = None

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


class Decided:
    """What a set of decisions says through its primary predictor (a person's, or the
    robot's: the frame's)."""

    decisions: tuple[Decision, ...]
    primary: str

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


@dataclass(frozen=True)
class PersonResult(Decided):
    """One person in one frame: identity, box, pose when run, features and decisions.

    `fresh` is False when the decisions are the person's last ones, carried while their
    landmarks wait for the budget (no features this frame)."""

    person_id: int
    box: Box
    pose: Pose | None
    features: Features | None
    decisions: tuple[Decision, ...]
    primary: str
    fresh: bool = True


@dataclass(frozen=True)
class FrameResult(Decided):
    """Everything the pipeline produced for one frame (pose may be absent).

    `decisions` holds one entry per predictor that could decide (ground-mode predictors
    need the camera model and a foot point below the horizon); the first predictor is
    the primary one, exposed as `prediction`, `warning` and `path`. `people` holds
    everyone seen (one at most with the one-pedestrian tracker); `pose`, `features` and
    `decisions` are those of `person_id`, the person whose warning is the robot's (the
    worst), or of no one.
    """

    frame_index: int
    timestamp: float
    pose: PoseResult
    features: Features | None
    decisions: tuple[Decision, ...]
    stage_ms: dict[str, float]
    image_size: tuple[int, int]
    primary: str = ""
    people: tuple[PersonResult, ...] = ()
    person_id: int | None = None


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
        # One tracker or the other: each loads its own model sessions.
        everyone = self.config.people is not None
        self.tracker = None if everyone else PoseTracker(self.config.tracker)
        self.people = PeopleTracker(self.config.tracker, self.config.people) if everyone else None
        self.reset()

    def reset(self) -> None:
        """Forget everyone (a cut in the video, a new sequence) but keep the loaded models:
        the tracks, and each person's features and last decisions, which would otherwise
        pass to whoever gets their identity next."""
        for tracker in (self.tracker, self.people):
            if tracker is not None:
                tracker.reset()
        self.features = self._extractor()
        self._extractors: dict[int, FeatureExtractor] = {}  # per person, everyone mode
        self._last: dict[int, tuple[float, tuple[Decision, ...]]] = {}  # their last decisions
        self._person_id = 0  # the one-pedestrian tracker's: a new one at each acquisition

    def _extractor(self) -> FeatureExtractor:
        return FeatureExtractor(
            robot_width=self.config.warning.robot.width, ground_column=self.config.ground_column
        )

    @property
    def primary(self) -> str:
        return predictor_key(self.predictors[0])

    def process(self, frame: Frame, region: Region | None = None) -> FrameResult:
        """Run every stage on one frame; `region` overrides detection (ablations only,
        one-pedestrian tracker)."""
        if self.people is not None:
            if region is not None:
                raise ValueError("a region override needs the one-pedestrian tracker")
            return self._process_everyone(frame)
        h, w = frame.image.shape[:2]
        timer = StageTimer()
        band = GroundBand.from_camera(frame.ego.camera) if frame.ego is not None else None
        assert self.tracker is not None
        pose = self.tracker.process(frame.image, region, band, frame.timestamp)
        timer.lap("pose")
        feats = self.features.update(frame.timestamp, pose.pose, h, frame.ego)
        timer.lap("features")
        decisions = self._decide(feats, (w, h), frame.ego, timer) if feats is not None else ()
        people: tuple[PersonResult, ...] = ()
        if pose.pose is not None:
            if pose.detector_runs > 0 or self._person_id == 0:
                self._person_id += 1  # acquired afresh: perhaps someone else
            people = (
                PersonResult(
                    self._person_id, pose_box(pose.pose), pose.pose, feats, decisions,
                    self.primary,
                ),
            )  # fmt: skip
        return FrameResult(
            frame.index, frame.timestamp, pose, feats, decisions, _stage_ms(timer, pose),
            (w, h), self.primary, people, people[0].person_id if people else None,
        )  # fmt: skip

    def _decide(
        self,
        feats: Features,
        size: tuple[int, int],
        ego: EgoState | None,
        timer: StageTimer,
    ) -> tuple[Decision, ...]:
        """Every predictor's prediction, warning and projected path on one person's features."""
        decisions = []
        for predictor in self.predictors:
            if predictor.mode is Mode.GROUND and feats.ground is None:
                continue
            prediction = predictor.predict(feats, self.config.horizon)
            timer.lap("predict")
            warning = self.config.warning.assess(feats, prediction, predictor.mode, size, ego)
            path = project_path(feats, prediction, warning.zone)
            timer.lap("warning")
            decisions.append(
                Decision(predictor_key(predictor), predictor.mode, prediction, warning, path)
            )
        return tuple(decisions)

    def _process_everyone(self, frame: Frame) -> FrameResult:
        assert self.people is not None
        h, w = frame.image.shape[:2]
        t = frame.timestamp
        timer = StageTimer()
        band = GroundBand.from_camera(frame.ego.camera) if frame.ego is not None else None
        seen = self.people.process(frame.image, t, band)
        timer.lap("pose")
        people = []
        for sighting in seen.sightings:
            pid = sighting.person_id
            extractor = self._extractors.setdefault(pid, self._extractor())
            feats = extractor.update(t, sighting.pose, h, frame.ego)
            timer.lap("features")
            if feats is not None:
                decisions, fresh = self._decide(feats, (w, h), frame.ego, timer), True
                self._last[pid] = (t, decisions)
            else:
                when, decisions = self._last.get(pid, (t, ()))
                decisions = decisions if t - when <= extractor.max_gap else ()
                fresh = False
            people.append(
                PersonResult(
                    pid, sighting.box, sighting.pose, feats, decisions, self.primary, fresh
                )
            )
        present = {p.person_id for p in people}
        for pid in [pid for pid in self._extractors if pid not in present]:
            del self._extractors[pid]  # gone: an identity never comes back
            self._last.pop(pid, None)
        worst = worst_for(people, self.primary)
        pose = PoseResult(
            worst.pose if worst is not None else None,
            seen.detector_runs,
            seen.detect_ms,
            seen.landmark_ms,
        )
        return FrameResult(
            frame.index, t, pose, worst.features if worst else None,
            worst.decisions if worst else (), _stage_ms(timer, pose), (w, h), self.primary,
            tuple(people), worst.person_id if worst else None,
        )  # fmt: skip


RISK_ORDER = {Risk.GREEN: 0, Risk.YELLOW: 1, Risk.RED: 2}


def worst_for(people: Sequence[PersonResult], key: str) -> PersonResult | None:
    """The person whose warning by predictor `key` is the robot's: the highest risk, then
    the soonest collision, then a fresh decision over a carried one; people without that
    predictor's decision only when no one has one (then the first seen with a pose).

    The pipeline's robot warning is the primary predictor's worst person; each other
    predictor's robot warning is its own worst person (how sweeps compare predictors)."""

    def rank(p: PersonResult) -> tuple:
        d = p.decision(key)
        w = d.warning if d is not None else None
        ttc = w.time_to_contact if w is not None and w.time_to_contact is not None else np.inf
        return (w is not None, RISK_ORDER[w.risk] if w else -1, -ttc, p.fresh, p.pose is not None)

    return max(people, key=rank, default=None)


def _stage_ms(timer: StageTimer, pose: PoseResult) -> dict[str, float]:
    stage_ms = dict(timer.laps)
    stage_ms["detect"] = pose.detect_ms
    stage_ms["landmarks"] = pose.landmark_ms
    stage_ms["total"] = sum(
        stage_ms.get(k, 0.0) for k in ("pose", "features", "predict", "warning")
    )
    return stage_ms
