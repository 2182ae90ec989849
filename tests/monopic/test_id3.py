"""The ID3 learner on Quinlan's play-tennis table, its stopping rules, ties, unseen
values, JSON and DOT; and the trained tree as a predictor."""

from __future__ import annotations

import json
import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.camera import CameraModel
from monopic.cases import Case
from monopic.features.record import Features, GroundFeatures
from monopic.predict.base import Mode, extrapolate_image
from monopic.tree.id3 import (
    DecisionTree,
    ID3Params,
    Node,
    entropy,
    fit_id3,
    information_gain,
    majority,
    render_dot,
    render_text,
)
from monopic.tree.model import Placement, TrainingSample, TreePredictor, fit_model
from monopic.tree.serialise import dumps, load_model, model_from_json, save_model

ATTRS = ("Outlook", "Temperature", "Humidity", "Wind")
# Quinlan (1986), Table 1 / Mitchell (1997), Table 3.2.
TENNIS = """\
Sunny Hot High Weak No
Sunny Hot High Strong No
Overcast Hot High Weak Yes
Rain Mild High Weak Yes
Rain Cool Normal Weak Yes
Rain Cool Normal Strong No
Overcast Cool Normal Strong Yes
Sunny Mild High Weak No
Sunny Cool Normal Weak Yes
Rain Mild Normal Weak Yes
Sunny Mild Normal Strong Yes
Overcast Mild High Strong Yes
Overcast Hot Normal Weak Yes
Rain Mild High Strong No"""
ROWS = [dict(zip(ATTRS, line.split()[:4], strict=True)) for line in TENNIS.splitlines()]
LABELS = [line.split()[4] for line in TENNIS.splitlines()]


def test_entropy_and_gains_match_the_textbook():
    assert entropy(LABELS) == pytest.approx(0.940, abs=5e-4)
    gains = {a: information_gain(ROWS, LABELS, a) for a in ATTRS}
    # Mitchell prints 0.246, 0.151, 0.048, 0.029 (truncated); exact values round as below.
    assert gains["Outlook"] == pytest.approx(0.2467, abs=1e-4)
    assert gains["Humidity"] == pytest.approx(0.1518, abs=1e-4)
    assert gains["Wind"] == pytest.approx(0.0481, abs=1e-4)
    assert gains["Temperature"] == pytest.approx(0.0292, abs=1e-4)
    sunny = [i for i, r in enumerate(ROWS) if r["Outlook"] == "Sunny"]
    sub_rows, sub_labels = [ROWS[i] for i in sunny], [LABELS[i] for i in sunny]
    assert entropy(sub_labels) == pytest.approx(0.971, abs=5e-4)
    assert information_gain(sub_rows, sub_labels, "Humidity") == pytest.approx(0.971, abs=5e-4)
    assert information_gain(sub_rows, sub_labels, "Temperature") == pytest.approx(0.571, abs=5e-4)
    assert information_gain(sub_rows, sub_labels, "Wind") == pytest.approx(0.020, abs=5e-4)


def test_play_tennis_gives_quinlans_tree():
    tree = fit_id3(ROWS, LABELS, ATTRS)
    root = tree.root
    assert root.attribute == "Outlook"
    assert [v for v, _ in root.branches] == ["Overcast", "Rain", "Sunny"]
    overcast, rain, sunny = (c for _, c in root.branches)
    assert overcast.is_leaf and overcast.label == "Yes" and overcast.n == 4
    assert sunny.attribute == "Humidity"
    assert {v: c.label for v, c in sunny.branches} == {"High": "No", "Normal": "Yes"}
    assert rain.attribute == "Wind"
    assert {v: c.label for v, c in rain.branches} == {"Strong": "No", "Weak": "Yes"}
    assert all(c.is_leaf for _, c in sunny.branches + rain.branches)
    assert tree.depth == 2
    assert [tree.predict(r) for r in ROWS] == LABELS


def test_min_samples_stops_small_nodes_at_their_majority():
    tree = fit_id3(ROWS, LABELS, ATTRS, params=ID3Params(min_samples=6))
    assert tree.root.attribute == "Outlook"
    kids = dict(tree.root.branches)
    assert kids["Sunny"].is_leaf and kids["Sunny"].label == "No"  # 3 No, 2 Yes
    assert kids["Rain"].is_leaf and kids["Rain"].label == "Yes"  # 3 Yes, 2 No
    assert fit_id3(ROWS, LABELS, ATTRS, params=ID3Params(min_samples=15)).root.is_leaf


