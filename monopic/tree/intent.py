"""The ground-mode intent tree: ID3 over what a robot can compute, leaves giving case,
intent and a correction to constant velocity; the `intent-tree` predictor that uses it.

Why a joint label: ID3 splits on one label, but a leaf must say both the motion case
(monopic/cases.py) and what the pedestrian will do within the horizon (keep going, stop,
turn away, start crossing; the simulator's intent labels, read from datasets). The tree
is grown on "case/intent" strings (e.g. "5/stop"), so its information gain favours
splits that explain either; each leaf's counts then give both marginals exactly.

Each node's `mean` is the mean correction to constant velocity over the model's horizon
(metres, robot frame, forward and left): true future position minus the pipeline's own
constant-velocity point. The prediction is constant velocity plus that correction, then
the intent rules (IntentRules, thresholds chosen on a validation split when training).
They read the intent counts of the rule node: the deepest node on the row's path with at
least min_rows rows (a leaf's few rows say little; its ancestors pool more alike rows):

- stop or turn away together on a share >= hold_back_support of the rule node's rows,
  stop the more common of the two: the point stays where the person is (held back: no
  motion into the robot's path is predicted);
- the same with turn away the more common: the lateral motion toward the path's centre
  line is dropped;
- otherwise start crossing on a share >= warn_support: the lateral motion toward the
  centre line is at least start_speed x horizon (warns earlier).

Holding back is bounded in time (release_s): it applies only while the person, at the
constant velocity the baseline extrapolates, needs more than release_s to come within the
warning's reach of the robot's swept band (path_distance less the warning zone's margin
and the pedestrian disc's radius, ZONE_REACH, over the lateral speed toward the centre
line): where constant velocity's warning could fire. A walker who does keep going is then
warned no later than about release_s before that, whatever their speed: a hold-back can
delay a warning, never drop it below the lead a robot needs. (An unbounded hold-back
cost 0.25 s of lead on validation and more on faster walkers: docs/intent/ground-tree.md.)

The shares, not the majority: a stop is rare among all rows even where it is likely,
and the warning needs to know that it is likely, not that it is the commonest outcome.
The case and the correction come from the leaf.

The predictor sees only the feature record (never the truth); it is stateless.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any

import numpy as np

from monopic.cases import Case
from monopic.features.record import Features
from monopic.horizon import HORIZON_S
from monopic.predict.base import Mode, Prediction, with_ground_point
from monopic.tree.discretise import Discretiser
from monopic.tree.id3 import DecisionTree, ID3Params, Node, fit_id3, information_gain
from monopic.tree.id3 import entropy as label_entropy
from monopic.tree.ops import ComparisonCounter, Ops

# The simulator's intent vocabulary (sim.world.intent.Intent values; a test keeps them equal).
INTENTS = ("keep going", "stop", "turn away", "start crossing")
START_CROSSING = "start crossing"
# m beyond the swept band where the ground warning can fire: the zone's safety margin
# (RobotGeometry.margin, 0.2) and the pedestrian disc's radius (PEDESTRIAN_RADIUS, 0.3) of
# monopic.variants.zone, which the tree may not import; a test holds them equal.
ZONE_REACH = 0.5

# The feature record's fields the tree may read, by attribute name (the order breaks
# information-gain ties: velocity first, as the image tree).
INTENT_ATTRIBUTES = (
    "forward",
    "left",
    "speed",
    "acceleration",
    "heading_rate",
    "phi",
    "phi_rate",
    "head_yaw",
    "head_toward",
    "path_offset",
    "path_distance",
)


def joint_label(case: Case, intent: str) -> str:
    """The label the tree is grown on: 'case/intent', e.g. '5/stop'."""
    if intent not in INTENTS:
        raise ValueError(f"intent {intent!r} is not one of {', '.join(INTENTS)}")
    return f"{int(case)}/{intent}"


def split_label(label: int | str) -> tuple[Case, str]:
    """Inverse of `joint_label`; ValueError on anything else."""
    text = str(label)
    head, sep, intent = text.partition("/")
    if not sep or intent not in INTENTS or not head.isdigit() or not 1 <= int(head) <= 9:
        raise ValueError(
            f"label {label!r} is not 'case/intent' (case 1-9, intent one of {INTENTS})"
        )
    return Case(int(head)), intent


def intent_values(features: Features) -> dict[str, float]:
    """The raw values the intent tree bins (NaN where the pipeline does not know them)."""
    g = features.ground
    if g is None:
        raise ValueError("the intent tree needs the camera model (ground features)")
    vf, vl = g.velocity
    return {
        "forward": vf,
        "left": vl,
        "speed": g.speed,
        "acceleration": g.acceleration,
        "heading_rate": g.heading_rate,
        "phi": features.phi,
        "phi_rate": features.phi_rate,
        "head_yaw": features.head_yaw,
        "head_toward": features.head_toward,
        "path_offset": g.path_offset,
        "path_distance": g.path_distance,
    }


@dataclass(frozen=True)
class IntentRules:
    """When the intent counts change the predicted point (see the module docstring).

    A support above 1 switches that rule off; min_rows picks the rule node.
    """

    hold_back_support: float = 1.01
    warn_support: float = 1.01
    min_rows: int = 20
    start_speed: float = 1.0  # m/s toward the path's centre line when starting to cross
    # s: hold back only while reaching the swept band takes longer than this (inf: always)
    release_s: float = math.inf

    def __post_init__(self) -> None:
        for name in ("hold_back_support", "warn_support"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0 < v <= 1.01):
                raise ValueError(f"{name} must be in (0, 1.01] (above 1: off), got {v}")
        if self.min_rows < 1:
            raise ValueError(f"min_rows must be >= 1, got {self.min_rows}")
        if not (math.isfinite(self.start_speed) and self.start_speed >= 0):
            raise ValueError(f"start_speed must be a finite number >= 0, got {self.start_speed}")
        if not self.release_s > 0:  # NaN fails too
            raise ValueError(f"release_s must be > 0 (inf: no bound), got {self.release_s}")

    def to_json(self) -> dict[str, Any]:
        return {
            "hold_back_support": self.hold_back_support,
            "warn_support": self.warn_support,
            "min_rows": self.min_rows,
            "start_speed_mps": self.start_speed,
            # JSON has no infinity: null is "no bound" (files before release_s lack the key)
            "release_s": self.release_s if math.isfinite(self.release_s) else None,
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> IntentRules:
        known = {"hold_back_support", "warn_support", "min_rows", "start_speed_mps", "release_s"}
        extra = set(data) - known
        if extra:
            raise ValueError(f"intent_rules has unknown keys {sorted(extra)}")
        return cls(
            hold_back_support=float(data["hold_back_support"]),
            warn_support=float(data["warn_support"]),
            min_rows=int(data["min_rows"]),
            start_speed=float(data["start_speed_mps"]),
            release_s=math.inf if data.get("release_s") is None else float(data["release_s"]),
        )


@dataclass(frozen=True)
class IntentSample:
    """One training row: the pipeline's values and position, the truth's labels and future.

    `position` and `velocity` are the pipeline's own ground estimates (m, m/s, robot
    frame); `future` is the true position `horizon` seconds later in the same frame.
    """

    values: Mapping[str, float]
    case: Case
    intent: str
    position: tuple[float, float]
    velocity: tuple[float, float]
    future: tuple[float, float]

    def correction(self, horizon: float) -> tuple[float, float]:
        """True future minus the constant-velocity point (NaN velocity counts as 0)."""
        vf, vl = (v if math.isfinite(v) else 0.0 for v in self.velocity)
        return (
            self.future[0] - (self.position[0] + vf * horizon),
            self.future[1] - (self.position[1] + vl * horizon),
        )


@dataclass(frozen=True)
class IntentTreeModel:
    """A fitted intent tree with what is needed to use and audit it."""

    horizon: float
    discretiser: Discretiser
    tree: DecisionTree
    rules: IntentRules
    root_entropy: float
    root_gains: tuple[tuple[str, float], ...]
    provenance: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.horizon > 0:
            raise ValueError(f"horizon must be positive, got {self.horizon}")
        if set(self.tree.attributes) != set(self.discretiser.attributes):
            raise ValueError("the tree's attributes differ from the discretiser's")
        for node in self.tree.nodes():
            split_label(node.label)
            for lab, _ in node.counts:
                split_label(lab)
            if node.mean is None or len(node.mean) != 2:
                raise ValueError(f"node correction {node.mean!r} is not a (forward, left) pair")


def fit_intent_model(
    samples: Sequence[IntentSample],
    discretiser: Discretiser,
    params: ID3Params | None = None,
    horizon: float = HORIZON_S,
    rules: IntentRules | None = None,
    provenance: Mapping[str, Any] | None = None,
) -> IntentTreeModel:
    """Bin the samples and grow the tree on their joint labels; nodes carry corrections."""
    if not samples:
        raise ValueError("no training samples")
    labels = [joint_label(s.case, s.intent) for s in samples]
    rows = [discretiser.discretise(s.values) for s in samples]
    targets = np.array([s.correction(horizon) for s in samples], dtype=float)
    if not np.all(np.isfinite(targets)):
        raise ValueError("training corrections must be finite (positions and futures known)")
    tree = fit_id3(rows, labels, discretiser.attributes, targets, params)
    gains = tuple((a, information_gain(rows, labels, a)) for a in discretiser.attributes)
    return IntentTreeModel(
        horizon=horizon,
        discretiser=discretiser,
        tree=tree,
        rules=rules or IntentRules(),
        root_entropy=label_entropy(labels),
        root_gains=gains,
        provenance=dict(provenance or {}),
    )


def shrink_corrections(tree: DecisionTree, shrink: float | None) -> DecisionTree:
    """Every node's correction times n / (n + shrink); None: all corrections zero.

    Why: on little data a leaf's mean correction is mostly noise; pulling it toward 0
    (constant velocity) by its row count keeps what many rows agree on. The intent
    counts, and so the rules, are unchanged.
    """
    if shrink is not None and not (math.isfinite(shrink) and shrink >= 0):
        raise ValueError(f"shrink must be a finite number >= 0 or None, got {shrink}")

    def walk(node: Node) -> Node:
        assert node.mean is not None
        k = 0.0 if shrink is None else node.n / (node.n + shrink)
        return replace(
            node,
            mean=tuple(m * k for m in node.mean),
            branches=tuple((v, walk(child)) for v, child in node.branches),
        )

    return DecisionTree(tree.attributes, walk(tree.root))


@dataclass(frozen=True)
class LeafReading:
    """What a row's path says: the leaf's majority case, intent and correction, and the
    rule node's shares of the intents the rules act on (marginals of joint counts)."""

    case: Case
    intent: str
    support: float  # share of the leaf's rows with that intent
    rows: int  # the rule node's rows
    correction: tuple[float, float]  # m over the model's horizon (forward, left)
    hold_share: float = 0.0  # the rule node's share of stop + turn away rows
    hold_intent: str = "stop"  # the more common of the two there (ties: stop)
    start_share: float = 0.0  # the rule node's share of start-crossing rows

    @classmethod
    def of(cls, node: Node, rule_node: Node | None = None) -> LeafReading:
        """`node` the leaf (or the node the row ends at), `rule_node` where the rules read."""
        cases, intents = _marginals(node)
        n = sum(intents.values())
        case = min(cases, key=lambda k: (-cases[k], int(k)))  # ties: the smaller case
        intent = min(intents, key=lambda k: (-intents[k], INTENTS.index(k)))
        _, at = _marginals(rule_node or node)
        m = sum(at.values())
        assert node.mean is not None
        return cls(
            case,
            intent,
            intents[intent] / n,
            m,
            (node.mean[0], node.mean[1]),
            hold_share=(at["stop"] + at["turn away"]) / m,
            hold_intent="stop" if at["stop"] >= at["turn away"] else "turn away",
            start_share=at[START_CROSSING] / m,
        )

    @classmethod
    def on_path(cls, path: Sequence[Node], min_rows: int) -> LeafReading:
        """The reading of a row's path: the rules read its deepest node with min_rows rows."""
        rule_node = next((nd for nd in reversed(path) if nd.n >= min_rows), path[0])
        return cls.of(path[-1], rule_node)


