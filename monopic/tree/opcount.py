"""Operations per prediction, beside the paper's "23 calculations per prediction".

One prediction = discretisation (counted by the binners as they run) + one test per tree
node visited + the arithmetic that places the predicted point. The whole stage after
pose adds the facing angle (look-at, quaternion, theta, phi as in
monopic/features/orientation.py), its Kalman filter, the velocity estimate
(monopic/features/motion.py with a full window) and the warning check.

The counts for orientation, Kalman and velocity are read off the code line by line (see
the comments); tests pin them so a change to those modules must update them here. The
warning variant is not in this tree yet: it is counted as the paper describes it, the
predicted point tested against the robot's zone (an axis-aligned box: 4 comparisons)
and a risk level from the apparent size (2 threshold comparisons).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from monopic.cases import Case
from monopic.features.record import Features
from monopic.predict.base import Mode
from monopic.tree.model import (
    GAIN_PLACEMENT_OPS,
    LEAF_PLACEMENT_OPS,
    LeafValue,
    Placement,
    TreePredictor,
    extrapolation_ops,
)
from monopic.tree.ops import Ops

PAPER_CALCULATIONS_PER_PREDICTION = 23

# look_at: f = target - eye (3 sub); |f| (3 mul, 2 add, sqrt); |f| < eps (1 cmp);
# f /= |f| (3 div); s = f x up (6 mul, 3 sub); |s| (3 mul, 2 add, sqrt); |s| < eps (1 cmp);
# s /= |s| (3 div); u = s x f (6 mul, 3 sub); -f in the third row (3 neg).
LOOK_AT_OPS = Ops(comparisons=2, arithmetic=40, functions=2)
# quaternion: 1 + r00 + r11 + r22 (3 add), abs, sqrt, 0.5 * (1 mul); a < eps (1 cmp);
# b, c, d: one subtraction, 4 * a and a division each (9).
QUATERNION_OPS = Ops(comparisons=1, arithmetic=13, functions=2)
# theta: |Q| (4 mul, 3 add, sqrt); |Q| < eps (1 cmp); a / |Q| (1 div); clamp with min and
# max (2 cmp); acos.
THETA_OPS = Ops(comparisons=3, arithmetic=8, functions=2)
# phi = theta * 180 / pi * 4 - 180.
PHI_OPS = Ops(arithmetic=4)
# Kalman1D.update on a finite measurement with a running estimate: two finite checks;
# p += q; k = p / (p + r); x += k * (z - x); p *= 1 - k.
KALMAN_OPS = Ops(comparisons=2, arithmetic=8)
# VelocityEstimator.update with a full window: t <= last (1 cmp); dt = t - t0 (1);
# (x - x0) / dt and (y - y0) / dt (4); two moving averages of 4, each a finite check,
# sum() of four values (4 additions from 0) and a division.
VELOCITY_OPS = Ops(comparisons=3, arithmetic=15)
# Predicted point inside the robot's zone (4 cmp) and risk level by apparent size (2 cmp).
WARNING_OPS = Ops(comparisons=6)


@dataclass(frozen=True)
class PredictionOps:
    """Operations of one prediction, by part."""

    discretisation: Ops
    tree: Ops
    placement: Ops

    @property
    def total(self) -> Ops:
        return self.discretisation + self.tree + self.placement


def prediction_ops(predictor: TreePredictor, features: Features, horizon: float) -> PredictionOps:
    """What predicting from these features actually costs (image mode)."""
    decision = predictor.decide(features)
    _, placement = predictor.predict_counted(features, horizon)
    return PredictionOps(decision.discretisation_ops, decision.tree_ops, placement)


def worst_case_prediction_ops(predictor: TreePredictor) -> PredictionOps:
    """An upper bound: every binner at its worst, the deepest path, the dearer placement."""
    if predictor.model.mode is not Mode.IMAGE:
        raise ValueError("operation counts cover image mode (the paper's method) only")
    case_ops = max((extrapolation_ops(c) for c in Case), key=lambda o: o.total)
    if predictor.placement is Placement.LEAF and (
        predictor.model.leaf_value is LeafValue.VELOCITY_GAIN
    ):
        placement = GAIN_PLACEMENT_OPS
    elif predictor.placement is Placement.LEAF:
        placement = max(LEAF_PLACEMENT_OPS, case_ops + Ops(comparisons=2), key=lambda o: o.total)
    else:
        placement = case_ops
    return PredictionOps(
        predictor.model.discretiser.worst_case_ops(),
        Ops(comparisons=predictor.model.tree.depth),
        placement,
    )


@dataclass(frozen=True)
class StageOps:
    """Operations of the whole stage after pose, by part."""

    parts: tuple[tuple[str, Ops], ...]

    @property
    def total(self) -> Ops:
        out = Ops()
        for _, o in self.parts:
            out = out + o
        return out

    def table(self) -> str:
        width = max(len(name) for name, _ in self.parts)
        lines = [f"  {name:<{width}}  {o.describe()}" for name, o in self.parts]
        lines.append(f"  {'total':<{width}}  {self.total.describe()}")
        return "\n".join(lines)


def stage_ops(prediction: PredictionOps) -> StageOps:
    """The stage after pose around one prediction."""
    return StageOps(
        (
            ("orientation: look-at", LOOK_AT_OPS),
            ("orientation: quaternion", QUATERNION_OPS),
            ("orientation: theta", THETA_OPS),
            ("orientation: phi", PHI_OPS),
            ("phi Kalman filter", KALMAN_OPS),
            ("velocity", VELOCITY_OPS),
            ("tree: discretisation", prediction.discretisation),
            ("tree: node tests", prediction.tree),
            ("prediction", prediction.placement),
            ("warning", WARNING_OPS),
        )
    )


def mean_prediction_ops(
    predictor: TreePredictor, features: Iterable[Features], horizon: float
) -> tuple[float, int, int]:
    """(mean, min, max) total operations over many predictions."""
    totals = [prediction_ops(predictor, f, horizon).total.total for f in features]
    if not totals:
        raise ValueError("no features to count over")
    return sum(totals) / len(totals), min(totals), max(totals)


def ops_report(predictor: TreePredictor) -> str:
    """Worst-case counts for one prediction and for the stage, beside the paper's 23."""
    worst = worst_case_prediction_ops(predictor)
    lines = [
        "Operations for one prediction (worst case over inputs):",
        f"  discretisation  {worst.discretisation.describe()}",
        f"  tree tests      {worst.tree.describe()}",
        f"  placement       {worst.placement.describe()}",
        f"  total           {worst.total.describe()}"
        f"   [paper: {PAPER_CALCULATIONS_PER_PREDICTION} calculations per prediction]",
        "Operations for the whole stage after pose (worst case):",
        stage_ops(worst).table(),
    ]
    return "\n".join(lines)
