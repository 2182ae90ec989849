"""Operation counts: per binner path, per tree walk, per placement, and for the stage."""

from __future__ import annotations

import ast
import inspect
import math

import pytest

from monopic.cases import Case
from monopic.features import orientation
from monopic.features.record import Features
from monopic.tree.discretise import AuthorsPhiBins, DeadZoneSignBins, authors_discretiser
from monopic.tree.model import Placement, TrainingSample, TreePredictor, fit_model
from monopic.tree.opcount import (
    KALMAN_OPS,
    LOOK_AT_OPS,
    PHI_OPS,
    QUATERNION_OPS,
    THETA_OPS,
    VELOCITY_OPS,
    WARNING_OPS,
    ops_report,
    prediction_ops,
    stage_ops,
    worst_case_prediction_ops,
)
from monopic.tree.ops import Ops


@pytest.mark.parametrize(
    ("phi", "comparisons"),
    [
        (90.0, 1 + 2),  # finite, 75 < phi, phi < 105
        (0.0, 1 + 1 + 2),  # finite, 75 < phi fails, -15 < phi < 15
        (50.0, 1 + 1 + 2 + 2),  # 75 < phi fails; -15 < phi, phi < 15 fails; 0 < phi < 90
        (-100.0, 1 + 1 + 1 + 1 + 1),  # every first comparison fails
        (200.0, 1 + 2 + 2 + 2 + 2),  # every second comparison fails: the worst path
        (math.nan, 1),
    ],
)
def test_phi_comparisons_follow_the_path_taken(phi, comparisons):
    assert AuthorsPhiBins().bin_counted(phi)[1] == Ops(comparisons=comparisons)


@pytest.mark.parametrize(
    ("v", "ops"),
    [
        (0.0, Ops(comparisons=2, functions=1)),  # finite, |v| < 15
        (20.0, Ops(comparisons=3, functions=1)),  # ... then 0 < v
        (-20.0, Ops(comparisons=3, functions=1)),
        (math.nan, Ops(comparisons=1)),
    ],
)
def test_velocity_bin_ops(v, ops):
    assert DeadZoneSignBins().bin_counted(v)[1] == ops


def test_worst_case_discretisation_is_the_sum_of_the_worst_paths():
    assert authors_discretiser().worst_case_ops() == Ops(comparisons=9 + 3 + 3, functions=2)


def _model():
    samples = [
        TrainingSample({"phi": 90.0, "vx": 40.0, "vy": 30.0}, Case.PERPENDICULAR_RIGHT, (0.4, 0.0)),
        TrainingSample(
            {"phi": 90.0, "vx": 40.0, "vy": -30.0}, Case.PERPENDICULAR_RIGHT, (0.5, 0.0)
        ),
        TrainingSample(
            {"phi": 0.0, "vx": -40.0, "vy": 30.0}, Case.OBLIQUE_LEFT_TOWARD, (-0.3, 0.2)
        ),
        TrainingSample(
            {"phi": 0.0, "vx": -40.0, "vy": -30.0}, Case.OBLIQUE_LEFT_AWAY, (-0.3, -0.2)
        ),
    ]
    return fit_model(samples)


def _features(phi: float, vx: float, vy: float) -> Features:
    return Features(0.0, (100.0, 100.0), (100.0, 150.0), 100.0, phi, vx, vy)


def test_one_prediction_counts_what_it_did():
    model = _model()
    # phi and vx tie at the root (gain 1.0, vy 0.5): phi is listed first. Under phi = 3
    # only vy separates the two left cases.
    assert model.tree.root.attribute == "phi"
    assert dict(model.tree.root.branches)[3].attribute == "vy"
    assert model.tree.depth == 2
    leaf = TreePredictor(model)
    ops = prediction_ops(leaf, _features(90.0, 40.0, 0.0), 1.0)
    assert ops.discretisation == Ops(comparisons=3 + 3 + 2, functions=2)
    assert ops.tree == Ops(comparisons=1)  # root test only: phi = 4 is a leaf
    assert ops.placement == Ops(comparisons=2, arithmetic=8)
    deep = prediction_ops(leaf, _features(0.0, -40.0, 30.0), 1.0)
    assert deep.tree == Ops(comparisons=2)
    # An unseen bin stops at the root: the failed test still counts.
    unseen = prediction_ops(leaf, _features(200.0, 0.0, 0.0), 1.0)
    assert unseen.tree == Ops(comparisons=1)
    # Case placement: two axis tests, one multiply per moving axis, four additions.
    case = prediction_ops(TreePredictor(model, Placement.CASE), _features(0.0, -40.0, 30.0), 1.0)
    assert case.placement == Ops(comparisons=2, arithmetic=2 + 4)
    assert ops.total.total == ops.discretisation.total + 1 + 10


def test_worst_case_prediction_and_stage():
    worst = worst_case_prediction_ops(TreePredictor(_model()))
    assert worst.discretisation.total == 17
    assert worst.tree.total == 2
    assert worst.placement.total == 10
    stage = stage_ops(worst)
    parts = dict(stage.parts)
    assert parts["orientation: look-at"] == LOOK_AT_OPS
    assert parts["velocity"] == VELOCITY_OPS
    assert parts["warning"] == WARNING_OPS
    expected = LOOK_AT_OPS + QUATERNION_OPS + THETA_OPS + PHI_OPS + KALMAN_OPS + VELOCITY_OPS
    expected = expected + WARNING_OPS + worst.total
    assert stage.total == expected
    report = ops_report(TreePredictor(_model()))
    assert "paper: 23 calculations per prediction" in report
    assert f"total           {worst.total.describe()}" in report


def _main_path_nodes(node: ast.AST):
    """All nodes except those inside an `if` body (the early-return degenerate cases)."""
    yield node
    for field, value in ast.iter_fields(node):
        if isinstance(node, ast.If) and field in ("body", "orelse"):
            continue
        children = value if isinstance(value, list) else [value]
        for child in children:
            if isinstance(child, ast.AST):
                yield from _main_path_nodes(child)


def _source_ops(fn) -> tuple[int, int, dict[str, int]]:
    """(binary arithmetic ops, comparisons, calls by name) on a function's main path."""
    nodes = list(_main_path_nodes(ast.parse(inspect.getsource(fn))))
    arith = sum(isinstance(n, ast.BinOp) for n in nodes)
    compares = sum(len(n.ops) for n in nodes if isinstance(n, ast.Compare))
    calls: dict[str, int] = {}
    for n in nodes:
        if isinstance(n, ast.Call):
            f = n.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "?")
            calls[name] = calls.get(name, 0) + 1
    return arith, compares, calls


def test_scalar_orientation_counts_match_the_code():
    """quaternion, theta and phi are scalar code: their counts can be read off the source
    (each operation outside the degenerate early returns runs once)."""
    arith, compares, calls = _source_ops(orientation.quaternion)
    assert arith == QUATERNION_OPS.arithmetic
    assert compares == QUATERNION_OPS.comparisons
    assert calls.get("sqrt", 0) + calls.get("abs", 0) == QUATERNION_OPS.functions
    arith, compares, calls = _source_ops(orientation.theta_from_quaternion)
    assert arith == THETA_OPS.arithmetic
    assert compares + calls["min"] + calls["max"] == THETA_OPS.comparisons
    assert calls["sqrt"] + calls["acos"] == THETA_OPS.functions
    arith, compares, _ = _source_ops(orientation.phi_from_theta)
    assert (arith, compares) == (PHI_OPS.arithmetic, 0)
