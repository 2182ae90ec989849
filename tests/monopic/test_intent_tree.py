"""The ground intent tree: learning a known rule from hand-made dataset files, the split,
the predictor's intent rules, the tree file, and the one-line errors on bad input."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from monopic.camera import CameraModel
from monopic.cases import Case, case_from_ground_velocity
from monopic.cli.main import main
from monopic.errors import UserError
from monopic.features.record import Features, GroundFeatures
from monopic.frame import EgoState
from monopic.predict.base import Mode
from monopic.tree.discretise import CutPointBins, Discretiser
from monopic.tree.id3 import DecisionTree, Node
from monopic.tree.intent import (
    INTENT_ATTRIBUTES,
    Action,
    IntentRules,
    IntentTreeModel,
    IntentTreePredictor,
    LeafReading,
    place,
    worst_case_ops,
)
from monopic.tree.intent_training import (
    FEATURE_COLUMNS,
    LabelledRow,
    RuleOption,
    RunCount,
    RunRows,
    WarningCount,
    choose_rules,
    count_runs,
    read_dataset,
    split_runs,
    train_intent_tree,
)
from monopic.tree.serialise import (
    load_default_model,
    load_intent_model,
    load_model,
    save_model,
)
from monopic.variants.warning import CollisionWarning
from monopic.variants.zone import RobotGeometry

CAM = CameraModel.from_fov(768, 432, 70, 1.0, pitch_deg=5)
SPEED = 1.3  # m/s, walking toward the robot's path from its right (+ left)
ROBOT_SPEED = 2.0
HORIZON = 1.0
# The hand-made stops come 0.1-0.4 m (0.08-0.3 s) short of where the warning can fire (the
# band's edge less ZONE_REACH): a release time below that lets the trainer hold back on
# them (the shipped grid starts at 1.1 s).
TEST_RELEASE = (0.05,)


# --- hand-made dataset: stop exactly when slowing near the kerb ---------------------------


def _row(rng: np.random.Generator, slowing: bool, near: bool) -> dict:
    """One frame whose right answer is known: slowing near the kerb -> stop, else walk on."""
    gap = rng.uniform(0.6, 0.9) if near else rng.uniform(2.5, 3.5)  # m, to the band's edge
    y = -(0.3 + gap)
    stop = slowing and near
    future_y = y + (0.2 if stop else SPEED * HORIZON)
    values = {
        "forward": rng.normal(0, 0.05),
        "left": SPEED + rng.normal(0, 0.05),
        "speed": SPEED + rng.normal(0, 0.05),
        "acceleration": rng.uniform(-1.6, -0.9) if slowing else rng.uniform(-0.2, 0.2),
        "heading_rate": rng.normal(0, 20),
        "phi": rng.uniform(-180, 180),
        "phi_rate": rng.normal(0, 30),
        "head_yaw": rng.normal(0, 10),
        "head_toward": 0.0,  # never looks: the draws above stay the same
        "path_offset": y,
        "path_distance": gap,
    }
    return {
        "values": values,
        "position": (2.0, y),
        "future": (2.0, future_y),
        "intent": "stop" if stop else "keep going",
        "case": int(case_from_ground_velocity(0.0, future_y - y)),
        "collision": near and not stop,
    }


def write_dataset(
    folder: Path,
    families: dict[str, int],
    frames: int = 40,
    seed: int = 0,
    params: dict[str, list[dict]] | None = None,
) -> None:
    """A dataset folder as `monopic dataset` writes it, with only what the trainer reads."""
    rng = np.random.default_rng(seed)
    (folder / "features").mkdir(parents=True)
    (folder / "truth").mkdir()
    runs = []
    for family, seeds in families.items():
        for s in range(seeds):
            run = f"{family}/{s:04d}-abcdef{s:02d}"
            runs.append((run, family, 100 + s))
            (folder / "features" / family).mkdir(exist_ok=True)
            (folder / "truth" / family).mkdir(exist_ok=True)
            cols = ["frameNumber", "time", "groundX", "groundY", *FEATURE_COLUMNS.values()]
            with (folder / "features" / f"{run}.csv").open("w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(cols)
                lines = []
                for k in range(frames):
                    r = _row(rng, slowing=k % 2 == 0, near=(k // 2) % 2 == 0)
                    t = round(k / 15, 6)
                    feats = [r["values"][a] for a in FEATURE_COLUMNS]
                    w.writerow([k, f"{t:.6f}", *r["position"], *feats])
                    lines.append(
                        json.dumps(
                            {
                                "frame": k,
                                "time": t,
                                "case": r["case"],
                                "intent": r["intent"],
                                "horizon": HORIZON,
                                "future_position_robot": list(r["future"]),
                                "collision": r["collision"],
                                "robot": {
                                    "length": 0.8,
                                    "width": 0.6,
                                    "speed": ROBOT_SPEED,
                                    "yaw_rate": 0.0,
                                },
                            }
                        )
                    )
            (folder / "truth" / f"{run}.jsonl").write_text("\n".join(lines) + "\n")
    with (folder / "runs.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["run", "family", "kind", "scale", "parameters", "seed"])
        for run, family, s in runs:
            drawn = (params or {}).get(family, [{}])
            w.writerow([run, family, "near-miss", "small", json.dumps(drawn[s % len(drawn)]), s])


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("intent") / "data"
    write_dataset(folder, {"kerb-a": 4, "kerb-b": 4})
    return folder


def ground_features(values: dict[str, float], position: tuple[float, float]) -> Features:
    g = GroundFeatures(
        position=position,
        velocity=(values["forward"], values["left"]),
        camera=CAM,
        speed=values["speed"],
        acceleration=values["acceleration"],
        heading_rate=values["heading_rate"],
        path_offset=values["path_offset"],
        path_distance=values["path_distance"],
    )
    return Features(
        1.0, (400.0, 300.0), (400.0, 380.0), 160.0, values["phi"], 0.0, 0.0, g,
        phi_rate=values["phi_rate"], head_yaw=values["head_yaw"],
        head_toward=values["head_toward"],
    )  # fmt: skip


def test_the_trainer_learns_slowing_near_the_kerb_means_stop(dataset: Path) -> None:
    runs = read_dataset(dataset)
    assert len(runs) == 8 and all(len(r.rows) == 40 for r in runs)
    split = split_runs(runs)
    result = train_intent_tree(runs, split, release_times=TEST_RELEASE)
    model = result.model
    assert model.tree.root.attribute in ("acceleration", "path_distance", "path_offset")
    predictor = IntentTreePredictor(model)
    rng = np.random.default_rng(7)
    for slowing in (True, False):
        for near in (True, False):
            r = _row(rng, slowing, near)
            d = predictor.decide(ground_features(r["values"], r["position"]), HORIZON)
            assert d.reading.intent == ("stop" if slowing and near else "keep going")
            assert d.reading.support == 1.0
            err = math.hypot(d.point[0] - r["future"][0], d.point[1] - r["future"][1])
            assert err < 0.2, (slowing, near, d)
    # Holding back on stop removes constant velocity's false warnings with no new miss.
    assert model.rules.hold_back_support <= 1.0
    assert "Split by (family, seed)" in result.report


def _runs(groups: list[tuple[str, int]]) -> list[RunRows]:
    return [RunRows(f"{f}/{s}", f, s, (), 1.0) for f, s in groups]


def test_the_split_never_trains_on_an_excluded_family_and_keeps_groups_whole() -> None:
    groups = [(f, s) for f in ("cpna", "kerb", "turn", "wait") for s in range(6)]
    runs = _runs(groups + [("kerb", 0)])  # a (family, seed) group of two runs
    split = split_runs(runs, 0.3, excluded_families=["wait"])
    train = {r.group for r in split.train}
    val = {r.group for r in split.validation}
    assert not train & val and train and val
    assert all(f != "wait" for f, _ in train | val)
    assert {r.family for r in split.excluded} == {"wait"}
    assert len(split.train) + len(split.validation) + len(split.excluded) == len(runs)
    named = split_runs(runs, validation_families=["turn"], excluded_families=["wait"])
    assert {r.family for r in named.validation} == {"turn"}
    assert {r.family for r in named.train} == {"cpna", "kerb"}
    with pytest.raises(UserError, match="'walk' is in no dataset"):
        split_runs(runs, excluded_families=["walk"])
    with pytest.raises(UserError, match="both validated on and excluded"):
        split_runs(runs, validation_families=["kerb"], excluded_families=["kerb"])


def leaf_model(label: str, n: int, rules: IntentRules, mean=(0.0, 0.0)) -> IntentTreeModel:
    disc = Discretiser("one", tuple((a, CutPointBins(())) for a in INTENT_ATTRIBUTES))
    root = Node(label=label, counts=((label, n),), mean=mean)
    tree = DecisionTree(INTENT_ATTRIBUTES, root)
    return IntentTreeModel(1.0, disc, tree, rules, 0.0, ())


WALK_IN = {
    "forward": 0.0, "left": SPEED, "speed": SPEED, "acceleration": -1.2, "heading_rate": 0.0,
    "phi": 90.0, "phi_rate": 0.0, "head_yaw": 0.0, "head_toward": 0.0, "path_offset": -1.0,
    "path_distance": 0.7,
}  # fmt: skip


def test_the_predictor_holds_back_on_a_stop_leaf_and_the_warning_follows() -> None:
    on = IntentRules(hold_back_support=0.8, min_rows=20)
    f = ground_features(WALK_IN, (2.0, -1.0))
    held = IntentTreePredictor(leaf_model("6/stop", 30, on)).predict(f, 1.0)
    assert held.ground == (2.0, -1.0) and held.case is Case.PERPENDICULAR_LEFT
    plain = IntentTreePredictor(leaf_model("6/stop", 30, IntentRules())).predict(f, 1.0)
    assert plain.ground == pytest.approx((2.0, -1.0 + SPEED))  # rule off: constant velocity
    few = IntentTreePredictor(leaf_model("6/stop", 19, on)).predict(f, 1.0)
    assert few.ground == pytest.approx((2.0, -1.0 + SPEED))  # too little support
    warning = CollisionWarning(RobotGeometry(front=0.4))
    ego = EgoState(CAM, speed=ROBOT_SPEED)
    assert warning.assess(f, plain, Mode.GROUND, (768, 432), ego).collision
    assert not warning.assess(f, held, Mode.GROUND, (768, 432), ego).collision


def test_a_hold_back_is_released_when_the_band_is_nearer_than_the_release_time() -> None:
    """1.2 m from the band, 0.7 m beyond the warning's reach (ZONE_REACH), at 1.3 m/s
    toward it: 0.54 s left. A 0.5 s release still holds back, a 0.6 s one does not (the
    warning then fires as constant velocity's would)."""
    from monopic.tree.intent import ZONE_REACH
    from monopic.variants.zone import PEDESTRIAN_RADIUS

    assert math.isclose(ZONE_REACH, RobotGeometry().margin + PEDESTRIAN_RADIUS)
    f = ground_features(dict(WALK_IN, path_distance=1.2), (2.0, -1.5))
    walk_in = (2.0, -1.5 + SPEED)
    for release, held in ((0.5, True), (0.6, False), (math.inf, True)):
        rules = IntentRules(hold_back_support=0.8, min_rows=20, release_s=release)
        d = IntentTreePredictor(leaf_model("6/stop", 30, rules)).decide(f, 1.0)
        assert (d.action is Action.HOLD_STOP) is held, release
        assert d.point == pytest.approx((2.0, -1.5) if held else walk_in)
    # Walking away from the band, or standing, leaves all the time in the world.
    away = ground_features(dict(WALK_IN, left=-SPEED), (2.0, -1.0))
    rules = IntentRules(hold_back_support=0.8, min_rows=20, release_s=5.0)
    assert IntentTreePredictor(leaf_model("6/stop", 30, rules)).decide(away, 1.0).action is (
        Action.HOLD_STOP
    )
    # Inside the band (distance 0) or unknown distance: never held back under a bound.
    for dist in (0.0, math.nan):
        g = ground_features(dict(WALK_IN, path_distance=dist), (2.0, -1.0))
        d = IntentTreePredictor(leaf_model("6/stop", 30, rules)).decide(g, 1.0)
        assert d.action is Action.NONE
    # A turn-away leaf is released the same way.
    turn = IntentTreePredictor(leaf_model("8/turn away", 30, replace(rules, release_s=0.6)))
    assert turn.decide(f, 1.0).action is Action.NONE
    assert turn.decide(f, 1.0).ops.total <= worst_case_ops(turn.model).total
    with pytest.raises(ValueError, match="release_s must be > 0"):
        IntentRules(release_s=0.0)
    with pytest.raises(ValueError, match="release_s must be > 0"):
        IntentRules(release_s=math.nan)
    assert IntentRules.from_json(IntentRules(release_s=1.3).to_json()).release_s == 1.3
    assert IntentRules.from_json(IntentRules().to_json()).release_s == math.inf
    old = {k: v for k, v in IntentRules().to_json().items() if k != "release_s"}
    assert IntentRules.from_json(old).release_s == math.inf  # files before release_s


def test_the_rules_read_shares_at_the_deepest_node_with_enough_rows() -> None:
    # A leaf of 8 rows, all "keep going", under a node of 100 where a third stop or turn.
    leaf = Node(label="6/keep going", counts=(("6/keep going", 8),), mean=(0.0, 0.0))
    other = Node("6/keep going", (("6/keep going", 59), ("6/stop", 33)), mean=(0.0, 0.0))
    parent = Node(
        attribute="speed",
        label="6/keep going",
        counts=(("6/keep going", 67), ("6/stop", 21), ("6/turn away", 12)),
        mean=(0.0, 0.0),
        branches=((0, leaf), (1, other)),
    )
    reading = LeafReading.on_path([parent, leaf], min_rows=20)
    assert reading.intent == "keep going" and reading.support == 1.0  # the leaf's own
    assert reading.rows == 100 and reading.hold_share == pytest.approx(0.33)
    assert reading.hold_intent == "stop"  # 21 stops against 12 turns
    assert LeafReading.on_path([parent, leaf], min_rows=5).hold_share == 0.0
    # A third is not the majority, yet holds back at a share of 0.3.
    f = ground_features(WALK_IN, (2.0, -1.0))
    point, action, _ = place(f.ground.position, f.ground.velocity, reading,
                             IntentRules(hold_back_support=0.3, min_rows=20), 1.0, 1.0)  # fmt: skip
    assert action is Action.HOLD_STOP and point == (2.0, -1.0)
    _, action, _ = place(f.ground.position, f.ground.velocity, reading,
                         IntentRules(hold_back_support=0.4, min_rows=20), 1.0, 1.0)  # fmt: skip
    assert action is Action.NONE


def test_turn_away_drops_the_motion_toward_the_path_and_start_crossing_adds_it() -> None:
    on = IntentRules(hold_back_support=0.8, warn_support=0.8, min_rows=5, start_speed=1.0)
    f = ground_features(WALK_IN, (2.0, -1.0))
    turn = IntentTreePredictor(leaf_model("8/turn away", 10, on, mean=(0.5, -0.2)))
    d = turn.decide(f, 1.0)
    assert d.action is Action.HOLD_TURN and d.point == pytest.approx((2.5, -1.0))
    standing = dict(WALK_IN, left=0.0, speed=0.0)
    g = ground_features(standing, (3.0, 1.5))  # left of the path: toward it is -y
    start = IntentTreePredictor(leaf_model("9/start crossing", 10, on)).decide(g, 1.0)
    assert start.action is Action.EARLIER and start.point == pytest.approx((3.0, 0.5))
    off = IntentTreePredictor(leaf_model("9/start crossing", 10, IntentRules(min_rows=5)))
    assert off.decide(g, 1.0).point == pytest.approx((3.0, 1.5))
    # On the centre line there is no "toward": start crossing adds nothing, turn away
    # drops all lateral motion (any of it counts as away, as the labels say).
    centre = ground_features(standing, (3.0, 0.0))
    on_line = IntentTreePredictor(leaf_model("9/start crossing", 10, on)).decide(centre, 1.0)
    assert on_line.action is Action.NONE and on_line.point == pytest.approx((3.0, 0.0))
    walking = ground_features(WALK_IN, (3.0, 0.0))
    assert turn.decide(walking, 1.0).point == pytest.approx((3.5, 0.0))


def test_operation_counts_are_counted_as_run_and_bounded_by_the_worst_case() -> None:
    on = IntentRules(hold_back_support=0.8, warn_support=0.8, min_rows=5)
    model = leaf_model("9/start crossing", 10, on)
    g = ground_features(dict(WALK_IN, left=0.0, speed=0.0), (3.0, -1.5))
    d = IntentTreePredictor(model).decide(g, 1.0)
    assert d.action is Action.EARLIER
    worst = worst_case_ops(model)
    assert d.ops.total == worst.total  # this input takes the dearest path
    assert d.placement_ops.comparisons == 9 and d.placement_ops.arithmetic == 14
    plain = IntentTreePredictor(leaf_model("6/keep going", 10, on)).decide(g, 1.0)
    assert plain.ops.total < worst.total


def test_a_tree_file_round_trips_and_old_files_still_load(dataset: Path, tmp_path: Path) -> None:
    runs = read_dataset(dataset)
    model = train_intent_tree(runs, split_runs(runs), release_times=TEST_RELEASE).model
    path = tmp_path / "ground.json"
    save_model(model, path)
    again = load_intent_model(path)
    assert again == model
    assert json.loads(path.read_text())["version"] == 3
    assert load_default_model().mode is Mode.IMAGE  # the shipped version-1 tree
    with pytest.raises(
        UserError, match="ground intent tree .* use it with predictor 'intent-tree'"
    ):
        load_model(path)
    shipped = Path(__file__).parents[2] / "monopic" / "tree" / "default_tree.json"
    with pytest.raises(UserError, match="not a ground intent tree"):
        load_intent_model(shipped)


def test_train_and_show_commands(
    dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "trees" / "ground.json"
    argv = ["tree", "train", "--mode", "ground", str(dataset), "--out", str(out)]
    assert main([*argv, "--exclude-family", "kerb-b"]) == 0
    text = capsys.readouterr().out
    assert "excluded" in text and "wrote" in text
    model = load_intent_model(out)
    split = model.provenance["split"]
    assert not any(r.startswith("kerb-b/") for r in split["train"] + split["validation"])
    assert all(r.startswith("kerb-b/") for r in split["excluded"]) and split["excluded"]
    assert main(["tree", "show", str(out)]) == 0
    assert "ID3 intent tree, ground mode" in capsys.readouterr().out
    assert main(["tree", "show", str(out), "--dot"]) == 0
    assert capsys.readouterr().out.startswith("digraph")


def one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip()
    assert err and "\n" not in err, err
    return err


def _train(folder: Path, tmp_path: Path) -> list[str]:
    return ["tree", "train", "--mode", "ground", str(folder), "--out", str(tmp_path / "t.json")]


def test_bad_input_is_one_line_naming_file_and_field(
    dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(_train(tmp_path, tmp_path)) == 2
    assert "not a dataset folder (no runs.csv)" in one_line_error(capsys)

    broken = tmp_path / "broken"
    write_dataset(broken, {"kerb-a": 2}, frames=4)
    run = "kerb-a/0000-abcdef00"
    features = broken / "features" / f"{run}.csv"
    text = features.read_text()
    features.write_text(text.replace("groundAcceleration", "groundAccel", 1))
    assert main(_train(broken, tmp_path)) == 2
    assert f"{features}: no column 'groundAcceleration'" in one_line_error(capsys)

    features.write_text(text)
    truth = broken / "truth" / f"{run}.jsonl"
    lines = truth.read_text().splitlines()
    lines[2] = lines[2].replace('"intent": "', '"intent": "dawdle', 1)
    truth.write_text("\n".join(lines) + "\n")
    assert main(_train(broken, tmp_path)) == 2
    assert f"{truth}: line 3: intent = 'dawdle" in one_line_error(capsys)

    assert main([*_train(dataset, tmp_path), "--leaf-value", "velocity-gain"]) == 2
    assert "--leaf-value: image mode only" in one_line_error(capsys)
    assert not (tmp_path / "t.json").exists()


def test_corrections_shrink_toward_constant_velocity_by_row_count() -> None:
    from monopic.tree.intent import LeafReading, shrink_corrections

    tree = leaf_model("6/stop", 30, IntentRules(), mean=(1.0, -2.0)).tree
    half = shrink_corrections(tree, 30.0)
    assert half.root.mean == pytest.approx((0.5, -1.0))
    assert shrink_corrections(tree, None).root.mean == (0.0, 0.0)
    assert shrink_corrections(tree, 0.0) == tree
    assert LeafReading.of(half.root).intent == "stop"  # the rules read the same counts
    with pytest.raises(ValueError, match="shrink"):
        shrink_corrections(tree, -1.0)


def _timed_run(kind: str, collisions: list[bool], contact: float | None) -> RunRows:
    """A run of frames at 0.25 s steps; a frame on a collision course from its first
    collision frame on (enough for counting: the rows' samples are never read)."""
    first = collisions.index(True) if True in collisions else len(collisions)
    rows = tuple(
        LabelledRow(None, c, RobotGeometry(0.6, 0.8, 0.4), 2.0, 0.0, k * 0.25, k >= first)  # type: ignore[arg-type]
        for k, c in enumerate(collisions)
    )
    return RunRows(f"f/{kind}", "f", 0, rows, 1.5, kind, contact)


def test_run_counts_follow_the_sweep_metrics_definitions() -> None:
    hit = _timed_run("collision", [False, False, True, True, True, True, True], 1.75)
    near = _timed_run("near-miss", [False] * 4, None)
    runs = [hit, near]
    # A warning before the collision course does not count as the onset.
    early = [True, False, False, False, False, False, False] + [False] * 4
    assert count_runs(early, runs) == RunCount(1, 0, 1, 0, (("f", 0),))
    # Onset at 0.5 s, contact at 1.75 s: 1.25 s ahead; at 1.0 s it is only 0.75 s ahead.
    assert (
        count_runs([False, False, True, False, False, False, False] + [False] * 4, runs).warned_1s
        == 1
    )
    assert count_runs([False] * 4 + [True] * 3 + [False] * 4, runs).warned_1s == 0
    on_time = count_runs([False, False, True, False, False, False, False] + [False] * 4, runs)
    assert on_time.warned_1s_by_family == (("f", 1),)
    assert on_time.mean_lead == pytest.approx(1.25)  # the lead of every warned run
    # Any warning on a near miss counts it as warned.
    assert count_runs([False] * 7 + [False, False, True, False], runs).near_miss_warned == 1
    with pytest.raises(ValueError, match="flags for 11 rows"):
        count_runs([True], runs)


def test_rules_are_chosen_for_fewest_near_misses_at_the_recall_of_constant_velocity() -> None:
    def option(hold: float, a: int, b: int, nm: int, false_alarms: int = 0) -> RuleOption:
        # a, b: collision runs warned 1 s ahead in families "a" and "b"
        return RuleOption(
            IntentRules(hold_back_support=hold),
            0.0,
            None,  # type: ignore[arg-type]
            WarningCount(0, false_alarms, 10, 100),
            RunCount(10, a + b, 6, nm, (("a", a), ("b", b))),
        )

    cv = option(1.01, 2, 2, 3).runs
    options = [
        option(1.01, 2, 2, 3),
        option(0.7, 2, 2, 1, 9),
        option(0.5, 2, 1, 0),  # fewest near misses, but family b loses a run
        option(0.4, 3, 1, 0),  # as many in all as constant velocity, yet b loses one
        option(0.6, 2, 2, 1, 2),
    ]
    assert choose_rules(options, cv).rules.hold_back_support == 0.6  # nm 1, fewer false frames
    # When no option keeps constant velocity's recall, the one warning most runs in time.
    worse = [option(0.5, 1, 1, 0), option(0.7, 2, 1, 2)]
    assert choose_rules(worse, cv).rules.hold_back_support == 0.7
    # Equal on runs, the longer release time wins over fewer false frames.
    short, long = option(0.6, 2, 2, 1, 2), option(0.6, 2, 2, 1, 9)
    short = replace(short, rules=replace(short.rules, release_s=1.1))
    long = replace(long, rules=replace(long.rules, release_s=1.4))
    assert choose_rules([short, long], cv).rules.release_s == 1.4


def test_sensitivity_replays_every_predictor_per_cue_value(
    dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from monopic.tree.intent_sensitivity import sensitivity

    folder = tmp_path / "sens"
    lead = "pedestrian.behaviour.stop_lead"
    drawn = [{lead: 0.0, "pedestrian.behaviour.turn_lead": 0.0,
              "pedestrian.behaviour.head_check_probability": 0.0}, {lead: 0.4}]  # fmt: skip
    write_dataset(folder, {"kerb-c": 4}, seed=3, params={"kerb-c": drawn})
    runs = read_dataset(dataset)
    model = train_intent_tree(runs, split_runs(runs), release_times=TEST_RELEASE).model
    judged = read_dataset(folder)
    s = sensitivity(judged, {"full": model}, [lead])
    assert s.predictors == ("constant velocity", "full") and s.runs == 4
    assert set(s.by_value[lead]) == {0.0, 0.4}
    for cells in s.by_value[lead].values():
        # Every hand-made run has frames with contact ahead (and no contact time).
        assert (
            cells["full"].runs.collision_runs == 2 == cells["constant velocity"].runs.collision_runs
        )
        # The tree learnt that slowing near the kerb means stop; constant velocity did not.
        full, cv = cells["full"].frames, cells["constant velocity"].frames
        assert full.false_alarms < 0.5 * cv.false_alarms and full.misses <= cv.misses
    assert s.body_off["full"].runs.collision_runs == 2 == s.body_on["full"].runs.collision_runs
    tree = tmp_path / "full.json"
    save_model(model, tree)
    out = tmp_path / "report"
    argv = ["tree", "sensitivity", str(folder), "--tree", f"full={tree}", "--by", lead]
    assert main([*argv, "--out", str(out)]) == 0
    assert (out / "sensitivity.png").stat().st_size > 0
    assert "## Body cues off" in (out / "report.md").read_text()
    capsys.readouterr()
    assert main([*argv[:-2], "--by", "scene.road.lane_width", "--out", str(out)]) == 2
    assert "--by scene.road.lane_width: no run of the data sets it" in one_line_error(capsys)
    wide = tmp_path / "wide"
    drawn_wide = [{lead: round(0.01 * k, 2)} for k in range(20)]
    write_dataset(wide, {"kerb-d": 20}, seed=4, params={"kerb-d": drawn_wide})
    wide_argv = ["tree", "sensitivity", str(wide), "--tree", f"full={tree}", "--by", lead]
    assert main([*wide_argv, "--out", str(out)]) == 2
    assert "the runs take 20 values of it" in one_line_error(capsys)
    assert main(["tree", "sensitivity", str(folder), "--tree", str(tree), "--out", str(out)]) == 2
    assert "give NAME=TREE.json" in one_line_error(capsys)


def test_the_shipped_ground_tree_is_what_its_card_says() -> None:
    """monopic/tree/ground_tree.json against monopic/tree/GROUND_TREE.md."""
    from monopic.predict.registry import make_predictor
    from monopic.tree.serialise import shipped_ground_tree

    model = load_intent_model(shipped_ground_tree())
    card = (shipped_ground_tree().parent / "GROUND_TREE.md").read_text()
    p = model.provenance
    assert model.horizon == 1.5 and "1.5 s" in card
    assert (len(p["split"]["train"]), len(p["split"]["validation"])) == (258, 78)
    assert "258 runs" in card and "78 runs" in card
    assert p["chosen"] == {"binning": "mdl", "max_depth": 4, "shrink_rows": None}
    assert (model.rules.hold_back_support, model.rules.min_rows) == (0.05, 20)
    assert model.rules.warn_support > 1  # warn earlier: off
    assert f"{sum(n.is_leaf for n in model.tree.nodes()):,} leaves" in card
    assert f"{worst_case_ops(model).total} operations per prediction at worst" in card
    assert p["validation"]["runs"].startswith("31/32") and "2/41" in p["validation"]["runs"]
    predictor = make_predictor("intent-tree", Mode.GROUND)  # no file: the shipped tree
    assert isinstance(predictor, IntentTreePredictor) and predictor.model.tree == model.tree


def test_the_split_can_validate_above_the_training_ranges() -> None:
    runs = [
        replace(run, params={"pedestrian.speed": 1.1 + 0.05 * k, "robot.speed": 2.0})
        for k, run in enumerate(_runs([("kerb", s) for s in range(8)]))
    ]
    split = split_runs(runs, validate_above={"pedestrian.speed": 1.3})
    assert [r.params["pedestrian.speed"] for r in split.validation] == pytest.approx(
        [1.3, 1.35, 1.4, 1.45]
    )
    assert all(r.params["pedestrian.speed"] < 1.3 for r in split.train)
    either = split_runs(runs, validate_above={"pedestrian.speed": 1.4, "robot.speed": 3.0})
    assert len(either.validation) == 2
    with pytest.raises(UserError, match=r"run kerb/0: parameter 'lane' = None: not a swept number"):
        split_runs(runs, validate_above={"lane": 3.0})
    with pytest.raises(UserError, match="not both"):
        split_runs(runs, validation_families=["kerb"], validate_above={"robot.speed": 1.0})
    with pytest.raises(UserError, match="0 validation runs"):
        split_runs(runs, validate_above={"pedestrian.speed": 9.0})


def test_validate_above_is_checked_on_the_command_line(
    dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as stop:
        main([*_train(dataset, tmp_path), "--validate-above", "pedestrian.speed"])
    assert stop.value.code == 2
    assert "expected PARAM=VALUE, got 'pedestrian.speed'" in capsys.readouterr().err
    assert main([*_train(dataset, tmp_path), "--validate-above", "pedestrian.speed=1.3"]) == 2
    assert "parameter 'pedestrian.speed' = None" in one_line_error(capsys)


def test_no_release_bound_counts_as_no_lead_in_hand() -> None:
    def option(release: float, false_alarms: int) -> RuleOption:
        return RuleOption(
            IntentRules(hold_back_support=0.5, release_s=release),
            0.0,
            None,  # type: ignore[arg-type]
            WarningCount(0, false_alarms, 10, 100),
            RunCount(10, 4, 6, 1, (("a", 4),)),
        )

    cv = option(1.1, 0).runs
    # Equal on runs: a bounded hold-back keeps lead in hand, no bound keeps none.
    assert choose_rules([option(math.inf, 0), option(1.1, 5)], cv).rules.release_s == 1.1
