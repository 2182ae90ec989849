"""studies.intent.cue_auc: the AUC, the decisive rows, the per-family view, and wrong input as
one line."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from monopic.cases import Case
from monopic.tree.intent import IntentSample
from monopic.tree.intent_training import LabelledRow, RunRows
from monopic.variants.zone import RobotGeometry
from studies.intent import cue_auc
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.cue_auc"]


def labelled(
    t: float,
    intent: str,
    position: tuple[float, float],
    velocity: tuple[float, float],
    values: dict[str, float] | None = None,
) -> LabelledRow:
    """A training row of a small robot (0.6 m wide) standing still, the future unused."""
    robot = RobotGeometry(width=0.6, length=0.8, front=0.4)
    s = IntentSample(values or {}, Case.STILL, intent, position, velocity, position)
    return LabelledRow(s, False, robot, 1.0, 0.0, time=t)


def test_auc_of_separated_reversed_tied_and_empty_groups() -> None:
    assert cue_auc.auc([3.0, 4.0], [1.0, 2.0]) == 1.0
    assert cue_auc.auc([1.0, 2.0], [3.0, 4.0]) == 0.0
    assert cue_auc.auc([1.0, 1.0], [1.0, 1.0, 1.0]) == 0.5
    assert math.isnan(cue_auc.auc([], [1.0]))


def test_auc_is_the_share_of_pairs_ordered_right() -> None:
    rng = np.random.default_rng(3)
    pos, neg = rng.integers(0, 5, 30).astype(float), rng.integers(0, 5, 40).astype(float)
    pairs = [(p > n) + 0.5 * (p == n) for p in pos for n in neg]
    assert cue_auc.auc(list(pos), list(neg)) == pytest.approx(np.mean(pairs))


def test_a_folder_that_is_no_dataset_is_one_line(tmp_path: Path) -> None:
    r = subprocess.run(
        [*TOOL, str(tmp_path)], capture_output=True, text=True, timeout=120, cwd=ROOT
    )
    assert r.returncode == 2 and r.stdout == ""
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"cue_auc: {tmp_path}: not a dataset folder")


def test_decisive_rows_are_those_where_constant_velocity_reaches_the_band_from_outside() -> None:
    def row(y: float, vl: float) -> LabelledRow:
        return labelled(math.nan, "stop", (5.0, y), (0.0, vl))

    rows = (row(-2.0, 1.5), row(-2.0, 0.2), row(0.1, 0.0), row(2.0, -1.3), row(-2.0, float("nan")))
    run = RunRows("r", "f", 0, rows, horizon=1.0)
    kept = cue_auc.decisive_rows([run])
    assert [s.position[1] * s.velocity[1] for s in kept] == [-3.0, -2.6]  # rows 1 and 4


def test_family_medians_split_the_decisive_rows_by_what_lies_ahead() -> None:
    def row(t: float, intent: str, speed: float, acc: float, y: float = -2.0) -> LabelledRow:
        return labelled(t, intent, (5.0, y), (0.0, 1.5), {"speed": speed, "acceleration": acc})

    stops = RunRows(
        "a", "kerb", 0, (row(2.0, "stop", 0.9, 1.2), row(2.2, "turn away", 1.1, 0.8)), 1.0
    )
    walks = RunRows(
        "b", "kerb", 1,
        (row(3.0, "keep going", 1.3, 0.1), row(3.1, "keep going", 1.3, 0.2, y=0.1)),  # in band
        1.0,
    )  # fmt: skip
    got = [g[:6] for g in cue_auc.family_medians([stops, walks])]
    assert got == [("kerb", False, 1, 3.0, 1.3, 0.1), ("kerb", True, 2, 2.1, 1.0, 1.0)]
    truth = {"a": {1.8: 0.9, 2.0: 0.8, 2.2: 0.7}, "b": {3.0: 1.3}}  # b: nothing 0.2 s back
    walk, stop = cue_auc.family_medians([stops, walks], truth)
    assert walk[6] == 1.3 and math.isnan(walk[7])
    assert stop[6] == pytest.approx(0.75)  # the true speeds 0.8 and 0.7
    assert stop[7] == pytest.approx(-0.5)  # both slowing by 0.1 m/s over 0.2 s
    assert stop[8] == walk[8] == 1.5  # the track's speed: |(0, 1.5)|


def test_by_family_on_a_dataset_whose_truth_has_no_speed_is_one_line(tmp_path: Path) -> None:
    from tests.monopic.test_intent_tree import write_dataset

    write_dataset(tmp_path / "d", {"kerb-a": 1})  # its truth lines carry no "speed"
    r = subprocess.run(
        [*TOOL, str(tmp_path / "d"), "--by-family"],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 2 and r.stdout == ""
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("cue_auc: ") and "cannot read the truth's speed" in line


def test_the_plot_draws_one_run_per_family_preferring_one_with_a_stop_ahead(
    tmp_path: Path,
) -> None:
    def row(t: float, intent: str) -> LabelledRow:
        return labelled(t, intent, (5.0, -2.0), (0.0, 1.5), {"speed": 1.0})

    walk = RunRows("kerb/0", "kerb", 0, (row(1.0, "keep going"),), 1.0)
    stop = RunRows("kerb/1", "kerb", 1, (row(1.0, "keep going"), row(1.1, "stop")), 1.0)
    cross = RunRows("cross/0", "cross", 0, (row(2.0, "keep going"),), 1.0)
    png = tmp_path / "p.png"
    drawn = cue_auc.plot_runs([walk, stop, cross], {"kerb/1": {1.0: 0.9}}, png)
    assert drawn == ["cross/0", "kerb/1"] and png.read_bytes()[:4] == b"\x89PNG"


def test_plot_without_by_family_is_one_line(tmp_path: Path) -> None:
    r = subprocess.run(
        [*TOOL, str(tmp_path), "--plot", str(tmp_path / "p.png")],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.strip() == "cue_auc: --plot draws the --by-family view; give both"