def _marginals(node: Node) -> tuple[Counter, Counter]:
    cases: Counter = Counter()
    intents: Counter = Counter()
    for lab, c in node.counts:
        case, intent = split_label(lab)
        cases[case] += c
        intents[intent] += c
    return cases, intents


class Action(StrEnum):
    """What the intent rules did to the constant-velocity-plus-correction point."""

    NONE = "none"
    HOLD_STOP = "hold back: stop"
    HOLD_TURN = "hold back: turn away"
    EARLIER = "warn earlier: start crossing"


@dataclass(frozen=True)
class IntentDecision:
    """One frame's reading, the point it gives, the rule applied and the operations spent."""

    reading: LeafReading
    point: tuple[float, float]
    action: Action
    discretisation_ops: Ops
    tree_ops: Ops
    placement_ops: Ops

    @property
    def ops(self) -> Ops:
        return self.discretisation_ops + self.tree_ops + self.placement_ops


def place(
    position: tuple[float, float],
    velocity: tuple[float, float],
    reading: LeafReading,
    rules: IntentRules,
    horizon: float,
    model_horizon: float,
    path_distance: float = math.nan,
) -> tuple[tuple[float, float], Action, Ops]:
    """The predicted ground point from a leaf, and the operations spent (counted as run).

    `path_distance` (m to the swept band's nearer edge, GroundFeatures.path_distance)
    bounds the hold-back in time (IntentRules.release_s); unknown (NaN), it allows no
    hold-back under a finite release_s.
    """
    c = ComparisonCounter()
    arithmetic = 0
    x, y = position
    vf = velocity[0] if c.finite(velocity[0]) else 0.0
    vl = velocity[1] if c.finite(velocity[1]) else 0.0
    k = horizon / model_horizon
    px = x + vf * horizon + reading.correction[0] * k
    py = y + vl * horizon + reading.correction[1] * k
    arithmetic += 9  # k; two velocity moves (2 mul); two corrections (2 mul); four additions
    action = Action.NONE
    if not c.lt(reading.rows, rules.min_rows):
        toward = 0.0
        if c.lt(0.0, y):
            toward = -1.0
        elif c.lt(y, 0.0):
            toward = 1.0
        if not c.lt(reading.hold_share, rules.hold_back_support):
            in_time = True  # the warning's reach is further than release_s (or no bound)
            if math.isfinite(rules.release_s):  # a property of the model, not of the row
                arithmetic += 3  # release_s x (toward x lateral speed); distance - reach
                in_time = c.finite(path_distance) and c.lt(
                    rules.release_s * (toward * vl), path_distance - ZONE_REACH
                )
            if in_time:  # else too near to hold back: constant velocity's point stands
                c.comparisons += 1  # which of the two
                if reading.hold_intent == "stop":
                    px, py, action = x, y, Action.HOLD_STOP
                else:
                    arithmetic += 2  # (py - y) * toward
                    if toward == 0.0 or c.lt(0.0, (py - y) * toward):
                        py, action = y, Action.HOLD_TURN
        elif not c.lt(reading.start_share, rules.warn_support):
            c.comparisons += 1  # toward != 0: on the centre line there is no "toward"
            if toward != 0.0:
                reach = rules.start_speed * horizon
                arithmetic += 3  # reach; (py - y) * toward
                if c.lt((py - y) * toward, reach):
                    py, action = y + toward * reach, Action.EARLIER
                    arithmetic += 2
    ops = c.ops + Ops(arithmetic=arithmetic)
    return (px, py), action, ops


