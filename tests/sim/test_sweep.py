"""Sweeps end to end on tiny runs: results lines, resume after a stop or a torn line,
identical results on Ray, and the two commands."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from sim.runs.code_version import code_version
from sim.runs.executors import local_executor, ray_executor, ray_runtime_env, work
from sim.runs.result import RunResult
from sim.runs.results_file import ResultsWriter, read_results, read_rows, scan
from sim.runs.sweep import expand_spec, load_spec, run_sweep
from sim.world.render import KeptRenderContext
from tests.rrd import rows_per_entity

# A 6-frame crossing on a 256x144 camera without buildings: seconds per run.
SCENARIO = """
name = "tiny"
kind = "collision"
scale = "small"
duration = 0.4
fps = 15
[robot]
speed = 2.0
[robot.camera]
width = 256
height = 144
[pedestrian]
speed = 1.4
[path]
kind = "case"
case = 5
distance = 3.0
[scene.road]
buildings = false
crosswalk = false
[sweep]
sampling = "grid"
[sweep.parameters]
"robot.speed" = [0.0, 1.0, 2.0]
"""
SPEC = """
name = "tiny"
ablation = {ablation}
[[include]]
files = ["tiny.toml"]
"""


@pytest.fixture()
def spec_path(tmp_path: Path) -> Path:
    (tmp_path / "tiny.toml").write_text(SCENARIO)
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.format(ablation="true"))
    return path


def deterministic(row: dict) -> dict:
    return RunResult.from_json(row).deterministic()


def by_id(path: Path) -> dict[str, dict]:
    rows = list(read_results(path))
    assert len({r.id for r in rows}) == len(rows), "duplicate run ids"
    return {r.id: r.deterministic() for r in rows}


def test_results_file_ignores_a_torn_tail_and_rejects_a_bad_middle(tmp_path: Path) -> None:
    path = tmp_path / "r.jsonl"
    path.write_bytes(b'{"id": "a"}\n{"id": "b"}\n{"id": "c", "trun')
    state = scan(path)
    assert state.ids == {"a", "b"} and state.torn
    with ResultsWriter(path) as writer:
        assert writer.state == state
        with pytest.raises(UserError, match="another sweep is writing to it"):
            ResultsWriter(path)
        writer.append({"id": "d"})
    assert path.read_bytes() == b'{"id": "a"}\n{"id": "b"}\n{"id":"d"}\n'
    assert not scan(path).torn
    path.write_bytes(b'{"id": "a"}\nnot json\n{"id": "b"}\n')
    with pytest.raises(UserError, match=r"r.jsonl:2: not a result line"):
        scan(path)


@pytest.mark.slow
def test_a_worker_keeps_one_render_context_for_its_runs(spec_path: Path) -> None:
    specs = expand_spec(load_spec(spec_path))
    kept = KeptRenderContext()
    try:
        rows = [work(spec, kept) for spec in specs[:2]]
        context = kept.context
        camera = specs[2].scenario.robot.camera
        assert context is not None and kept.fitting(camera.width, camera.height) is context
    finally:
        kept.close()
    assert kept.context is None
    assert [r["id"] for r in rows] == [s.id for s in specs[:2]]
    assert not any("error" in r for r in rows)
    # The same results as runs with their own context.
    fresh = [work(spec) for spec in specs[:2]]
    assert [deterministic(r) for r in rows] == [deterministic(r) for r in fresh]


@pytest.mark.slow
def test_sweep_writes_one_line_per_run_and_resumes_without_loss(
    spec_path: Path, tmp_path: Path
) -> None:
    spec = load_spec(spec_path)
    ids = [r.id for r in expand_spec(spec)]
    assert len(ids) == 3
    out = tmp_path / "results.jsonl"
    executor = local_executor(2)

    # Stopped after one run (as if interrupted): one complete line.
    first = run_sweep(spec, out, executor, progress=False, limit=1)
    assert (first.finished, first.skipped) == (1, 0)
    assert len(out.read_text().splitlines()) == 1

    # Resumed: the other two, nothing twice.
    second = run_sweep(spec, out, executor, progress=False)
    assert (second.finished, second.skipped, second.total) == (2, 1, 3)
    rows = by_id(out)
    assert sorted(rows) == sorted(ids)

    # A torn last line (killed mid-write) is dropped and its run done again, identically.
    lines = out.read_bytes().splitlines(keepends=True)
    last = json.loads(lines[-1])
    out.write_bytes(b"".join(lines[:-1]) + lines[-1][: len(lines[-1]) // 2])
    third = run_sweep(spec, out, executor, progress=False)
    assert (third.finished, third.skipped) == (1, 2)
    again = by_id(out)
    assert sorted(again) == sorted(ids)
    assert again[last["id"]] == deterministic(last)  # deterministic per run

    # Every line holds both pipelines side by side with the truth, frame for frame, and
    # says which code made it.
    record = next(iter(read_results(out)))
    assert record.code == code_version()
    assert set(record.pipelines) == {"main", "gtcrop"}
    n = record.frames
    assert len(record.truth.t) == n
    assert len(record.truth.intent) == len(record.truth.case_now) == n
    for cols in record.pipelines["main"].decisions.values():
        # The intent column is kept only by predictors stating one (none run here).
        assert cols.intent == []
        assert all(len(v) == n for k, v in vars(cols).items() if k != "intent")

    # Runs that went wrong (missed collision, false alarm) keep a recording, the others not.
    recorded = sorted(r["recording"] for r in read_rows(out) if r["recording"])
    folder = tmp_path / "results_rrd"
    assert sorted(str(p.relative_to(folder)) for p in folder.rglob("*.rrd")) == recorded

    # On request every run is recorded, and the file holds the run's frames.
    everything = tmp_path / "all.jsonl"
    run_sweep(spec, everything, executor, progress=False, limit=1, record="all")
    (row,) = read_rows(everything)
    rrd = tmp_path / "all_rrd" / row["recording"]
    assert rows_per_entity(rrd)["/camera/image"] == row["frames"]


def test_results_of_other_code_are_not_resumed_but_set_aside_on_request(
    spec_path: Path, tmp_path: Path
) -> None:
    spec = load_spec(spec_path)
    out = tmp_path / "results.jsonl"
    ids = [r.id for r in expand_spec(spec)]
    old = [{"id": ids[0], "code": "0123456789ab"}, {"id": ids[1]}]  # the second: no code
    out.write_text("".join(json.dumps(r) + "\n" for r in old))
    (tmp_path / "results_rrd").mkdir()
    with pytest.raises(UserError, match=r"1 by 0123456789ab, 1 by unknown.*--restart"):
        run_sweep(spec, out, local_executor(1), progress=False)
    assert out.read_text().count("\n") == 2  # untouched

    outcome = run_sweep(spec, out, local_executor(1), progress=False, limit=1, restart=True)
    assert (outcome.finished, outcome.skipped) == (1, 0)  # nothing of the old code kept
    assert (tmp_path / "results.mixed.jsonl").read_text().count("\n") == 2
    assert (tmp_path / "results_rrd.mixed").is_dir()
    assert [r["code"] for r in read_rows(out)] == [code_version()]
    # The same code resumes as before; a second restart would not overwrite the first.
    assert run_sweep(spec, out, local_executor(1), progress=False, limit=0).skipped == 1
    (tmp_path / "results.unknown.jsonl").write_text("")
    out.write_text(json.dumps(old[1]) + "\n")
    with pytest.raises(UserError, match="already there"):
        run_sweep(spec, out, local_executor(1), progress=False, restart=True)


def test_a_results_file_of_another_sweep_is_refused_naming_it(
    spec_path: Path, tmp_path: Path
) -> None:
    spec = load_spec(spec_path)
    out = tmp_path / "results.jsonl"
    ids = [r.id for r in expand_spec(spec)]
    other = {"id": ids[0], "code": code_version(), "sweep": "demo"}
    out.write_text(json.dumps(other) + "\n")
    with pytest.raises(
        UserError, match=rf"another sweep \('demo' \(1 run\)\), not of '{spec.name}'"
    ):
        run_sweep(spec, out, local_executor(1), progress=False)
    assert out.read_text().count("\n") == 1  # untouched
    # Lines without a sweep name (older files) do not count as another sweep.
    assert scan(out).other_sweeps("demo") == {}
    out.write_text(json.dumps({"id": ids[0], "code": code_version()}) + "\n")
    assert scan(out).other_sweeps(spec.name) == {}


def _children(pid: int) -> set[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return {int(x) for x in path.read_text().split()} if path.exists() else set()


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has exited


def _sweep_until_first_result(spec_path: Path, out: Path) -> tuple[subprocess.Popen, set[int]]:
    cmd = [sys.executable, "-m", "monopic", "sweep", str(spec_path), "--out", str(out)]
    proc = subprocess.Popen([*cmd, "--workers", "2", "--record", "none"], stderr=subprocess.PIPE)
    deadline = time.monotonic() + 180
    while not (out.exists() and out.read_text().count("\n") >= 1):
        assert proc.poll() is None and time.monotonic() < deadline, "no result came"
        time.sleep(0.2)
    workers = _children(proc.pid)
    assert workers, "the sweep runs in worker processes"
    return proc, workers


def _gone_within(pids: set[int], seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while any(_alive(p) for p in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.2)
    return True


@pytest.mark.slow
def test_stopping_a_sweep_stops_its_workers(spec_path: Path, tmp_path: Path) -> None:
    # SIGTERM: the sweep stops its workers itself and says so in one line.
    proc, workers = _sweep_until_first_result(spec_path, tmp_path / "term.jsonl")
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143 and err.decode().strip().endswith("terminated")
    assert _gone_within(workers, 10)
    # SIGKILL leaves no chance to clean up: the workers notice their parent is gone and
    # exit after the run they are in, instead of running the rest of the sweep (80 runs
    # of a second or more each: 40 s and more for two workers).
    speeds = ", ".join(f"{0.0375 * k:.4f}" for k in range(80))
    (tmp_path / "tiny.toml").write_text(
        SCENARIO.replace('"robot.speed" = [0.0, 1.0, 2.0]', f'"robot.speed" = [{speeds}]')
    )
    spec_path.write_text(SPEC.format(ablation="false"))
    proc, workers = _sweep_until_first_result(spec_path, tmp_path / "kill.jsonl")
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    assert _gone_within(workers, 15)


@pytest.mark.slow
def test_ray_executor_gives_the_local_executor_results(tmp_path: Path) -> None:
    ray = pytest.importorskip("ray", reason="Ray is not installed (the optional [ray] extra)")
    (tmp_path / "tiny.toml").write_text(SCENARIO)
    spec_path = tmp_path / "spec.toml"
    spec_path.write_text(SPEC.format(ablation="false"))
    spec = load_spec(spec_path)
    local_out, ray_out = tmp_path / "local.jsonl", tmp_path / "ray.jsonl"
    run_sweep(spec, local_out, local_executor(2), progress=False)
    ray.init(num_cpus=2, include_dashboard=False, runtime_env=ray_runtime_env())
    try:
        outcome = run_sweep(spec, ray_out, ray_executor(None), progress=False)
    finally:
        ray.shutdown()
    assert outcome.finished == 3 and not outcome.failed
    assert by_id(ray_out) == by_id(local_out)


@pytest.mark.slow
def test_sweep_and_report_commands(
    spec_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "new" / "cli.jsonl"  # folders are made as needed (README)
    assert main(["sweep", str(spec_path), "--out", str(out), "--dry-run"]) == 0
    assert "3 runs in 1 families, 0 already" in capsys.readouterr().out
    code = main(["sweep", str(spec_path), "--out", str(out), "--workers", "2", "--no-ablation"])
    assert code == 0
    assert len(out.read_text().splitlines()) == 3
    assert all("gtcrop" not in r["pipelines"] for r in read_rows(out))
    kept = [r["recording"] for r in read_rows(out) if r["recording"]]
    printed = capsys.readouterr().out
    folder = out.parent / "cli_rrd"
    if kept:
        assert (
            f"recordings (missed collisions and false alarms): {len(kept)} in {folder}" in printed
        )
    else:
        assert "recordings (missed collisions and false alarms): none kept" in printed
    assert not [p for p in out.parent.rglob("*") if p.is_dir() and not any(p.iterdir())]
    report_dir = tmp_path / "deep" / "er" / "report"
    assert main(["report", str(out), "--out", str(report_dir)]) == 0
    printed = capsys.readouterr().out
    assert "rules/image" in printed and "report.md" in printed
    assert (report_dir / "report.md").is_file()
    assert len(list(report_dir.glob("*.png"))) == 7


def test_bad_spec_and_results_are_one_line_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "spec.toml"
    spec.write_text('name = "x"\n[[include]]\nfiles = ["nothing*.toml"]\n')
    assert main(["sweep", str(spec), "--dry-run"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("include[0].files = 'nothing*.toml': matches no scenario file")
    assert "\n" not in err
    assert main(["report", str(tmp_path / "none.jsonl")]) == 2
    assert "no such results file" in capsys.readouterr().err
    assert main(["sweep", str(spec), "--address", "h:1"]) == 2


def _intent_tree_file(path: Path) -> Path:
    """A one-leaf ground intent tree file (hand-made: what matters is that it loads)."""
    from monopic.tree.intent import IntentRules
    from monopic.tree.serialise import save_model
    from tests.monopic.test_intent_tree import leaf_model

    path.parent.mkdir(parents=True, exist_ok=True)
    save_model(leaf_model("6/stop", 30, IntentRules(hold_back_support=0.8)), path)
    return path


def test_a_spec_names_an_intent_tree_relative_to_itself_and_runs_it_last(tmp_path: Path) -> None:
    from sim.runs.pipelines import PREDICTORS, make_pipeline
    from sim.runs.sweep import expand_spec, load_spec

    (tmp_path / "tiny.toml").write_text(SCENARIO)
    tree = _intent_tree_file(tmp_path / "trees" / "ground.json")
    spec_file = tmp_path / "spec.toml"
    spec_file.write_text('intent_tree = "trees/ground.json"\n' + SPEC.format(ablation="false"))
    spec = load_spec(spec_file)
    assert spec.intent_tree == tree.resolve()
    runs = expand_spec(spec)
    assert runs and all(r.intent_tree == str(tree.resolve()) for r in runs)
    plain = make_pipeline(runs[0].scenario)
    with_tree = make_pipeline(runs[0].scenario, intent_tree=Path(runs[0].intent_tree))
    keys = [f"{n}/{m}" for n, m in PREDICTORS]
    assert [f"{p.name}/{p.mode}" for p in plain.predictors] == keys
    assert [f"{p.name}/{p.mode}" for p in with_tree.predictors] == [*keys, "intent-tree/ground"]
    assert with_tree.primary == plain.primary
    # Results carry the tree's digest in their code version: another tree is other code.
    from sim.runs.code_version import code_version
    from sim.runs.sweep import sweep_code

    first = sweep_code(spec)
    assert first.startswith(code_version() + "+tree-")
    tree.write_text(tree.read_text().replace('"min_rows": 20', '"min_rows": 21'))
    assert sweep_code(load_spec(spec_file)) not in (first, code_version())
    (tmp_path / "plain.toml").write_text(SPEC.format(ablation="false"))
    assert sweep_code(load_spec(tmp_path / "plain.toml")) == code_version()


@pytest.mark.parametrize(
    ("line", "expected"),
    [
        ('intent_tree = "nowhere.json"', "intent_tree = 'nowhere.json': no such file"),
        ('intent_tree = "old.json"', "not a ground intent tree"),
        ('intent_tre = "trees/ground.json"', "intent_tree"),
    ],
)
def test_a_bad_intent_tree_key_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], line: str, expected: str
) -> None:
    from monopic.cli.main import main

    (tmp_path / "tiny.toml").write_text(SCENARIO)
    _intent_tree_file(tmp_path / "trees" / "ground.json")
    shipped = Path(__file__).parents[2] / "monopic" / "tree" / "default_tree.json"
    (tmp_path / "old.json").write_text(shipped.read_text())
    spec_file = tmp_path / "spec.toml"
    spec_file.write_text(line + "\n" + SPEC.format(ablation="false"))
    assert main(["sweep", str(spec_file), "--dry-run"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(spec_file) in err and expected in err, err


def test_the_judged_intent_sweep_shares_no_run_or_seed_with_the_training_data() -> None:
    """intent-judged draws other seeds and values outside intent-train's ranges (both halves)."""
    import tomllib

    from sim.runs.sweep import expand_spec, load_spec, parse_spec
    from tests.paths import SCENARIOS

    halves = [
        expand_spec(load_spec(SCENARIOS / "datasets" / name))
        for name in ("intent-train.toml", "intent-train-b.toml")
    ]
    assert not {(r.family, r.scenario.seed) for r in halves[0]} & {
        (r.family, r.scenario.seed) for r in halves[1]
    }
    train = halves[0] + halves[1]
    draws = []
    for name in ("intent-judged.toml", "intent-judged-b.toml", "intent-judged-c.toml"):
        judged_path = SCENARIOS / "sweeps" / name
        data = tomllib.loads(judged_path.read_text())
        assert data.pop("intent_tree") == "../../recordings/intent/ground.json"
        judged = expand_spec(parse_spec(judged_path, data))  # the tree file is made later
        assert {r.family for r in judged} == {r.family for r in train}
        assert not {(r.family, r.scenario.seed) for r in train} & {
            (r.family, r.scenario.seed) for r in judged
        }
        for key in ("scene.road.lane_width", "pedestrian.speed", "pedestrian.behaviour.stop_lead"):
            top = max(r.params[key] for r in train)
            assert min(r.params[key] for r in judged) > top, key
        draws.append({(r.family, r.scenario.seed) for r in judged})
    for k, draw in enumerate(draws):  # each fresh draw repeats no run judged before
        assert not draw & set().union(*draws[:k])
    # The cue-sensitivity dataset is judged too: other seeds, the judged road and speeds.
    sensitivity = expand_spec(load_spec(SCENARIOS / "datasets" / "intent-sensitivity.toml"))
    assert len(sensitivity) == 7 * 32
    assert not {(r.family, r.scenario.seed) for r in train} & {
        (r.family, r.scenario.seed) for r in sensitivity
    }
    for key in ("scene.road.lane_width", "pedestrian.speed"):
        assert min(r.params[key] for r in sensitivity) > max(r.params[key] for r in train)
    assert max(r.params["pedestrian.behaviour.head_check_probability"] for r in judged) < min(
        r.params["pedestrian.behaviour.head_check_probability"] for r in train
    )


