"""`monopic tree judge`: the leave-one-file-out split, the velocity-gain leaves and their
file format, the 1 s horizon metric on hand-made logs with known motion, bad input."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from monopic.cases import Case
from monopic.cli.main import main
from monopic.features.record import Features
from monopic.predict.constant_velocity import ConstantVelocityPredictor
from monopic.replay.dataset import prepare, window_velocities
from monopic.replay.judge import (
    candidate_grid,
    judge_leave_one_out,
    leave_one_out,
    median_error,
    predict_centres,
)
from monopic.replay.logs import COLUMNS, read_log
from monopic.replay.training import TrainOptions, train_on_logs
from monopic.tree.model import (
    GAIN_PLACEMENT_OPS,
    LeafValue,
    Placement,
    TrainingSample,
    TreePredictor,
    fit_model,
    velocity_gain,
)
from monopic.tree.opcount import prediction_ops, worst_case_prediction_ops
from monopic.tree.serialise import dumps, load_default_model, load_model, model_from_json
from tests.paths import AUTHORS_LOGS

SHARED_LOGS = AUTHORS_LOGS  # read where the workspace keeps them, never copied
DT = 0.05
HEIGHT_PX = 200.0


def write_log(path: Path, t: np.ndarray, x: np.ndarray, y: np.ndarray, phi: float = 90.0) -> Path:
    """An authors'-format log of a centre moving along (x, y) at times t."""
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for i, (ti, xi, yi) in enumerate(zip(t, x, y, strict=True)):
            row = {c: 0.0 for c in COLUMNS}
            row.update(
                frameNumber=i, windowSize=4, XYError=10, timeToFuture=1, time=1000.0 + ti,
                fps=0 if i == 0 else 1 / DT, currentCenterX=xi, currentCenterY=yi,
                angleOfApproach=phi + 10 * np.sin(ti), occupiedHeights=HEIGHT_PX / 432,
                predictedX=xi, predictedY=yi,
            )  # fmt: skip
            w.writerow([repr(float(row[c])) for c in COLUMNS])
    return path


def walk(path: Path, vx: float, vy: float, seconds: float = 6.0) -> Path:
    t = np.arange(0.0, seconds, DT)
    return write_log(path, t, 300 + vx * t, 200 + vy * t)


def test_leave_one_out_never_holds_the_judged_index():
    for n in range(2, 7):
        splits = leave_one_out(n)
        assert [k for k, _ in splits] == list(range(n))
        for k, train in splits:
            assert k not in train and sorted(train) == [j for j in range(n) if j != k]
    with pytest.raises(ValueError, match="at least 2"):
        leave_one_out(1)


def test_constant_velocity_is_exact_on_a_steady_walk(tmp_path):
    p = prepare(read_log(walk(tmp_path / "w.csv", 60.0, -20.0)), velocity_window=0.5)
    pred, _ = predict_centres(ConstantVelocityPredictor(), p)
    assert p.scored.sum() > 50
    assert median_error(p, pred) == pytest.approx(0.0, abs=1e-6)


def test_judge_metric_on_an_accelerating_walk_gives_the_known_error(tmp_path):
    # x = a t^2 / 2. The least-squares slope over the 11 samples of [t - 0.5, t] is the
    # speed at their mean time t - 0.25; so the 1 s prediction is x(t) + a (t - 0.25)
    # and the truth x(t + 1) = x(t) + a t + a / 2: the error is 0.75 a, on every row.
    a = 40.0
    t = np.arange(0.0, 5.0, DT)
    log = read_log(write_log(tmp_path / "acc.csv", t, 100 + a * t**2 / 2, 200 + 0 * t))
    p = prepare(log, velocity_window=0.52)  # 0.52: the sample at t - 0.5 despite rounding
    vel = window_velocities(log, 0.52)
    scored = np.flatnonzero(p.scored)
    assert np.allclose(vel[scored, 0], a * (log.time[scored] - log.time[0] - 0.25))
    pred, _ = predict_centres(ConstantVelocityPredictor(), p)
    assert median_error(p, pred) == pytest.approx(0.75 * a, abs=1e-6)


