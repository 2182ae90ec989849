"""The trained tree as a predictor: bins -> ID3 node -> case and where the person will be.

A leaf stores the case of its training rows and, by the model's `leaf_value`, either
their mean displacement over the training horizon or a velocity gain per image axis.

- displacement: in image mode in units of the pedestrian's apparent height (so one tree
  serves people near and far): future = current + mean * height; in ground mode metres
  on the ground, in the robot's frame. It throws the measured speed away (a leaf holds
  the average of everyone whose velocity fell in its bins).
- velocity-gain (image mode): future = current + (gx * vx, gy * vy) * horizon, the gains
  learnt per leaf as the weighted median of actual over constant-velocity displacement
  (the gain minimising the absolute error, robust to tracker jumps), shrunk toward 1
  (constant velocity) by n / (n + shrink). The tree corrects constant velocity where its
  training rows say so and keeps the measured speed.

`Placement.CASE` instead extrapolates the measured velocity along the tree's case
(`extrapolate_image`), the paper's method, so they can be compared.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any

import numpy as np

from monopic.cases import Case
from monopic.features.record import Features
from monopic.horizon import HORIZON_S
from monopic.predict.base import (
    Mode,
    Prediction,
    extrapolate_ground,
    extrapolate_image,
    with_ground_point,
)
from monopic.tree.discretise import (
    Discretiser,
    authors_discretiser,
    entropy_discretiser,
    ground_discretiser,
)
from monopic.tree.id3 import DecisionTree, ID3Params, Node, fit_id3, information_gain
from monopic.tree.id3 import entropy as label_entropy
from monopic.tree.ops import Ops

DISPLACEMENT_UNITS = {Mode.IMAGE: "apparent-height", Mode.GROUND: "metre"}


class LeafValue(StrEnum):
    """What a leaf's two numbers mean: a displacement, or a gain on the measured velocity."""

    DISPLACEMENT = "displacement"
    VELOCITY_GAIN = "velocity-gain"


class Placement(StrEnum):
    """Where a tree prediction puts the person: the leaf's learned mean displacement, or
    the measured velocity extrapolated along the leaf's case."""

    LEAF = "leaf"
    CASE = "case"


@dataclass(frozen=True)
class TrainingSample:
    """One training row: raw feature values, the case that followed, the displacement.

    `displacement` is over the model's horizon, in the mode's unit (apparent heights in
    image mode, metres in ground mode).
    """

    values: Mapping[str, float]
    label: Case
    displacement: tuple[float, float]
    # What constant velocity moves over the same horizon, same unit (velocity-gain leaves).
    velocity_displacement: tuple[float, float] | None = None


@dataclass(frozen=True)
class TreeModel:
    """A fitted tree with everything needed to use and audit it."""

    mode: Mode
    horizon: float
    discretiser: Discretiser
    tree: DecisionTree
    root_entropy: float
    root_gains: tuple[tuple[str, float], ...]
    provenance: Mapping[str, Any] = field(default_factory=dict)
    leaf_value: LeafValue = LeafValue.DISPLACEMENT

    def __post_init__(self) -> None:
        if self.leaf_value is LeafValue.VELOCITY_GAIN and self.mode is not Mode.IMAGE:
            raise ValueError("velocity-gain leaves are for image mode only")

    @property
    def displacement_unit(self) -> str:
        return DISPLACEMENT_UNITS[self.mode]


def feature_values(features: Features, mode: Mode) -> dict[str, float]:
    """The raw values the tree of `mode` bins."""
    if mode is Mode.IMAGE:
        return {"phi": features.phi, "vx": features.vx, "vy": features.vy}
    if features.ground is None:
        raise ValueError("ground mode needs the camera model (ground features)")
    vf, vl = features.ground.velocity
    return {"forward": vf, "left": vl}