def test_the_shipped_trees_judged_spec_draws_intent_judged_e_s_runs() -> None:
    """docs/intent/verdict.md judges the shipped tree on intent-judged-e's own runs: the two
    specs must expand to the same scenarios, only the tree differs."""
    import tomllib

    from sim.runs.sweep import expand_spec, load_spec, parse_spec
    from tests.paths import ROOT, SCENARIOS

    judged_path = SCENARIOS / "sweeps" / "intent-judged-e.toml"
    data = tomllib.loads(judged_path.read_text())
    data.pop("intent_tree")  # session 13's tree, made later from recordings/
    judged = expand_spec(parse_spec(judged_path, data))
    shipped_spec = load_spec(SCENARIOS / "sweeps" / "intent-judged-e-shipped.toml")
    shipped = expand_spec(shipped_spec)
    assert shipped_spec.intent_tree == (ROOT / "monopic" / "tree" / "ground_tree.json").resolve()
    assert len(shipped) == len(judged) == 4 * 128 + 3 * 32
    assert [(r.id, r.scenario) for r in shipped] == [(r.id, r.scenario) for r in judged]


LABELS = [
    ("kind", '["near-miss"]', "['near-miss']"),
    ("family", '["cpna-25"]', "['cpna-25']"),
    ("name", '["other"]', "['other']"),
    ("description", '["x"]', "['x']"),
]