def test_velocity_gain_is_the_weighted_median_shrunk_toward_one():
    v = np.array([1.0, 2.0, 3.0, -1.0])
    assert velocity_gain(2 * v, v, 0.0) == pytest.approx(2.0)
    assert velocity_gain(2 * v, v, 4.0) == pytest.approx(1.5)  # 4 rows, shrink 4: halfway
    # One tracker jump does not move the (weighted median) gain; it would move a mean.
    jump = 2 * v
    jump[0] = 400.0
    assert velocity_gain(jump, v, 0.0) == pytest.approx(2.0)
    assert velocity_gain(np.ones(3), np.zeros(3), 0.0) == 1.0  # no motion: no evidence


def _gain_samples() -> list[TrainingSample]:
    """Rightward walkers who go on twice as fast, leftward ones who stop."""
    out = []
    for k in range(12):
        out.append(
            TrainingSample({"phi": 10.0, "vx": 40.0 + k, "vy": 0.0}, Case.PERPENDICULAR_RIGHT,
                           (0.4, 0.0), velocity_displacement=(0.2, 0.0))
        )  # fmt: skip
        out.append(
            TrainingSample({"phi": 170.0, "vx": -40.0 - k, "vy": 0.0}, Case.STILL,
                           (0.0, 0.0), velocity_displacement=(-0.2, 0.0))
        )  # fmt: skip
    return out


def test_gain_leaves_scale_the_measured_velocity_and_round_trip(tmp_path):
    model = fit_model(_gain_samples(), leaf_value=LeafValue.VELOCITY_GAIN, shrink=0.0)
    pred = TreePredictor(model, Placement.LEAF)
    right = Features(0.0, (100.0, 50.0), (100.0, 150.0), HEIGHT_PX, 10.0, 50.0, 0.0)
    left = Features(0.0, (100.0, 50.0), (100.0, 150.0), HEIGHT_PX, 170.0, -50.0, 0.0)
    assert pred.predict(right, 1.0).center == pytest.approx((200.0, 50.0))  # gain 2
    assert pred.predict(left, 1.0).center == pytest.approx((100.0, 50.0))  # gain 0
    assert pred.predict(left, 1.0).case is Case.STILL
    assert prediction_ops(pred, right, 1.0).placement == GAIN_PLACEMENT_OPS
    assert worst_case_prediction_ops(pred).placement == GAIN_PLACEMENT_OPS
    text = dumps(model)
    data = json.loads(text)
    assert (data["version"], data["leaf_value"]) == (2, "velocity-gain")
    path = tmp_path / "gain.json"
    path.write_text(text)
    assert load_model(path) == model
    data["version"] = 1  # a version-1 file cannot say its leaves are gains
    with pytest.raises(ValueError, match="version-2 field"):
        model_from_json(data)


def test_old_tree_files_still_load_as_displacement_trees():
    model = load_default_model()
    assert model.leaf_value is LeafValue.DISPLACEMENT
    data = json.loads(dumps(model))
    assert data["version"] == 1 and "leaf_value" not in data


def test_judge_trains_each_fold_without_the_judged_log(tmp_path):
    paths = [walk(tmp_path / f"w{k}.csv", 30.0 * (k + 1), 5.0 * k) for k in range(3)]
    logs = [read_log(p) for p in paths]
    judged = [prepare(log, velocity_window=0.5) for log in logs]
    views = [prepare(log) for log in logs]
    grid = candidate_grid(depths=(1, 2), shrinks=(10.0,), dead_zones=(15.0,))
    results = judge_leave_one_out(judged, views, load_default_model(), grid)
    for r, log in zip(results, logs, strict=True):
        names = [d["name"] for d in r.model.provenance["data"]]
        shas = [d["sha256"] for d in r.model.provenance["data"]]
        assert log.name not in names and log.sha256 not in shas and len(names) == 2
        assert r.training == tuple(names)
        assert not r.shipped_in_sample
        # Steady walks: constant velocity is exact, and the tree learnt gain 1 from them.
        assert r.stats(r.constant_velocity).median == pytest.approx(0.0, abs=1e-6)
        assert r.stats(r.tree).median == pytest.approx(0.0, abs=1e-6)