def fit_model(
    samples: Sequence[TrainingSample],
    mode: Mode = Mode.IMAGE,
    discretiser: Discretiser | str = "authors",
    params: ID3Params | None = None,
    horizon: float = HORIZON_S,
    provenance: Mapping[str, Any] | None = None,
    leaf_value: LeafValue = LeafValue.DISPLACEMENT,
    shrink: float = 0.0,
) -> TreeModel:
    """Bin the samples and grow the tree; `discretiser` may be 'authors' or 'entropy'.

    'authors' means the authors' bins in image mode and the dead-zoned sign bins on the
    ground velocity in ground mode; 'entropy' fits MDL cut points on these samples.
    The tree splits on the case labels either way (the paper's ID3); `leaf_value` says
    what its nodes then carry, `shrink` (rows) pulls velocity gains toward 1.
    """
    if leaf_value is LeafValue.VELOCITY_GAIN:
        if mode is not Mode.IMAGE:
            raise ValueError("velocity-gain leaves are for image mode only")
        if any(s.velocity_displacement is None for s in samples):
            raise ValueError("velocity-gain leaves need each sample's velocity displacement")
    if not (math.isfinite(shrink) and shrink >= 0):
        raise ValueError(f"shrink must be a finite number >= 0, got {shrink}")
    if not samples:
        raise ValueError("no training samples")
    if not horizon > 0:
        raise ValueError(f"horizon must be positive, got {horizon}")
    labels = [int(s.label) for s in samples]
    if isinstance(discretiser, str):
        attrs = ("phi", "vx", "vy") if mode is Mode.IMAGE else ("forward", "left")
        if discretiser == "authors":
            disc = authors_discretiser() if mode is Mode.IMAGE else ground_discretiser()
        elif discretiser == "entropy":
            columns = {a: [s.values[a] for s in samples] for a in attrs}
            disc = entropy_discretiser(columns, labels, attrs)
        else:
            raise ValueError(f"unknown discretiser {discretiser!r}")
    else:
        disc = discretiser
    rows = [disc.discretise(s.values) for s in samples]
    targets = np.array([s.displacement for s in samples], dtype=float)
    if not np.all(np.isfinite(targets)):
        raise ValueError("training displacements must be finite")
    tree = fit_id3(rows, labels, disc.attributes, targets, params)
    if leaf_value is LeafValue.VELOCITY_GAIN:
        cv = np.array([s.velocity_displacement for s in samples], dtype=float)
        if not np.all(np.isfinite(cv)):
            raise ValueError("training velocity displacements must be finite")
        root = _with_gains(tree.root, list(range(len(rows))), rows, targets, cv, shrink)
        tree = DecisionTree(tree.attributes, root)
    gains = tuple((a, information_gain(rows, labels, a)) for a in disc.attributes)
    return TreeModel(
        leaf_value=leaf_value,
        mode=mode,
        horizon=horizon,
        discretiser=disc,
        tree=tree,
        root_entropy=label_entropy(labels),
        root_gains=gains,
        provenance=dict(provenance or {}),
    )


def velocity_gain(actual: np.ndarray, velocity: np.ndarray, shrink: float) -> float:
    """The gain g minimising sum |actual - g * velocity|, shrunk toward 1 by n / (n + shrink).

    The minimiser is the median of actual / velocity weighted by |velocity| (rows where
    constant velocity moves nothing carry no weight); with no weight at all it is 1.
    """
    a, v = np.asarray(actual, dtype=float), np.asarray(velocity, dtype=float)
    w = np.abs(v)
    keep = w > 0
    if not np.any(keep):
        return 1.0
    ratio, w = a[keep] / v[keep], w[keep]
    order = np.argsort(ratio, kind="stable")
    cum = np.cumsum(w[order])
    raw = float(ratio[order][int(np.searchsorted(cum, cum[-1] / 2))])
    n = int(a.size)
    return 1.0 + n / (n + shrink) * (raw - 1.0)


def _with_gains(
    node: Node,
    idx: list[int],
    rows: Sequence[Mapping[str, int]],
    actual: np.ndarray,
    velocity: np.ndarray,
    shrink: float,
) -> Node:
    """`node` and its subtree with `mean` replaced by the velocity gains of their rows."""
    gains = tuple(velocity_gain(actual[idx, ax], velocity[idx, ax], shrink) for ax in range(2))
    branches = tuple(
        (
            v,
            _with_gains(
                child,
                [i for i in idx if rows[i][node.attribute or ""] == v],
                rows,
                actual,
                velocity,
                shrink,
            ),
        )
        for v, child in node.branches
    )
    return replace(node, mean=gains, branches=branches)


@dataclass(frozen=True)
class TreeDecision:
    """What the tree decided for one input, and what it cost."""

    node: Node
    case: Case
    discretisation_ops: Ops
    tree_ops: Ops