@dataclass(frozen=True)
class IntentTreePredictor:
    """The intent tree behind the `Predictor` interface (ground mode, stateless: the
    readings it keeps are a property of the tree, worked out once per node reached)."""

    model: IntentTreeModel
    mode: Mode = Mode.GROUND
    name: str = "intent-tree"
    _readings: dict[int, LeafReading] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if self.mode is not Mode.GROUND:
            raise ValueError("the intent tree predicts in ground mode only")

    def decide(self, features: Features, horizon: float) -> IntentDecision:
        """Bin, walk the tree (one test per internal node visited), place the point."""
        g = features.ground
        if g is None:
            raise ValueError("ground mode needs the camera model (ground features)")
        bins, disc_ops = self.model.discretiser.discretise_counted(intent_values(features))
        path = self.model.tree.path(bins)
        node = path[-1]
        tests = len(path) - 1 if node.is_leaf else len(path)
        # The rule node is fixed per leaf (a property of the tree, like the leaf's label),
        # so finding it on the path costs the prediction nothing it would not store.
        reading = self._readings.get(id(node))
        if reading is None:
            reading = LeafReading.on_path(path, self.model.rules.min_rows)
            self._readings[id(node)] = reading
        point, action, placement = place(
            g.position,
            g.velocity,
            reading,
            self.model.rules,
            horizon,
            self.model.horizon,
            g.path_distance,
        )
        return IntentDecision(reading, point, action, disc_ops, Ops(comparisons=tests), placement)

    def predict(self, features: Features, horizon: float) -> Prediction:
        d = self.decide(features, horizon)
        p = with_ground_point(features, d.reading.case, horizon, d.point)
        return replace(p, intent=d.reading.intent)


def worst_case_ops(model: IntentTreeModel) -> Ops:
    """An upper bound on one prediction: every binner at its worst, the deepest path and
    the dearest placement (a start-crossing leaf moved toward the path)."""
    reading = LeafReading(
        Case.STILL, START_CROSSING, 1.0, model.rules.min_rows, (0.0, 0.0), start_share=1.0
    )
    rules = IntentRules(warn_support=1.0, min_rows=model.rules.min_rows, start_speed=1.0)
    _, _, placement = place((1.0, -1.0), (0.0, 0.0), reading, rules, 1.0, 1.0)
    if model.rules.hold_back_support <= 1 and math.isfinite(model.rules.release_s):
        held = replace(rules, hold_back_support=0.5, release_s=model.rules.release_s)
        hold = replace(reading, hold_share=1.0, hold_intent="turn away")
        _, _, placement_held = place((1.0, -1.0), (0.0, 1.0), hold, held, 1.0, 1.0, 2.0)
        placement = max(placement, placement_held, key=lambda o: o.total)
    return model.discretiser.worst_case_ops() + Ops(comparisons=model.tree.depth) + placement