def _one_error_line(capsys, *needles: str) -> None:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, (needle, err)


def test_judge_bad_input_is_one_line(tmp_path, capsys):
    good = [walk(tmp_path / f"w{k}.csv", 30.0, 0.0) for k in range(3)]
    out = tmp_path / "out" / "table.md"
    assert main(["tree", "judge", *map(str, good[:2]), "--out", str(out)]) == 2
    _one_error_line(capsys, "at least 3")
    missing = tmp_path / "nope.csv"
    assert main(["tree", "judge", *map(str, good[:2]), str(missing), "--out", str(out)]) == 2
    _one_error_line(capsys, "nope.csv", "cannot read")
    bad = tmp_path / "bad.csv"
    bad.write_text(good[0].read_text().replace("angleOfApproach", "angle", 1))
    assert main(["tree", "judge", *map(str, good[:2]), str(bad), "--out", str(out)]) == 2
    _one_error_line(capsys, "bad.csv", "'angleOfApproach'")
    cell = tmp_path / "cell.csv"
    lines = good[0].read_text().splitlines()
    cells = lines[3].split(",")
    cells[COLUMNS.index("currentCenterY")] = "north"
    cell.write_text("\n".join([*lines[:3], ",".join(cells), *lines[4:]]) + "\n")
    assert main(["tree", "judge", *map(str, good[:2]), str(cell), "--out", str(out)]) == 2
    _one_error_line(capsys, "cell.csv", "line 4", "'currentCenterY'", "'north'")
    assert main(["tree", "judge", *map(str, good[:2]), str(good[0])]) == 2
    _one_error_line(capsys, "w0.csv", "given twice")
    assert not out.parent.exists()  # nothing written on bad input


def test_judge_writes_the_table_atomically(tmp_path, capsys):
    logs = [walk(tmp_path / f"w{k}.csv", 20.0 * (k + 1), -10.0) for k in range(3)]
    out = tmp_path / "out" / "table.md"
    assert main(["tree", "judge", *map(str, logs), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    text = out.read_text()
    assert text in printed
    assert sum(line.startswith("| w") for line in text.splitlines()) == 6  # two tables
    assert sorted(p.name for p in out.parent.iterdir()) == ["table.md"]


@pytest.mark.skipif(not SHARED_LOGS.is_dir(), reason=f"authors' logs not at {SHARED_LOGS}")
def test_on_the_authors_logs_no_fold_sees_its_judged_log():
    logs = [read_log(SHARED_LOGS / f"data{k}.csv") for k in range(4)]
    judged = [prepare(log, velocity_window=0.5) for log in logs]
    views = [prepare(log) for log in logs]
    results = judge_leave_one_out(judged, views, load_default_model(), candidate_grid())
    for r, log in zip(results, logs, strict=True):
        assert log.sha256 not in [d["sha256"] for d in r.model.provenance["data"]]
        assert r.shipped_in_sample  # the shipped tree was trained on all four
        assert r.model.leaf_value is LeafValue.VELOCITY_GAIN
        assert r.selection.options.max_depth in (1, 2, 3)
    # The trees are not degenerate: more than one case among their answers.
    assert len({c for r in results for c in r.tree_cases}) > 1
    assert (
        train_on_logs(judged[:2], TrainOptions()).provenance["velocity"].startswith("least-squares")
    )
