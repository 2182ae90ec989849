"""Metrics on hand-made result rows whose answers are known by construction."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from monopic.cases import Case
from sim.analysis.metrics import (
    FrameCounts,
    RunOutcome,
    available_times,
    case_summary,
    compute,
    judge_run,
    paired_difference,
    paired_recall,
    position_summary,
    summarise,
    wilson,
)
from sim.analysis.report import sweeps_line, write_report
from sim.runs.result import RunResult

DT = 0.1
KEY = "rules/image"


def row(
    run_id: str,
    ttc: list[float | None],
    warn: list[int | None],
    *,
    horizon: float = 0.5,
    kind: str = "collision",
    family: str = "fam",
    scale: str = "small",
    case: list[int] | None = None,
    pred_case: list[int | None] | None = None,
    pose_ms: float = 10.0,
    robot_speed: float = 2.0,
) -> RunResult:
    """A result record with hand-made columns (what the metrics read; the rest plain)."""
    n = len(ttc)
    t = [round(k * DT, 4) for k in range(n)]
    foot = [[100.0 + 10 * k, 200.0] for k in range(n)]
    decisions = {
        KEY: {
            "warn": warn,
            "case": pred_case or [5 if w is not None else None for w in warn],
            # The prediction at k is the true foot 5 frames (the horizon) later + (3, 4) px.
            "foot": [
                [100.0 + 10 * (k + 5) + 3, 204.0] if warn[k] is not None else None for k in range(n)
            ],  # fmt: skip
            "ground": [None] * n,
            "ttc": [None] * n,
        }
    }
    return RunResult.from_json(
        {
            "schema": 1,
            "id": run_id,
            "family": family,
            "kind": kind,
            "scale": scale,
            "seed": 1,
            "params": {},
            "scenario": {
                "name": run_id,
                "case": None,
                "robot_speed": robot_speed,
                "robot_width": 0.6,
                "robot_length": 0.8,
                "horizon": horizon,
                "dt": DT,
                "duration": n * DT,
                "camera": {
                    "width": 320,
                    "height": 180,
                    "vertical_fov_deg": 65.0,
                    "mount_height": 1.2,
                    "pitch_deg": 5.0,
                },
                "pedestrian_height": 1.8,
                "pedestrian_speed": 1.4,
                "occluders": 0,
            },
            "truth": {
                "t": t,
                "ttc": ttc,
                "collision": [int(c is not None and c <= horizon) for c in ttc],
                "case": case or [5] * n,
                "phi": [0.0] * n,
                "range": [5.0] * n,
                "height": [100.0] * n,
                "in_frame": [1] * n,
                "visible": [1.0] * n,
                "foot": foot,
                "future": [[1.0, 0.0]] * n,
            },
            "pipelines": {
                "main": {"found": [1] * n, "phi": [10.0] * n, "decisions": decisions},
            },
            "timing": {
                "ms": {
                    "main": {
                        "pose": [pose_ms] * n,
                        "features": [0.0] * n,
                        "predict": [0.0] * n,
                        "warning": [0.0] * n,
                        "total": [pose_ms] * n,
                    }
                },
                "machine": {"cpu": "test", "cores": 1},
            },
        }
    )


def collision_row(run_id: str, first_warning: int | None, **kw: Any) -> RunResult:
    """20 frames, contact at t = 2.0 s; warnings from frame `first_warning` on."""
    ttc = [round(2.0 - k * DT, 4) for k in range(20)]
    warn = [int(first_warning is not None and k >= first_warning) for k in range(20)]
    return row(run_id, ttc, warn, **kw)


def near_miss_row(run_id: str, warn_frames: set[int]) -> RunResult:
    return row(run_id, [None] * 20, [int(k in warn_frames) for k in range(20)], kind="near-miss")


def test_wilson_lower_bound_known_values() -> None:
    assert wilson(10, 10)[0] == pytest.approx(10 / (10 + 1.959964**2), abs=1e-6)  # 0.7225
    assert wilson(73, 73)[0] == pytest.approx(0.950, abs=1e-3)  # the goal needs n >= 73
    assert wilson(1, 2)[0] == pytest.approx(0.0945, abs=1e-4)
    assert wilson(0, 5)[0] == 0.0
    assert all(math.isnan(v) for v in wilson(0, 0))


def test_frame_counts_recall_precision_and_false_alarms() -> None:
    # Run A: positive frames 15-19 (TTC <= 0.5 s); warns from frame 9: TP 5, FP 6, TN 9.
    a = judge_run(collision_row("a", 9), KEY)
    assert (a.frames.tp, a.frames.fp, a.frames.fn, a.frames.tn) == (5, 6, 0, 9)
    # Run B never warns: FN 5, TN 15. Near miss C warns once: FP 1, TN 19.
    b = judge_run(collision_row("b", None), KEY)
    c = judge_run(near_miss_row("c", {4}), KEY)
    s = summarise(KEY, [a, b, c])
    assert (s.frames.tp, s.frames.fp, s.frames.fn, s.frames.tn) == (5, 7, 5, 43)
    assert s.frames.recall == pytest.approx(0.5)
    assert s.frames.precision == pytest.approx(5 / 12)
    assert s.frames.false_alarm_rate == pytest.approx(7 / 50)


def test_run_recall_lead_time_and_near_misses() -> None:
    a = judge_run(collision_row("a", 9), KEY)  # onset t = 0.9, contact 2.0: lead 1.1 s
    b = judge_run(collision_row("b", 17), KEY)  # onset 1.7: lead 0.3 s
    c = judge_run(collision_row("c", None), KEY)
    d = judge_run(near_miss_row("d", {4}), KEY)
    e = judge_run(near_miss_row("e", set()), KEY)
    assert a.contact_time == pytest.approx(2.0) and a.lead == pytest.approx(1.1)
    assert b.lead == pytest.approx(0.3) and c.lead is None
    s = summarise(KEY, [a, b, c, d, e])
    assert (s.collision_runs, s.warned, s.warned_1s, s.timely) == (3, 2, 1, 0)
    assert s.recall == pytest.approx(2 / 3)
    assert s.recall_low == pytest.approx(wilson(2, 3)[0])
    assert s.recall_1s == pytest.approx(1 / 3)
    assert (s.near_miss_runs, s.near_miss_warned) == (2, 1)
    assert s.near_miss_warned_share == pytest.approx(0.5)
    assert s.lead_p50 == pytest.approx(0.7)
    assert not s.meets_goal


def test_latency_applied_recall_skips_frames_while_busy() -> None:
    """150 ms per frame at 10 frames/s: every other frame is processed, 150 ms late."""
    r = collision_row("a", 9, pose_ms=150.0)
    avail = available_times(r, "main")
    assert avail[0] == pytest.approx(0.15) and avail[1] is None
    assert avail[2] == pytest.approx(0.35) and avail[3] is None
    out = judge_run(r, KEY)
    # Frame 9 warned but was skipped; frame 10's warning exists at 1.15 s: lead 0.85 s.
    assert out.onset == pytest.approx(0.9)
    assert out.onset_latency == pytest.approx(1.15)
    assert out.lead_latency == pytest.approx(0.85)
    s = summarise(KEY, [out])
    assert (s.warned_1s, s.warned_latency, s.warned_1s_latency) == (1, 1, 0)


def test_a_warning_produced_after_contact_does_not_count() -> None:
    r = collision_row("a", 19, pose_ms=250.0)  # frame 18 processed, 19 skipped
    assert judge_run(r, KEY).onset == pytest.approx(1.9)
    assert judge_run(r, KEY).lead_latency is None


def test_case_accuracy_confusion_and_position_error() -> None:
    warn: list[int | None] = [0] * 10 + [None] * 2
    pred: list[int | None] = [5] * 6 + [6] * 4 + [None] * 2
    r = row("a", [None] * 12, warn, pred_case=pred)
    cases = case_summary([r], KEY)
    assert cases.frames == 10 and cases.accuracy == pytest.approx(0.6)
    assert cases.confusion[4, 4] == 6 and cases.confusion[4, 5] == 4
    assert cases.most_predicted == (Case.PERPENDICULAR_RIGHT, pytest.approx(0.6))
    assert case_summary([row("b", [None] * 2, [None] * 2)], KEY).most_predicted is None
    positions = position_summary([r], KEY)
    # Horizon 0.5 s = 5 frames: frames 0-6 have a true foot 5 frames later; error (3, 4).
    assert len(positions.px) == 7 and positions.px_percentile(50) == pytest.approx(5.0)
    acc = positions.accuracy_within([0, 4, 5, 10])
    assert list(acc) == [0.0, 0.0, 1.0, 1.0]


def test_compute_groups_and_report_files(tmp_path: Path) -> None:
    rows = [
        collision_row("a", 9, family="f1", robot_speed=1.0),
        collision_row("b", None, family="f1", robot_speed=2.0),
        collision_row("c", 2, family="f2", scale="car", robot_speed=2.0),
        near_miss_row("d", {3}),
        collision_row("a", None, family="f1"),  # a duplicate id: counted once
    ]
    m = compute(rows)
    assert m.rows == 4 and m.methods == (KEY,)
    fam = m.by_family[KEY]
    assert (fam["f1"].collision_runs, fam["f1"].warned) == (2, 1)
    assert m.by_speed[KEY][2.0].collision_runs == 2
    assert m.by_scale[KEY]["car"].timely == 1  # lead 1.8 s >= 1.7 s
    report = write_report(m, rows, tmp_path / "r.jsonl", tmp_path / "rep")
    assert report.markdown.read_text().startswith("# Sweep report")
    pngs = sorted(p.name for p in (tmp_path / "rep").glob("*.png"))
    assert sorted(p.name for p in report.plots) == pngs and len(pngs) == 7
    assert "rules/image" in report.headline
    # One sweep is named; runs of two sweeps in one file are said to be counted together.
    assert "Sweep: `unnamed`, 5 runs." in report.markdown.read_text()
    mixed = [replace(rows[0], sweep="demo"), replace(rows[1], sweep="demo"), rows[2]]
    assert sweeps_line(mixed) == (
        "Runs of 2 sweeps, counted together below: `demo` (2 runs), `unnamed` (1 run)."
    )


def test_nuisance_warnings_and_flicker_count_episodes_off_any_collision_course():
    # 20 frames at 0.1 s, no contact ahead; warned at 2-3, 6 (back 0.3 s after the end:
    # a flicker) and 18-19 (back 1.2 s later: no flicker), never on a collision course.
    warn = [0] * 20
    for k in (2, 3, 6, 18, 19):
        warn[k] = 1
    r = judge_run(row("n", [None] * 20, warn, kind="near-miss"), KEY)
    assert (r.episodes, r.nuisance_onsets, r.flickers) == (3, 3, 1)
    assert r.clear_seconds == pytest.approx(2.0)
    s = summarise(KEY, [r])
    assert s.nuisance_per_hour == pytest.approx(3 / (2.0 / 3600))
    assert s.flicker_share == pytest.approx(1 / 3)
    # Warnings while a contact is ahead are not nuisances, and an unwarned run has none.
    on_course = judge_run(collision_row("c", 9), KEY)
    assert on_course.nuisance_onsets == 0 and on_course.episodes == 1
    quiet = judge_run(row("q", [None] * 20, [0] * 20, kind="near-miss"), KEY)
    assert (quiet.episodes, quiet.nuisance_onsets, quiet.flickers) == (0, 0, 0)


def test_every_predictor_and_mode_has_its_own_colour_in_the_plots() -> None:
    """Histograms and bars have no line style: rules/image and rules/ground must differ."""
    from sim.analysis.plots import style
    from sim.runs.pipelines import PREDICTORS

    keys = [f"{name}/{mode}" for name, mode in PREDICTORS] + ["tree/ground"]
    colours = [style(key)["color"] for key in keys]
    assert len(set(colours)) == len(keys)
    assert style("gtcrop:rules/image")["color"] == style("rules/image")["color"]
    assert style("mine/image")["color"] == style("mine/image")["color"] not in colours


def test_two_sweeps_beside_each_other_cell_by_cell(tmp_path: Path) -> None:
    from sim.analysis.beside import beside_rows

    rail = compute([collision_row("a", 9, family="f1"), near_miss_row("d", {3})])
    human = compute([collision_row("a", None, family="f1"), collision_row("b", 9, family="f2")])
    (overall,) = beside_rows(rail, human, [KEY], by_family=False)
    assert overall[:4] == [KEY, "2 / 2", "1 / 2", "100 % [21] / 50 % [9]"]
    assert overall[5] == "1/1 / -"  # near misses: only the first sweep has one
    fam = {(r[0], r[1]): r for r in beside_rows(rail, human, [KEY], by_family=True)}
    assert fam[("f1", KEY)][4] == "100 % [21] / 0 % [0]"
    assert fam[("f2", KEY)][3] == "- / 1"  # a family only the other sweep holds
    report = write_report(rail, [], tmp_path / "rail.jsonl", tmp_path / "rep", ("human", human))
    assert "## Beside human" in report.markdown.read_text()


def test_frames_before_a_change_of_intent_are_the_last_1_5_s_before_it() -> None:
    from sim.analysis.metrics import before_change

    times = [k * 0.5 for k in range(8)]  # 0 .. 3.5 s
    labels = ["keep going"] * 5 + ["stop"] * 3  # changes at 2.5 s
    assert before_change(times, labels) == [False, False, True, True, True, False, False, False]
    assert not any(before_change(times, ["keep going"] * 8))
    with_gap = [*labels[:4], None, *labels[5:]]  # an unknown label is no change
    assert not any(before_change(times, with_gap))


def test_intent_accuracy_counts_decided_frames_and_those_before_a_change() -> None:
    from sim.analysis.metrics import Accuracy, _accuracy

    said = ["stop", None, "keep going", "stop"]
    truth = ["stop", "stop", "stop", "stop"]
    near = [True, True, False, True]
    got = _accuracy(said, truth, near)
    assert got == Accuracy(frames=3, correct=2, before_frames=2, before_correct=2)
    assert got.accuracy == 2 / 3 and got.before_accuracy == 1.0


def test_intent_summary_against_the_truth_and_constant_velocity() -> None:
    """Hand-made columns: the tree states intents; where its point leaves constant
    velocity's, the errors of both are reported there."""
    import dataclasses

    from sim.analysis.metrics import intent_summary
    from sim.runs.result import DecisionColumns

    n = 6
    base = row("r", [None] * n, [0] * n)
    truth = dataclasses.replace(
        base.truth,
        intent=["keep going"] * 3 + ["stop"] * 3,  # changes at 0.3 s
        case_now=[5, 5, 5, 9, 9, 9],
        case=[5, 5, 9, 9, 9, 9],
    )
    tree = DecisionColumns(
        warn=[0] * n,
        case=[5, 5, 9, 9, 9, 5],
        foot=[None] * n,
        ground=[[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.5, 0.0], [1.0, 0.0]],
        ttc=[None] * n,
        intent=["keep going", "stop", "stop", "stop", "stop", "keep going"],
    )
    cv = DecisionColumns(
        warn=[0] * n, case=[5] * n, foot=[None] * n, ground=[[1.0, 0.0]] * n, ttc=[None] * n
    )
    main = dataclasses.replace(
        base.pipelines["main"],
        decisions={"intent-tree/ground": tree, "constant-velocity/ground": cv},
    )
    r = dataclasses.replace(base, truth=truth, pipelines={"main": main})
    s = intent_summary([r], "intent-tree/ground")
    assert s is not None
    assert (s.intent.frames, s.intent.correct) == (6, 3)  # frames 1, 2 and 5 wrong
    assert (s.intent.before_frames, s.intent.before_correct) == (3, 1)  # frames 0-2
    assert (s.case.correct, s.baseline_case.correct) == (5, 5)
    assert (s.compared, s.differing) == (6, 1)  # frame 4: 0.5 m from constant velocity
    assert s.error_m == 0.5 and s.cv_error_m == 0.0  # the truth's future is (1, 0)
    assert intent_summary([r], "constant-velocity/ground") is None  # states no intent