@dataclass(frozen=True)
class TreePredictor:
    """The trained tree behind the `Predictor` interface (stateless)."""

    model: TreeModel
    placement: Placement = Placement.LEAF
    name: str = "tree"  # its name in the predictor registry (results say "tree/image")

    @property
    def mode(self) -> Mode:
        return self.model.mode

    def decide(self, features: Features) -> TreeDecision:
        """Bin the features and walk the tree; one test per internal node visited."""
        bins, disc_ops = self.model.discretiser.discretise_counted(
            feature_values(features, self.model.mode)
        )
        path = self.model.tree.path(bins)
        node = path[-1]
        tests = len(path) - 1 if node.is_leaf else len(path)
        return TreeDecision(node, Case(node.label), disc_ops, Ops(comparisons=tests))

    def predict(self, features: Features, horizon: float) -> Prediction:
        decision = self.decide(features)
        if self.model.mode is Mode.IMAGE:
            return self._image(features, decision, horizon)[0]
        return self._ground(features, decision, horizon)

    def predict_counted(self, features: Features, horizon: float) -> tuple[Prediction, Ops]:
        """Image mode: the prediction and the operations spent placing it after the tree."""
        if self.model.mode is not Mode.IMAGE:
            raise ValueError("operation counts cover image mode (the paper's method) only")
        return self._image(features, self.decide(features), horizon)

    def _image(
        self, features: Features, decision: TreeDecision, horizon: float
    ) -> tuple[Prediction, Ops]:
        mean = decision.node.mean
        h = features.apparent_height
        gain_leaf = self.model.leaf_value is LeafValue.VELOCITY_GAIN
        if self.placement is Placement.LEAF and mean is not None and gain_leaf:
            # offset = gain * v * horizon per axis (4 multiplies); centre and foot shifted.
            dx = mean[0] * _finite_or_zero(features.vx) * horizon
            dy = mean[1] * _finite_or_zero(features.vy) * horizon
            (cu, cv), (fu, fv) = features.center, features.foot
            pred = Prediction(decision.case, horizon, (cu + dx, cv + dy), (fu + dx, fv + dy))
            return pred, GAIN_PLACEMENT_OPS
        if self.placement is Placement.LEAF and mean is not None and _positive(h):
            # s = h * horizon / H; offset = mean * s; centre and foot shifted by it.
            s = h * horizon / self.model.horizon
            dx, dy = mean[0] * s, mean[1] * s
            (cu, cv), (fu, fv) = features.center, features.foot
            pred = Prediction(decision.case, horizon, (cu + dx, cv + dy), (fu + dx, fv + dy))
            return pred, LEAF_PLACEMENT_OPS
        clean = replace(features, vx=_finite_or_zero(features.vx), vy=_finite_or_zero(features.vy))
        ops = extrapolation_ops(decision.case)
        if self.placement is Placement.LEAF:  # fell back: the height check was made
            ops = ops + Ops(comparisons=2)
        return extrapolate_image(clean, decision.case, horizon), ops

    def _ground(self, features: Features, decision: TreeDecision, horizon: float) -> Prediction:
        g = features.ground
        if g is None:
            raise ValueError("ground mode needs the camera model (ground features)")
        mean = decision.node.mean
        if self.placement is Placement.LEAF and mean is not None:
            k = horizon / self.model.horizon
            future = (g.position[0] + mean[0] * k, g.position[1] + mean[1] * k)
            return with_ground_point(features, decision.case, horizon, future)
        vf, vl = g.velocity
        clean_ground = replace(g, velocity=(_finite_or_zero(vf), _finite_or_zero(vl)))
        return extrapolate_ground(replace(features, ground=clean_ground), decision.case, horizon)


# The height check (finite, positive), then s = h * horizon / H (2), the offset (2
# multiplies) and the shifted centre and foot (4 additions).
LEAF_PLACEMENT_OPS = Ops(comparisons=2, arithmetic=8)
# Two finite checks on the velocity, gain * v * horizon on both axes (4 multiplies) and
# the shifted centre and foot (4 additions).
GAIN_PLACEMENT_OPS = Ops(comparisons=2, arithmetic=8)


def extrapolation_ops(case: Case) -> Ops:
    """Operations of `extrapolate_image`: two axis tests, one multiply per moving axis,
    four additions (centre and foot, both axes)."""
    moving = (case.lateral != 0) + (case.depth != 0)
    return Ops(comparisons=2, arithmetic=moving + 4)


def _positive(x: float) -> bool:
    return math.isfinite(x) and x > 0


def _finite_or_zero(x: float) -> float:
    return x if math.isfinite(x) else 0.0