@pytest.mark.parametrize(("key", "toml", "shown"), LABELS, ids=[k for k, _, _ in LABELS])
def test_a_sweep_parameter_the_run_does_not_apply_is_refused_when_the_spec_is_read(
    tmp_path: Path, key: str, toml: str, shown: str
) -> None:
    """kind, family, name, description label a file's runs: swept, the runs kept the file's
    (a near miss counted as a collision). One rule for [include.parameters] and a file's
    own [sweep.parameters]."""
    from sim.scenario.files import load

    (tmp_path / "tiny.toml").write_text(SCENARIO)
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC.format(ablation="false") + f"[include.parameters]\n{key} = {toml}\n")
    reason = (
        f"cannot be swept: the file's {key} labels all its runs (their results and the "
        f"report keep it); to vary it, write one scenario file per {key}"
    )
    with pytest.raises(UserError) as err:
        load_spec(spec)
    assert str(err.value) == f"{spec}: include[0].parameters.{key} = {shown}: {reason}"
    (tmp_path / "own.toml").write_text(SCENARIO + f"{key} = {toml}\n")
    with pytest.raises(UserError) as err:
        load(tmp_path / "own.toml")
    assert str(err.value) == f"{tmp_path / 'own.toml'}: sweep.parameters.{key}: {reason}"