counts = st.integers(min_value=0, max_value=60)


@given(counts, counts, counts, counts)
def test_the_paired_interval_holds_the_difference_and_turns_with_the_order(
    both: int, first: int, second: int, neither: int
) -> None:
    if both + first + second + neither == 0:
        assert all(math.isnan(v) for v in paired_difference(0, 0, 0, 0))
        return
    diff, low, high = paired_difference(both, first, second, neither)
    n = both + first + second + neither
    assert diff == pytest.approx((first - second) / n)
    assert -1.0 - 1e-9 <= low <= diff + 1e-12 and diff - 1e-12 <= high <= 1.0 + 1e-9
    back = paired_difference(both, second, first, neither)
    assert back == pytest.approx((-diff, -high, -low))


def test_the_paired_interval_narrows_with_agreement_and_with_more_runs() -> None:
    # Discordant pairs widen it; the same split with ten times the runs narrows it.
    _, low_agree, _ = paired_difference(10, 1, 1, 4)
    _, low_split, _ = paired_difference(5, 6, 6, 0)
    assert low_agree > low_split
    _, low_many, high_many = paired_difference(100, 10, 10, 40)
    assert high_many - low_many < 0.5 * (0 - low_agree) * 2
    # Worked by hand for 36 both, 12 first only, 2 second only, none neither: Wilson
    # 0.865-0.989 (48/50) and 0.626-0.857 (38/50), phi = -24 / sqrt(48 * 2 * 38 * 12).
    assert paired_difference(36, 12, 2, 0) == pytest.approx((0.2, 0.0569, 0.3404), abs=1e-4)


