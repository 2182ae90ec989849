"""A sweep's run replayed through the ground pipeline from its own foot points, no rendering.

A results line keeps, for every frame, the foot point the pipeline found and the robot's
speed. Replaying those through a ground-motion estimator, a point predictor and the real
collision warning (monopic's own code, as Pipeline.process calls it) asks "what would
this method have warned?" of hundreds of runs in seconds: studies.ground_motion.estimators
compares estimators this way, studies.intent.ceiling the intent rules given the truth's
intent, studies.intent.crossfit trees grown out of fold, studies.intent.foot_noise the foot
point's noise. The product never replays: this lives with the studies that do.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from monopic.camera import CameraModel
from monopic.features.record import Features, GroundFeatures
from monopic.features.swept_path import path_offset
from monopic.frame import EgoState
from monopic.predict.base import Mode, Prediction
from monopic.predict.registry import make_predictor
from monopic.variants.warning import CollisionWarning
from monopic.variants.zone import RobotGeometry
from sim.analysis.metrics import RunOutcome, judge_run
from sim.runs.result import MAIN, DecisionColumns, RunResult

MAX_GAP = 0.5  # s, FeatureExtractor.max_gap: a longer gap restarts the track
CAR_MOUNT_FORWARD = 0.8  # m, sim.scenario.families' car camera (not in the result line)


class Estimator(Protocol):
    """What a ground-motion estimator offers (monopic.features.ground.GroundMotion's)."""

    def observe_ego(self, t: float, ego: EgoState) -> None: ...
    def update(
        self, t: float, ego: EgoState, foot: tuple[float, float], height: float
    ) -> tuple[tuple[float, float], tuple[float, float]] | None: ...
    def reset_track(self) -> None: ...


@dataclass(frozen=True)
class ReplayFrame:
    """What a point predictor sees of one replayed frame (index k of the run's truth)."""

    k: int
    features: Features  # with ground features
    constant_velocity: Prediction


# The predicted point of a frame; None keeps constant velocity's prediction.
PointRule = Callable[[ReplayFrame], Prediction | None]


def camera(row: RunResult) -> CameraModel:
    """The run's camera as the pipeline had it."""
    c = row.scenario.camera
    forward = CAR_MOUNT_FORWARD if row.scale == "car" else 0.0
    return CameraModel.from_fov(
        c.width, c.height, c.vertical_fov_deg, c.mount_height, c.pitch_deg, forward
    )


def replay(
    row: RunResult, estimator: Estimator, point: PointRule | None = None
) -> tuple[list[int | None], list[tuple[float, float] | None]]:
    """Per frame: the warning (None without a pose) and the predicted ground point.

    Constant velocity's point unless `point` gives another prediction for the frame.
    """
    s = row.scenario
    cam, horizon = camera(row), s.horizon
    robot = RobotGeometry(width=s.robot_width, length=s.robot_length, front=s.robot_length / 2)
    warning = CollisionWarning(robot=robot)
    predictor = make_predictor("constant-velocity", Mode.GROUND)
    main, truth = row.pipelines[MAIN], row.truth
    size = (s.camera.width, s.camera.height)
    warn: list[int | None] = []
    ground: list[tuple[float, float] | None] = []
    last = None
    for k, t in enumerate(truth.t):
        ego = EgoState(cam, truth.robot_speed[k], 0.0)
        estimator.observe_ego(t, ego)
        if last is not None and t - last > MAX_GAP:
            estimator.reset_track()
            last = None
        foot = main.foot[k] if main.found[k] else None
        if foot is None:
            warn.append(None)
            ground.append(None)
            continue
        last = t
        got = estimator.update(t, ego, (foot[0], foot[1]), main.height[k] or 0.0)
        if got is None:
            warn.append(0)
            ground.append(None)
            continue
        side = path_offset(got[0], s.robot_width)
        gf = GroundFeatures(
            got[0], got[1], cam, path_offset=side.offset, path_distance=side.distance
        )
        feats = Features(t, (foot[0], foot[1]), (foot[0], foot[1]), 0.0, 0.0, 0.0, 0.0, gf)
        pred = predictor.predict(feats, horizon)
        if point is not None:
            pred = point(ReplayFrame(k, feats, pred)) or pred
        w = warning.assess(feats, pred, Mode.GROUND, size, ego)
        warn.append(int(w.collision))
        ground.append(pred.ground)
    return warn, ground


def judge_warnings(
    row: RunResult, warn: list[int | None], method: str, columns: DecisionColumns | None = None
) -> RunOutcome:
    """The run judged as if `method` had warned `warn` (frame by frame), with the sweep's
    own metrics; `columns` carries the method's other recorded columns, if any."""
    main = row.pipelines[MAIN]
    replayed = replace(columns or DecisionColumns(), warn=warn)
    return judge_run(
        replace(row, pipelines={MAIN: replace(main, decisions={method: replayed})}), method
    )


def ground_errors(row: RunResult, ground: list[tuple[float, float] | None]) -> list[float]:
    """Distances (m) from each predicted point to the true position one horizon later."""
    return [
        float(np.hypot(end[0] - fut[0], end[1] - fut[1]))
        for end, fut in zip(ground, row.truth.future, strict=True)
        if end is not None and fut is not None
    ]