def test_a_swept_scale_is_the_scale_of_the_run_its_results_and_its_dry_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`scale` swept changes the scenario (robot, road, horizon): its run, result row and
    the dry run carry the swept scale, not the file's."""
    (tmp_path / "tiny.toml").write_text(SCENARIO)
    spec = tmp_path / "spec.toml"
    spec.write_text(
        SPEC.format(ablation="false")
        + 'sampling = "base"\n[include.parameters]\nscale = ["small", "car"]\n'
    )
    runs = expand_spec(load_spec(spec))
    assert [(r.scale, r.params, r.scenario.robot.width) for r in runs] == [
        ("small", {"scale": "small"}, 0.6),
        ("car", {"scale": "car"}, 1.8),
    ]
    out = tmp_path / "r.jsonl"
    assert main(["sweep", str(spec), "--out", str(out), "--dry-run"]) == 0
    assert capsys.readouterr().out.splitlines()[2].split() == ["tiny", "collision", "car/small",
                                                               "2", "2", "12"]  # fmt: skip
    run_sweep(load_spec(spec), out, local_executor(1), progress=False, record="none")
    assert sorted((r.scale, r.params["scale"]) for r in read_results(out)) == [
        ("car", "car"),
        ("small", "small"),
    ]
    # A file's own sweep may sweep it too (the same rule).
    from sim.scenario.files import load

    (tmp_path / "own.toml").write_text(SCENARIO + 'scale = ["small", "car"]\n')
    own = [(p["robot.speed"], p["scale"]) for p in load(tmp_path / "own.toml").runs()]
    assert own[:2] == [(0.0, "small"), (0.0, "car")] and len(own) == 6