def test_max_depth_limits_the_tree():
    stump = fit_id3(ROWS, LABELS, ATTRS, params=ID3Params(max_depth=0))
    assert stump.root.is_leaf and stump.root.label == "Yes"
    assert dict(stump.root.counts) == {"No": 5, "Yes": 9}
    one = fit_id3(ROWS, LABELS, ATTRS, params=ID3Params(max_depth=1))
    assert one.depth == 1 and one.root.attribute == "Outlook"
    with pytest.raises(ValueError):
        ID3Params(max_depth=-1)
    with pytest.raises(ValueError):
        ID3Params(min_samples=0)


def test_unseen_value_answers_with_that_nodes_majority():
    tree = fit_id3(ROWS, LABELS, ATTRS)
    foggy = {"Outlook": "Foggy", "Temperature": "Hot", "Humidity": "High", "Wind": "Weak"}
    assert tree.predict(foggy) == "Yes"
    assert tree.answer(foggy) is tree.root
    odd = {"Outlook": "Sunny", "Temperature": "Hot", "Humidity": "Extreme", "Wind": "Weak"}
    assert tree.predict(odd) == "No"  # the Sunny node: 3 No, 2 Yes
    assert len(tree.path(odd)) == 2
    with pytest.raises(ValueError, match="Humidity"):
        tree.predict({"Outlook": "Sunny"})


def test_ties_are_broken_deterministically():
    rows = [{"a": x, "b": x} for x in (0, 0, 1, 1)]
    labels = ["p", "p", "q", "q"]
    assert fit_id3(rows, labels, ("a", "b")).root.attribute == "a"
    assert fit_id3(rows, labels, ("b", "a")).root.attribute == "b"
    assert majority(["z", "y", "y", "z"]) == "y"
    assert majority([9, 3, 3, 9, 5]) == 3
    # Row order does not matter.
    order = list(range(len(ROWS)))
    random.Random(0).shuffle(order)
    shuffled = fit_id3([ROWS[i] for i in order], [LABELS[i] for i in order], ATTRS)
    assert shuffled == fit_id3(ROWS, LABELS, ATTRS)


def test_node_means_average_the_targets():
    targets = np.arange(28, dtype=float).reshape(14, 2)
    tree = fit_id3(ROWS, LABELS, ATTRS, targets=targets)
    assert tree.root.mean == pytest.approx(tuple(targets.mean(axis=0)))
    overcast = dict(tree.root.branches)["Overcast"]
    idx = [i for i, r in enumerate(ROWS) if r["Outlook"] == "Overcast"]
    assert overcast.mean == pytest.approx(tuple(targets[idx].mean(axis=0)))


def test_json_round_trip_is_identical():
    targets = np.random.default_rng(1).normal(size=(14, 2))
    tree = fit_id3(ROWS, LABELS, ATTRS, targets=targets)
    text = json.dumps(tree.to_json())
    back = DecisionTree.from_json(json.loads(text))
    assert back == tree
    assert json.dumps(back.to_json()) == text


def test_text_and_dot_outputs():
    tree = fit_id3(ROWS, LABELS, ATTRS)
    text = render_text(tree)
    assert text.splitlines()[0].startswith("root: Yes (n=14")
    assert "Outlook = Sunny: No (n=5, 60%), split on Humidity" in text
    assert "|   Wind = Strong: -> No (n=2, 100%)" in text
    dot = render_dot(tree, describe_value=lambda a, v: f'{a} "{v}"')
    assert dot.startswith('digraph "id3" {') and dot.rstrip().endswith("}")
    n_nodes = len(tree.nodes())
    assert dot.count("shape=") == n_nodes == 8
    assert dot.count(" -> ") == n_nodes - 1
    assert 'label="Outlook \\"Sunny\\""' in dot  # quotes escaped
    assert 'label="Outlook\\nYes\\nn=14"' in dot  # newlines as DOT \n


rows_st = st.lists(
    st.tuples(st.integers(0, 2), st.integers(0, 2), st.integers(0, 3)),
    min_size=1,
    max_size=40,
)


@settings(max_examples=60, deadline=None)
@given(rows_st)
def test_grown_tree_fits_consistent_data_and_never_fails(data):
    rows = [{"x": a, "y": b, "z": c} for a, b, c in data]
    # Labels are a function of the attributes, so the data are consistent.
    labels = [(a * 7 + b * 3 + c) % 4 for a, b, c in data]
    tree = fit_id3(rows, labels, ("x", "y", "z"))
    assert [tree.predict(r) for r in rows] == labels
    assert tree.predict({"x": 99, "y": -1, "z": 7}) in set(labels)
    assert DecisionTree.from_json(json.loads(json.dumps(tree.to_json()))) == tree


# --- the trained tree as a predictor --------------------------------------------------