def _outcome(i: int, onset: float | None, collision: bool = True) -> RunOutcome:
    return RunOutcome(
        id=f"r{i}", family="f", kind="collision" if collision else "near-miss", scale="small",
        case=5, robot_speed=1.0, horizon=1.5, collision_run=collision,
        contact_time=3.0 if collision else None, warned=onset is not None, onset=onset,
        onset_latency=onset, frames=FrameCounts(),
    )  # fmt: skip


def test_paired_recall_counts_the_runs_each_method_alone_warned_in_time() -> None:
    # Contact at 3 s: an onset at 1.5 s is 1.5 s ahead, one at 2.5 s only 0.5 s.
    first = [_outcome(0, 1.5), _outcome(1, 2.5), _outcome(2, 2.5), _outcome(3, None, False)]
    second = [_outcome(0, 1.5), _outcome(1, 1.5), _outcome(2, 1.5), _outcome(3, 1.0, False)]
    p = paired_recall(first, second)
    assert (p.collision_runs, p.warned_1s) == (3, (1, 3))
    assert (p.only_first, p.only_second) == (0, 2)  # two runs lost their 1 s warning
    assert p.near_miss_warned == (0, 1)
    back = paired_recall(second, first)
    assert (back.only_first, back.only_second) == (2, 0)