def _results_line(**fields: object) -> str:
    return json.dumps({"schema": 1, "code": code_version(), "sweep": "tiny", **fields}) + "\n"


# What the results path holds, and the line a sweep refuses it with ({out}, {tmp} filled in).
OUTPUTS = {
    "a folder": ("folder", "--out {out}: is a folder; give a file name"),
    "a file in the way": (
        "in the way",
        "--out {tmp}/plain/deeper: a file is in the way of this folder",
    ),
    "another sweep": (
        _results_line(id="a/1", sweep="demo"),
        "{out}: holds runs of another sweep ('demo' (1 run)), not of 'tiny'; a results file "
        "holds one sweep, so give this one another --out (or --restart to set that file aside "
        "and start over)",
    ),
    "other code": (
        _results_line(id="a/1", code="0123456789ab"),
        "{out}: holds runs of other code (1 by 0123456789ab; this code is "
        + code_version()
        + "), and a sweep resumes only its own code's runs; use another --out, or --restart "
        "to set the old results aside and start over",
    ),
    "a newer schema": (
        _results_line(id="a/1", schema=2),
        "{out}:1: a result of schema 2, newer than this code's 1 (written by newer code, which "
        "alone reads it); to redo its runs with this code, use another --out, or --restart to "
        "set the file aside and start over",
    ),
    "a bad line": ("{}\n" + _results_line(id="a/1"), "{out}:1: not a result line ("),
    "a sweep writing it": (
        "locked",
        "{out}: another sweep is writing to it; wait for it or use another --out",
    ),  # fmt: skip
}