def _samples() -> list[TrainingSample]:
    """Right-movers drift right by 0.5 heights, left-movers left, slow ones stay."""
    out = []
    for vx, case, dx in (
        (60.0, Case.PERPENDICULAR_RIGHT, 0.5),
        (-60.0, Case.PERPENDICULAR_LEFT, -0.5),
        (3.0, Case.STILL, 0.0),
    ):
        for k in range(5):
            out.append(TrainingSample({"phi": 90.0, "vx": vx + k, "vy": 0.0}, case, (dx, 0.1)))
    return out


def _features(vx: float, vy: float = 0.0, phi: float = 90.0) -> Features:
    return Features(
        timestamp=0.0,
        center=(300.0, 200.0),
        foot=(300.0, 300.0),
        apparent_height=200.0,
        phi=phi,
        vx=vx,
        vy=vy,
    )


def test_tree_predictor_places_the_leaf_displacement_in_heights():
    model = fit_model(_samples())
    pred = TreePredictor(model).predict(_features(50.0), 1.0)
    assert pred.case is Case.PERPENDICULAR_RIGHT
    assert pred.center == pytest.approx((300.0 + 0.5 * 200.0, 200.0 + 0.1 * 200.0))
    assert pred.foot == pytest.approx((400.0, 320.0))
    half = TreePredictor(model).predict(_features(-50.0), 0.5)
    assert half.center == pytest.approx((300.0 - 0.5 * 200.0 * 0.5, 200.0 + 0.1 * 200.0 * 0.5))


def test_case_placement_is_plain_extrapolation_along_the_case():
    model = fit_model(_samples())
    f = _features(50.0, vy=30.0)
    pred = TreePredictor(model, Placement.CASE).predict(f, 1.0)
    assert pred == extrapolate_image(f, Case.PERPENDICULAR_RIGHT, 1.0)
    assert pred.center == (350.0, 200.0)  # perpendicular: vy ignored


def test_missing_velocity_falls_back_to_the_root_majority():
    model = fit_model(_samples())
    pred = TreePredictor(model).predict(_features(math.nan), 1.0)
    root = model.tree.root
    assert pred.case == Case(root.label)
    assert pred.center == pytest.approx((300.0 + root.mean[0] * 200, 200.0 + root.mean[1] * 200))
    assert all(
        map(
            math.isfinite,
            TreePredictor(model, Placement.CASE).predict(_features(math.nan), 1.0).center,
        )
    )


def test_model_file_round_trip(tmp_path):
    model = fit_model(_samples(), provenance={"data": [{"name": "x.csv", "sha256": "ab"}]})
    path = tmp_path / "t.json"
    save_model(model, path)
    back = load_model(path)
    assert back == model
    assert dumps(back) == path.read_text()
    data = json.loads(path.read_text())
    assert data["format"] == "monopic-id3-tree" and data["version"] == 1
    data["version"] = 3
    with pytest.raises(ValueError, match="version 3"):
        model_from_json(data)
    data["version"] = 1
    data["tree"]["root"]["label"] = 12
    with pytest.raises(ValueError, match="case number"):
        model_from_json(data)


def test_entropy_discretiser_model_round_trips_and_predicts(tmp_path):
    model = fit_model(_samples(), discretiser="entropy")
    assert model.discretiser.name == "entropy"
    path = tmp_path / "e.json"
    save_model(model, path)
    assert load_model(path) == model
    assert TreePredictor(model).predict(_features(-61.0), 1.0).case is Case.PERPENDICULAR_LEFT


def test_ground_mode_uses_own_ground_velocity_and_metres():
    cam = CameraModel.from_fov(640, 480, 60.0, mount_height=1.0)
    samples = [
        TrainingSample({"forward": -1.2 + 0.01 * k, "left": 0.0}, Case.TOWARD, (-1.2, 0.0))
        for k in range(5)
    ] + [
        TrainingSample(
            {"forward": 0.0, "left": 1.0 + 0.01 * k}, Case.PERPENDICULAR_LEFT, (0.0, 1.0)
        )
        for k in range(5)
    ]
    model = fit_model(samples, mode=Mode.GROUND)
    assert model.displacement_unit == "metre"
    ground = GroundFeatures(position=(6.0, 0.5), velocity=(-1.1, 0.05), camera=cam)
    f = Features(0.0, (320.0, 250.0), (320.0, 300.0), 100.0, 0.0, 0.0, 0.0, ground=ground)
    pred = TreePredictor(model).predict(f, 1.0)
    assert pred.case is Case.TOWARD
    assert pred.ground == pytest.approx((4.8, 0.5))
    assert TreePredictor(model).mode is Mode.GROUND
    with pytest.raises(ValueError, match="ground"):
        TreePredictor(model).predict(_features(1.0), 1.0)


def test_node_rejects_non_scalar_values():
    with pytest.raises(ValueError):
        Node.from_json({"label": [1], "counts": []})
