"""Triage: the report lists the runs that went wrong with the command that runs each again,
and `monopic rerun` runs a results line again and checks it against the line."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from sim.analysis.metrics import compute, methods
from sim.analysis.report import write_report
from sim.analysis.triage import PER_FAMILY, primary
from sim.runs.code_version import code_version
from sim.runs.pipelines import PREDICTORS
from sim.runs.rebuild import first_difference, intent_tree_of, scenario_file_of, shipped_trees
from sim.runs.result import RunResult
from sim.runs.results_file import read_rows
from sim.runs.sweep import run_scenario, tree_digest
from sim.scenario.files import load
from tests.rrd import rows_per_entity
from tests.sim.test_metrics import collision_row, near_miss_row
from tests.sim.test_sweep import SCENARIO

# One 6-frame run of the sweep tests' tiny crossing.
ONE_RUN = SCENARIO.replace('"robot.speed" = [0.0, 1.0, 2.0]', '"robot.speed" = [2.0]')
SPEC = 'name = "tiny"\nablation = true\n[[include]]\nfiles = ["tiny.toml"]\n'


def _section(markdown: str) -> str:
    text = markdown.split("## Runs to look at", 1)[1]
    return text.split("\n## ", 1)[0]


def _report(tmp_path: Path, rows: list[RunResult], results: Path) -> str:
    out = tmp_path / "results_report"
    write_report(compute(rows), rows, results, out)
    return _section((out / "report.md").read_text())


def test_the_report_lists_missed_late_and_near_miss_runs_with_a_rerun_command_each(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    results = Path("results.jsonl")  # relative, as a user types it
    kept = tmp_path / "results_rrd" / "fam" / "missed.rrd"
    kept.parent.mkdir(parents=True)
    kept.write_bytes(b"x")
    rows = [
        replace(collision_row("fam/missed", None), recording="fam/missed.rrd",
                params={"robot.speed": 2.0}),
        collision_row("fam/late", 15),  # onset 1.5 s, contact 2.0 s: 0.5 s ahead
        collision_row("fam/in-time", 5),  # 1.5 s ahead: counted by recall@1s
        near_miss_row("fam/nm-warned", {3, 4, 5}),
        near_miss_row("fam/nm-clear", set()),
    ]  # fmt: skip
    section = _report(tmp_path, rows, results)
    listed = [ln.split("`")[1] for ln in section.splitlines() if ln.startswith("- `")]
    assert listed == ["fam/missed", "fam/late", "fam/nm-warned"]  # the worst first
    assert "`fam/missed` (robot.speed = 2): **missed**" in section
    assert "**late: 0.50 s before contact**" in section
    assert "**near miss warned (3 frames)**" in section
    # The command as the user gave the results path, and links relative to report.md.
    assert "  `monopic rerun results.jsonl fam/late`" in section
    assert "recording [fam/missed.rrd](../results_rrd/fam/missed.rrd)" in section
    late = "`fam/late` (the file's values): **late: 0.50 s before contact**; recording not kept"
    assert late in section
    assert "The sweep kept 1 recording, in [results_rrd/](../results_rrd)." in section
    assert "**fam**: 1 missed, 1 late, 1 near miss warned of 5 runs" in section
    assert "| all    | 1 / 1 / 1   |" in section


def test_the_list_keeps_the_worst_runs_of_each_family_and_counts_the_rest(tmp_path: Path) -> None:
    leads = [0.9, 0.3, 0.6, 0.1, 0.8, 0.5]  # s before contact: frames 11, 17, 14, 19, 12, 15
    rows = [collision_row(f"big/late{k}", round(20 - lead * 10)) for k, lead in enumerate(leads)]
    rows += [collision_row(f"big/missed{k}", None) for k in range(3)]
    rows += [collision_row("small/missed", None, family="small")]
    section = _report(tmp_path, rows, tmp_path / "results.jsonl")
    listed = [ln.split("`")[1] for ln in section.splitlines() if ln.startswith("- `")]
    assert PER_FAMILY == 5
    assert listed == [
        "big/missed0", "big/missed1", "big/missed2", "big/late3", "big/late1", "small/missed"
    ]  # fmt: skip
    assert "- and 4 more (4 late)" in section
    assert "at most 5 per family" in section


def test_the_triage_list_is_the_robots_primary_predictor() -> None:
    row = collision_row("fam/a", 5)
    decisions = row.pipelines["main"].decisions
    keys = [f"{name}/{mode}" for name, mode in PREDICTORS]
    row.pipelines["main"].decisions = {k: decisions["rules/image"] for k in reversed(keys)}
    assert methods([row])[0] == keys[0]
    assert primary(compute([row])) == keys[0]


def test_first_difference_names_the_frame_count_before_the_columns() -> None:
    line = json.loads(collision_row("fam/a", 5).dumps())
    same = json.loads(json.dumps(line))
    assert first_difference(line, same) is None
    other = json.loads(json.dumps(line))
    other["pipelines"]["main"]["decisions"]["rules/image"]["warn"][7] = 0
    assert first_difference(line, other) == (
        "pipelines.main.decisions.rules/image.warn[7] (frame 7, t = 0.70 s): 1 in the sweep, 0 now"
    )
    other["frames"] = 19
    assert first_difference(line, other) == "frames: 0 in the sweep, 19 now"


def test_a_relative_scenario_file_is_the_one_that_gives_the_runs_digest(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    sweep_dir, elsewhere = tmp_path / "sweep", tmp_path / "elsewhere"
    sweep_dir.mkdir()
    elsewhere.mkdir()
    (sweep_dir / "tiny.toml").write_text(ONE_RUN)
    (elsewhere / "tiny.toml").write_text(ONE_RUN.replace("distance = 3.0", "distance = 4.0"))
    _, _, digest = run_scenario(load(sweep_dir / "tiny.toml"), {"robot.speed": 2.0})
    row = replace(
        collision_row(f"tiny/0000-{digest}", 5), file="tiny.toml", params={"robot.speed": 2.0}
    )
    monkeypatch.chdir(elsewhere)  # its tiny.toml is another scenario: passed over
    found, scenario = scenario_file_of(row, sweep_dir / "results.jsonl")
    assert found.path == sweep_dir / "tiny.toml" and scenario.robot.speed == 2.0
    with pytest.raises(UserError, match="no longer gives run tiny/0000-.*changed since"):
        scenario_file_of(row, elsewhere / "results.jsonl")


def test_a_run_of_the_shipped_intent_tree_finds_it(tmp_path: Path) -> None:
    tree = next(t for t in shipped_trees() if t.name == "ground_tree.json")
    row = replace(collision_row("fam/a", 5), code=f"{code_version()}+tree-{tree_digest(tree)}")
    assert intent_tree_of(row, tmp_path / "r.jsonl", None) == tree
    assert intent_tree_of(row, tmp_path / "r.jsonl", tree) == tree.resolve()


# -- the command ----------------------------------------------------------------------


@pytest.mark.slow
def test_rerun_gives_the_sweeps_frames_and_decisions_and_a_readable_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "tiny.toml").write_text(ONE_RUN)
    (tmp_path / "spec.toml").write_text(SPEC)
    results = tmp_path / "tiny.jsonl"
    sweep = ["sweep", str(tmp_path / "spec.toml"), "--out", str(results), "--workers", "1"]
    assert main([*sweep, "--record", "all"]) == 0
    (line,) = read_rows(results)
    capsys.readouterr()

    rrd = tmp_path / "again" / "run.rrd"
    assert main(["rerun", str(results), line["id"], "--out", str(rrd)]) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[-1] == "same frames and decisions as in the sweep", printed
    assert f"recording: {rrd}" in printed
    counts = rows_per_entity(rrd)  # rerun's own reader
    assert counts["/camera/image"] == line["frames"]
    assert counts == rows_per_entity(tmp_path / "tiny_rrd" / line["recording"])

    # A line that does not hold what the run gives is caught, at its first difference
    # (here also a line of other code, which --anyway runs).
    warn = line["pipelines"]["main"]["decisions"]["rules/image"]["warn"]
    k = next(i for i, w in enumerate(warn) if w is not None)
    warn[k] = 1 - warn[k]
    line["code"] = "0123456789ab"
    edited = tmp_path / "edited.jsonl"
    edited.write_text(json.dumps(line) + "\n")
    assert main(["rerun", str(edited), line["id"]]) == 2
    assert "--anyway" in capsys.readouterr().err
    assert main(["rerun", str(edited), line["id"], "--anyway"]) == 1
    printed = capsys.readouterr().out
    assert (
        f"first difference at pipelines.main.decisions.rules/image.warn[{k}] (frame {k}, "
        in printed
    )
    assert (tmp_path / "edited_rerun" / f"{line['id']}.rrd").is_file()  # the default --out


def _line(tmp_path: Path, **changes: object) -> dict:
    """A results line of this code for the one-run tiny file (its real id), with changes."""
    (tmp_path / "tiny.toml").write_text(ONE_RUN)
    _, _, digest = run_scenario(load(tmp_path / "tiny.toml"), {"robot.speed": 2.0})
    line = json.loads(collision_row(f"tiny/0000-{digest}", 5).dumps())
    line.update(file=str(tmp_path / "tiny.toml"), params={"robot.speed": 2.0}, code=code_version())
    line.update(changes)
    return line


@pytest.mark.parametrize(
    ("changes", "run_id", "extra", "expected"),
    [
        ({}, "tiny/0000-nope", [], "no run 'tiny/0000-nope' in it (1 runs, ids such as"),
        ({"code": "0123456789ab"}, None, [], "made by other code (0123456789ab; this code is"),
        ({"code": None}, None, [], "made by other code (unknown: written before"),
        ({"file": "gone/tiny.toml"}, None, [], "gone/tiny.toml: no such scenario file"),
        ({"params": {"robot.speed": 1.0}}, None, [], "no longer gives run tiny/0000-"),
        ({"code": code_version() + "+tree-0badc0de"}, None, [], "--intent-tree FILE"),
        ({}, None, ["--intent-tree", "spec.toml"], "ran no intent tree; leave it out"),
        ({"truth": None}, None, [], "is not a run of a sweep, a closed loop or a Euro NCAP grid"),
    ],
)
def test_what_cannot_be_rerun_is_one_line(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    changes: dict,
    run_id: str | None,
    extra: list[str],
    expected: str,
) -> None:
    line = _line(tmp_path, **changes)
    (tmp_path / "spec.toml").write_text(SPEC)
    results = tmp_path / "results.jsonl"
    results.write_text(json.dumps(line) + "\n")
    out = tmp_path / "out" / "run.rrd"
    args = ["rerun", str(results), run_id or line["id"], "--out", str(out), *extra]
    assert main([a.replace("spec.toml", str(tmp_path / "spec.toml")) for a in args]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err, err
    assert not (tmp_path / "out").exists()  # nothing made for a refused input


def test_rerun_refuses_a_missing_or_foreign_results_file_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["rerun", str(tmp_path / "none.jsonl"), "x/0000-1"]) == 2
    assert capsys.readouterr().err.strip().endswith("none.jsonl: no such results file")
    (tmp_path / "tiny.toml").write_text(ONE_RUN)
    assert main(["rerun", str(tmp_path / "tiny.toml"), "x/0000-1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "not a sweep's results file" in err, err


def test_a_run_of_a_tree_not_shipped_says_its_rerun_needs_the_tree_file(tmp_path: Path) -> None:
    shipped = tree_digest(next(t for t in shipped_trees() if t.name == "ground_tree.json"))
    own = replace(collision_row("fam/own", None), code=f"{code_version()}+tree-0badc0de")
    ours = replace(collision_row("fam/ours", None), code=f"{code_version()}+tree-{shipped}")
    section = _report(tmp_path, [own, ours], Path("r.jsonl"))
    assert "`monopic rerun r.jsonl fam/own --intent-tree TREE`" in section
    assert "`monopic rerun r.jsonl fam/ours`" in section
    assert "TREE: the intent tree file the sweep spec names (`intent_tree`)" in section


# -- closed-loop and Euro NCAP runs ----------------------------------------------------------


def _loop_row(policy: str, scenario: str, contact: bool, braked: bool, impact: float = 2.0,
              recording: str = "") -> dict:  # fmt: skip
    from dataclasses import asdict

    from sim.runs.closed_loop import LoopOutcome

    o = LoopOutcome(scenario=scenario, policy=policy, seed=0, frames=30, contact=contact,
                    contact_time=2.0 if contact else None, impact_speed=impact if contact else None,
                    min_gap=0.0 if contact else 0.5, first_warning_time=1.0 if braked else None,
                    brake_time=1.25 if braked else None, warned_frames=3 * braked,
                    start_speed=2.0, final_speed=0.0 if braked else 2.0)  # fmt: skip
    case = int(scenario[4])
    source = {"file": None, "case": case, "given": {"robot.speed": 2.0}, "meet_time": 3.0}
    return json.loads(json.dumps({"id": f"{policy}/{scenario}-0123abcd", "policy": policy,
                                  "scenario": scenario, "seed": 0, "source": source,
                                  "outcome": asdict(o), "recording": recording}))  # fmt: skip


def test_the_closed_loop_lists_a_braking_policys_contacts_and_needless_stops(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from sim.analysis.triage import Rerunning, loop_triage_lines

    monkeypatch.chdir(tmp_path)
    kept = Path("rrd") / "case6@2-rules-ground.rrd"
    kept.parent.mkdir()
    kept.write_bytes(b"x")
    rows = [
        _loop_row("none", "case5@2", True, False),
        _loop_row("rules/ground", "case5@2", True, True, impact=1.5),  # braked, still hit
        _loop_row("truth", "case5@2", False, True),  # avoided: nothing to look at
        _loop_row("none", "case6@2", True, False),
        _loop_row("rules/ground", "case6@2", True, False, recording=str(kept)),  # missed
        _loop_row("none", "case7@2", False, False),
        _loop_row("rules/ground", "case7@2", False, True),  # braked without need
        _loop_row("truth", "case7@2", False, False),
    ]
    where = Rerunning(Path("loop.jsonl"), Path("rrd"), Path())
    text = "\n".join(loop_triage_lines(rows, where, recorded=True))
    listed = [ln.split("`")[1] for ln in text.splitlines() if ln.startswith("- `")]
    assert listed == [  # contacts by impact speed, then the needless stops; no baseline run
        "rules/ground/case6@2-0123abcd",
        "rules/ground/case5@2-0123abcd",
        "rules/ground/case7@2-0123abcd",
    ]
    assert "**rules/ground**: 2 with contact, 1 braked without need of 3 runs" in text
    assert "**truth**" not in text and "**none**" not in text
    assert (
        "- `rules/ground/case6@2-0123abcd` (case 6, robot.speed = 2): **contact at 2.00 m/s**; "
        "recording [case6@2-rules-ground.rrd](rrd/case6@2-rules-ground.rrd)"
    ) in text
    assert "**braked without need (brake from 1.25 s)**; recording not kept" in text
    assert "  `monopic rerun loop.jsonl rules/ground/case7@2-0123abcd`" in text
    quiet = [r for r in rows if r["policy"] != "rules/ground"]
    assert "None: no braking policy hit the pedestrian" in "\n".join(
        loop_triage_lines(quiet, where)
    )


def _ncap_row(role: str, index: int, contact: bool, braked: bool, rel: float = 0.0) -> dict:
    point = {"test": "cpna", "function": "AEB", "speed_kmh": 40.0, "impact": 0.5,
             "load_case": "CPNA day"}  # fmt: skip
    if role == "near-miss":
        point = {"test": "near-miss", "family": "nearmiss_kerb_stop", "speed_kmh": 40.0}
    outcome = {"contact": contact, "impact_speed": 5.0 if contact else None,
               "relative_impact_speed": rel if contact else None,
               "brake_time": 1.5 if braked else None}  # fmt: skip
    return {"id": f"rules/ground/{point['test']}/{role}{index}-0123abcd", "policy": "rules/ground",
            "role": role, "index": index, **point, "outcome": outcome}  # fmt: skip


def test_the_ncap_report_lists_contacts_and_braked_near_misses_with_a_rerun_command() -> None:
    from sim.analysis.triage import Rerunning, ncap_triage_lines

    rows = [
        _ncap_row("grid", 0, True, True, rel=2.0),
        _ncap_row("grid", 1, True, True, rel=4.0),
        _ncap_row("verify", 2, False, True),
        _ncap_row("near-miss", 0, False, True),
        _ncap_row("near-miss", 1, False, False),
    ]
    out = Path("recordings/ncap")
    text = "\n".join(ncap_triage_lines(rows, Rerunning(out / "results.jsonl", out, out)))
    listed = [ln.split("`")[1] for ln in text.splitlines() if ln.startswith("- `")]
    assert listed == [
        "rules/ground/cpna/grid1-0123abcd",
        "rules/ground/cpna/grid0-0123abcd",
        "rules/ground/near-miss/near-miss0-0123abcd",
    ]
    assert "**rules/ground, cpna**: 2 with contact of 3 runs" in text
    assert "**rules/ground, near-miss**: 1 braked without need of 2 runs" in text
    assert (
        "- `rules/ground/cpna/grid1-0123abcd` (CPNA day AEB 40 km/h, impact 50%, grid run 1): "
        "**contact at 18.0 km/h (14.4 km/h relative)**"
    ) in text
    assert "(nearmiss_kerb_stop at 40 km/h, seed 0): **braked without need (brake from" in text
    assert (
        "  `monopic rerun recordings/ncap/results.jsonl rules/ground/cpna/grid0-0123abcd`" in text
    )


def test_the_ncap_report_lists_braking_for_the_wrong_person_naming_them() -> None:
    from sim.analysis.triage import Rerunning, ncap_triage_lines

    wrong = _ncap_row("grid", 3, False, True)
    wrong["outcome"].update(braked_for="bystander", braked_for_track=2, braked_for_on_course=False)
    phantom = _ncap_row("grid", 4, False, True)
    phantom["outcome"].update(braked_for="nobody", braked_for_track=5)
    right = _ncap_row("grid", 5, False, True)
    right["outcome"].update(braked_for="ped", braked_for_track=1, braked_for_on_course=True)
    out = Path("recordings/ncap")
    text = "\n".join(
        ncap_triage_lines([wrong, phantom, right], Rerunning(out / "r.jsonl", out, out))
    )
    listed = [ln.split("`")[1] for ln in text.splitlines() if ln.startswith("- `")]
    assert listed == ["rules/ground/cpna/grid3-0123abcd", "rules/ground/cpna/grid4-0123abcd"]
    said = "braked for bystander (track 2), not on a collision course (brake from 1.50 s)"
    assert f"**{said}**" in text
    assert "**braked for nobody (a phantom) (track 5) (brake from 1.50 s)**" in text