@pytest.mark.parametrize("case", list(OUTPUTS))
def test_the_dry_run_refuses_what_the_run_refuses_with_the_same_line(
    spec_path: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    case: str,
) -> None:
    import sim.runs.executors

    def no_runs(*args: object, **kwargs: object) -> None:
        raise AssertionError("a run started before the output was checked")

    monkeypatch.setattr(sim.runs.executors, "local_executor", lambda *a, **k: no_runs)
    holds, expected = OUTPUTS[case]
    out = tmp_path / "r.jsonl"
    writer = None
    if holds == "folder":
        out.mkdir()
    elif holds == "in the way":
        (tmp_path / "plain").write_text("x")
        out = tmp_path / "plain" / "deeper" / "r.jsonl"
    elif holds == "locked":
        writer = ResultsWriter(out)  # another sweep appending to it
    else:
        out.write_text(holds)
    before = sorted(p.name for p in tmp_path.iterdir())
    lines = []
    try:
        for dry in (["--dry-run"], []):
            assert main(["sweep", str(spec_path), "--out", str(out), *dry]) == 2
            err = capsys.readouterr().err.strip()
            assert "\n" not in err, err
            lines.append(err)
    finally:
        if writer is not None:
            writer.close()
    assert lines[0] == lines[1]
    expected = "monopic sweep: error: " + expected.format(out=out, tmp=tmp_path)
    assert lines[0].startswith(expected), lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # neither wrote anything


def test_a_dry_run_with_restart_says_what_it_would_set_aside(
    spec_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "r.jsonl"
    out.write_text(_results_line(id="a/1", sweep="demo"))
    assert main(["sweep", str(spec_path), "--out", str(out), "--dry-run", "--restart"]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[0] == f"would set aside (--restart): {out} -> {tmp_path / 'r.demo.jsonl'}"
    assert printed[1] == f"{spec_path}: 3 runs in 1 families, 0 already in {out}, 3 to run"
    (tmp_path / "r.demo.jsonl").write_text("")  # an earlier one is never overwritten
    for dry in (["--dry-run"], []):
        assert main(["sweep", str(spec_path), "--out", str(out), "--restart", *dry]) == 2
        assert capsys.readouterr().err.strip() == (
            f"monopic sweep: error: {tmp_path / 'r.demo.jsonl'}: already there; move it away "
            f"to restart {out}"
        )
    assert out.read_text() == _results_line(id="a/1", sweep="demo")
