"""Command-line mistakes a newcomer makes: one line that points at the real mistake."""

from __future__ import annotations

import os
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from monopic.cli.main import main
from tests.paths import SCENARIOS

if TYPE_CHECKING:
    from sim.scenario.spec import Scenario

CASE5 = SCENARIOS / "cases" / "case5_perpendicular_right.toml"
DEMO = SCENARIOS / "sweeps" / "demo.toml"


def one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip()
    assert err and "\n" not in err, err
    return err


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["sweep", str(CASE5), "--dry-run"], "this is a scenario file, not a sweep spec"),
        (["dataset", str(CASE5), "--out", "x", "--estimate-only"], "not a dataset spec"),
        (["record", str(DEMO)], "this is a sweep spec, not a scenario file"),
        (["closed-loop", str(DEMO)], f"run it with `monopic sweep {DEMO}`"),
    ],
)
def test_a_scenario_file_and_a_sweep_spec_given_for_each_other_are_named(
    capsys: pytest.CaptureFixture[str], argv: list[str], expected: str
) -> None:
    assert main(argv) == 2
    assert expected in one_line_error(capsys)


def test_a_misspelt_required_key_is_named_as_unknown(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "spec.toml"
    spec.write_text(f'name = "x"\n[[include]]\nfile = ["{CASE5}"]\n')
    assert main(["sweep", str(spec), "--dry-run"]) == 2
    assert one_line_error(capsys) == (
        f"monopic sweep: error: {spec}: include[0].file = ['{CASE5}']: unknown key, and "
        "include[0].files is missing: did you mean 'files'?"
    )
    spec.write_text(f'name = "x"\n[[include]]\nfiles = ["{CASE5}"]\nsamplng = "grid"\n')
    assert main(["sweep", str(spec), "--dry-run"]) == 2
    assert "include[0].samplng = 'grid': unknown key (did you mean 'sampling'? known" in (
        one_line_error(capsys)
    )
    scenario = tmp_path / "s.toml"
    scenario.write_text(CASE5.read_text().replace('kind = "case"\ncase', 'knid = "case"\ncase'))
    assert main(["record", str(scenario)]) == 2
    assert "path.knid = 'case': unknown key, and path.kind is missing" in one_line_error(capsys)


def test_base_sampling_applies_its_parameters_and_refuses_draw_settings(tmp_path: Path) -> None:
    """sampling = "base" with [include.parameters] used to drop them without a word."""
    from monopic.errors import UserError
    from sim.runs.sweep import expand_spec, load_spec

    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'name = "x"\n[[include]]\nfiles = ["{CASE5}"]\nsampling = "base"\n'
        '[include.parameters]\nduration = [2.0]\n"robot.speed" = [0.0, 1.0]\n'
    )
    runs = expand_spec(load_spec(spec))
    assert [r.params for r in runs] == [
        {"duration": 2.0, "robot.speed": 0.0},
        {"duration": 2.0, "robot.speed": 1.0},
    ]
    assert {r.scenario.duration for r in runs} == {2.0}
    assert [r.scenario.robot.speed for r in runs] == [0.0, 1.0]
    # Without parameters: one run at the file's own values (its 18-run sweep dropped).
    spec.write_text(f'name = "x"\n[[include]]\nfiles = ["{CASE5}"]\nsampling = "base"\n')
    (run,) = expand_spec(load_spec(spec))
    assert run.params == {} and run.scenario.duration == 4.0
    for sampling, key in (("base", "runs = 3"), ("grid", "seed = 2")):
        spec.write_text(
            f'name = "x"\n[[include]]\nfiles = ["{CASE5}"]\nsampling = "{sampling}"\n{key}\n'
        )
        with pytest.raises(UserError) as err:
            load_spec(spec)
        assert str(err.value) == (
            f"{spec}: include[0].{key}: draws at random only: "
            f'sampling = "{sampling}" would ignore it'
        )


def test_every_command_makes_the_folder_its_output_goes_to(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One rule for output paths (README): a missing folder is created, for tree and replay
    here; video (test_cli_video_errors), sweep and report (test_sweep), closed-loop and
    dataset (below) and record (tests/test_walkthrough.py) in their own tests."""
    import numpy as np

    from tests.monopic.test_image_tree_judge import write_log

    t = np.arange(0.0, 8.0, 0.05)  # three hand-made walks in the authors' log format
    logs = [
        write_log(tmp_path / f"walk{k}.csv", t, 200 + v * t, 240 + 0 * t, phi)
        for k, (v, phi) in enumerate([(40.0, 90.0), (-30.0, 150.0), (0.0, 30.0)])
    ]
    tree = tmp_path / "a" / "b" / "tree.json"
    assert main(["tree", "train", *map(str, logs[:2]), "--out", str(tree)]) == 0
    assert tree.is_file()
    table = tmp_path / "c" / "d" / "pred.csv"
    assert main(["replay", str(logs[2]), "--tree", str(tree), "--csv", str(table)]) == 0
    assert table.read_text().count("\n") > 10
    capsys.readouterr()
    (tmp_path / "plain").write_text("x")
    assert main(["tree", "train", str(logs[0]), "--out", str(tmp_path / "plain" / "t.json")]) == 2
    assert one_line_error(capsys).endswith("a file is in the way of this folder")
    assert main(["tree", "train", str(logs[0]), "--out", str(tmp_path)]) == 2
    assert one_line_error(capsys).endswith(f"--out {tmp_path}: is a folder; give a file name")


TINY = """
name = "tiny"
kind = "collision"
duration = 0.4
[robot.camera]
width = 256
height = 144
[path]
kind = "case"
case = 5
distance = 3.0
[sweep]
sampling = "grid"
[sweep.parameters]
"robot.speed" = [0.0, 1.0, 2.0]
"""


def test_dry_run_shows_runs_per_family_and_a_time_it_says_how_it_computed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    (tmp_path / "tiny.toml").write_text(TINY)
    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'name = "t"\n[[include]]\nfiles = ["tiny.toml", "{CASE5}"]\nsampling = "base"\n'
    )
    out = tmp_path / "r.jsonl"
    assert main(["sweep", str(spec), "--out", str(out), "--dry-run", "--workers", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == f"{spec}: 2 runs in 2 families, 0 already in {out}, 2 to run"
    assert lines[1].split() == ["family", "kind", "scale", "runs", "to", "run", "frames", "(at",
                                "most)"]  # fmt: skip
    assert lines[2].split() == ["cases", "case", "small", "1", "1", "60"]
    assert lines[3].split() == ["tiny", "collision", "small", "1", "1", "6"]
    # 6 frames at 256x144 and 60 at 768x432, each with the ablation, on 2 workers.
    bench = (6 * (0.0456 / 9 + 0.0339 + 0.0217) + 60 * 0.1012) / 66
    assert lines[4] == (
        f"time: about 11 s on 2 workers: 8 s to start, then up to 66 frames x {bench:.3f} s "
        "per frame and worker "
        "(the simulator benchmark's 79.5/101.2 ms per 768x432 frame and its per-person "
        "figures (bench/history.jsonl); no run measured yet)"
    )
    assert not out.exists()  # a dry run writes nothing
    # Finished runs in the results file scale each run's benchmark figure by how much
    # slower they ran than theirs (lines without a camera: the default 768x432, one person).
    from sim.runs.estimate import bench_frame_seconds
    from sim.runs.sweep import load_spec, sweep_code
    from sim.scenario.spec import CameraSpec

    mine = {"sweep": "t", "code": sweep_code(load_spec(spec))}  # else the run would refuse it
    rows = [{"id": "x/1", "frames": 10, "timing": {"wall_s": 3.0}, **mine},
            {"id": "x/2", "frames": 30, "timing": {"wall_s": 5.0}, **mine}]  # fmt: skip
    out.write_text("".join(json.dumps(r) + "\n" for r in rows))
    assert main(["sweep", str(spec), "--out", str(out), "--dry-run", "--no-ablation"]) == 0
    time_line = capsys.readouterr().out.splitlines()[4]
    full, small = CameraSpec(), CameraSpec(width=256, height=144)
    scale = 8.0 / (40 * bench_frame_seconds(full, False))
    per = scale * (6 * bench_frame_seconds(small, False) + 60 * bench_frame_seconds(full, False))
    assert time_line.startswith("time: about ") and time_line.endswith(
        f"up to 66 frames x {per / 66:.3f} s per frame and worker (each run's benchmark "
        f"figure for its camera and people x {scale:.2f}, as measured on 2 finished runs in "
        f"{out})"
    )


def test_a_sweep_reports_the_recordings_it_kept_and_leaves_no_empty_folders(
    tmp_path: Path,
) -> None:
    from sim.commands.sweep import kept_recordings

    folder = tmp_path / "r_rrd"
    (folder / "cases").mkdir(parents=True)
    (folder / "cpna-25" / "deeper").mkdir(parents=True)
    (folder / "cpna-25" / "0001-ab.rrd").write_bytes(b"RRF2")
    assert kept_recordings(folder, "failed") == (
        f"recordings (missed collisions and false alarms): 1 in {folder}"
    )
    assert sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*")) == [
        "cpna-25",
        "cpna-25/0001-ab.rrd",
    ]
    (folder / "cpna-25" / "0001-ab.rrd").unlink()
    assert kept_recordings(folder, "all") == "recordings (every run): none kept"
    assert not folder.exists()
    assert kept_recordings(folder, "failed").endswith("none kept")


def test_report_of_a_file_that_is_not_a_results_file_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    walk = tmp_path / "walk.csv"
    walk.write_text("time,x\n1,2\n")
    assert main(["report", str(walk)]) == 2
    err = one_line_error(capsys)
    assert err == (
        f"monopic report: error: {walk}: not a sweep's results file (its first line, "
        "'time,x', is not a JSON result line): give the .jsonl that `monopic sweep` writes"
    )
    assert "--out" not in err
    assert not (tmp_path / "walk_report").exists()
    empty = tmp_path / "empty.jsonl"
    empty.write_text("")
    assert main(["report", str(empty)]) == 2
    assert one_line_error(capsys).endswith(f"{empty}: no finished runs in it yet")


@pytest.mark.parametrize(
    ("option", "key", "value", "reason"),
    [
        ("--distance", "path.distance", -3.0, "must be >= 0 m"),
        (
            "--lateral-offset",
            "path.lateral_offset",
            40.0,
            "the pedestrian's path leaves the street",
        ),
        ("--robot-speed", "robot.speed", 3.5, "must be <= 3 m/s (robot.max_speed)"),
        ("--duration", "duration", 0.0, "must be > 0 s"),
        ("--pedestrian-speed", "pedestrian.speed", 0.2, "must be >= 0.3 m/s"),
        ("--seed", "seed", -1, "must be an integer in [0, 2147483647]"),
    ],
)
def test_record_checks_a_case_as_a_scenario_file_checks_it(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    option: str,
    key: str,
    value: float,
    reason: str,
) -> None:
    """The same value is refused on the command line and in a file, for the same reason."""
    from sim.scenario.files import build, with_values
    from sim.scenario.toml_table import FieldError

    # Case 5 as a file: small scale, the command's robot (max_speed 3 m/s).
    text = CASE5.read_text().split("[sweep]")[0]
    with pytest.raises(FieldError) as in_file:
        build(CASE5, with_values(tomllib.loads(text), {key: value}))
    assert reason in in_file.value.reason
    assert main(["record", "5", option, str(value), "--out", str(tmp_path / "x.rrd")]) == 2
    err = one_line_error(capsys)
    assert f"{option} {value:g}" in err and reason in err
    assert not (tmp_path / "x.rrd").exists()


@pytest.mark.parametrize("command", ["sweep", "dataset", "closed-loop", "ncap"])
@pytest.mark.parametrize(
    ("options", "expected"),
    [
        (["--address", "127.0.0.1:1"], "--address is for --executor ray"),
        (["--executor", "ray", "--workers", "2"], "--workers is for --executor local (Ray"),
    ],
)
def test_the_executor_options_refuse_what_they_cannot_apply(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, options: list[str],
    expected: str,
) -> None:  # fmt: skip
    out = tmp_path / ("out" if command in ("dataset", "ncap") else "out.jsonl")
    given = {"sweep": [str(DEMO)], "dataset": [str(DEMO)], "ncap": [],
             "closed-loop": ["--cases", "5"]}[command]  # fmt: skip
    assert main([command, *given, "--out", str(out), *options]) == 2
    assert expected in one_line_error(capsys)
    assert not out.exists()


def record_scenario(*argv: str) -> Scenario:
    """The Scenario `monopic record ARGV` would run (its arguments parsed as the CLI does)."""
    from monopic.cli.main import build_parser
    from sim.commands.record import resolve_scenario

    args = build_parser().parse_args(["record", *argv])
    return resolve_scenario(args.scenario, args)


def test_a_case_on_the_command_line_is_the_placement_with_the_small_robots_limit() -> None:
    """Placed as a small-scale file is, a case is the scenario CasePlacement gives, with the
    one difference the file's checks make: the small robot's max_speed, 3 m/s (not 20)."""
    from monopic.cases import Case
    from sim.scenario.cases import CasePlacement

    for case in Case:
        before = CasePlacement(case).scenario()
        small = replace(before, robot=replace(before.robot, max_speed=3.0))
        assert record_scenario(str(int(case))) == small, case
    values = ["--distance", "5", "--lateral-offset", "1.5", "--pedestrian-speed", "1.1",
              "--robot-speed", "1.5", "--duration", "3", "--seed", "4"]  # fmt: skip
    placed = CasePlacement(Case.OBLIQUE_LEFT_TOWARD, distance=5.0, lateral_offset=1.5,
                           pedestrian_speed=1.1, robot_speed=1.5, duration=3.0, seed=4)  # fmt: skip
    before = placed.scenario()
    assert record_scenario("4", *values) == replace(
        before, robot=replace(before.robot, max_speed=3.0)
    )


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        # above the small robot's max_speed (RobotSpec's 20 m/s let it run at 10)
        (["5", "--robot-speed", "10"], "--robot-speed 10: must be <= 3 m/s (robot.max_speed)"),
        # off the end of the road within the run: both values named
        (
            ["9", "--robot-speed", "3", "--duration", "40"],
            "--robot-speed 3 --duration 40: the robot would drive off the end of the road "
            "within the run (120.4 m > 120.0 m): lower the speed or the duration",
        ),
        # the pedestrian off the street, with where it leaves
        (
            ["5", "--lateral-offset", "6"],
            "--lateral-offset 6: the pedestrian's path leaves the street (x in [-120, 120] m, "
            "y in [-6.65, 6.65] m); at {t = 0.0, x = 8.0, y = 8.8}",
        ),
        # each placement range
        (["5", "--distance", "-0.5"], "--distance -0.5: must be >= 0 m"),
        (["9", "--distance", "201"], "--distance 201: must be <= 200 m"),
        (["5", "--pedestrian-speed", "0.29"], "--pedestrian-speed 0.29: must be >= 0.3 m/s"),
        (["8", "--pedestrian-speed", "10.5"], "--pedestrian-speed 10.5: must be <= 10 m/s"),
        (["5", "--robot-speed", "-1"], "--robot-speed -1: must be >= 0 m/s"),
        (["5", "--duration", "0"], "--duration 0: must be > 0 s"),
        (["9", "--duration", "61"], "--duration 61: must be <= 60 s"),
        (["5", "--seed", "2147483648"], "--seed 2147483648: must be an integer in [0, 2147483647]"),
        # a value that cannot apply is refused, not dropped
        (["9", "--pedestrian-speed", "2"], "--pedestrian-speed 2: case 9 (still) stands"),
        (["crossing", "--seed", "3"], "--seed 3: 'crossing' is a fixed scenario"),
    ],
)
def test_each_check_a_case_on_the_command_line_gets(argv: list[str], expected: str) -> None:
    from monopic.errors import UserError

    with pytest.raises(UserError) as err:
        record_scenario(*argv)
    assert str(err.value).startswith(expected), str(err.value)


def _help_ranges() -> dict[str, tuple[str, float, float, str]]:
    """Each case option's range as `monopic record --help` states it: (opening bracket, low,
    high, its text)."""
    import re

    from monopic.cli.main import build_parser

    record = build_parser()._subparsers._group_actions[0].choices["record"]  # type: ignore[union-attr]
    out = {}
    for action in record._actions:
        option = action.option_strings[0] if action.option_strings else ""
        if option in ("--distance", "--lateral-offset", "--pedestrian-speed", "--robot-speed",
                      "--duration", "--seed"):  # fmt: skip
            found = re.search(r"([\[(])(-?[\d.]+), (-?[\d.]+)\]", action.help or "")
            assert found, (option, action.help)
            out[option] = (found[1], float(found[2]), float(found[3]), action.help or "")
    return out


# For each option, other values that leave the option's own range as the only limit: a
# standing person (case 9) on a standing robot, or (walking speeds) one walking along the
# robot's path for a short run.
RANGE_CONTEXT = {
    "--distance": ["9", "--robot-speed", "0"],
    "--lateral-offset": ["9", "--robot-speed", "0"],
    "--pedestrian-speed": ["8", "--distance", "30", "--duration", "1"],
    "--robot-speed": ["9", "--duration", "1"],
    "--duration": ["9", "--robot-speed", "0"],
    "--seed": ["5"],
}


@pytest.mark.parametrize("option", list(RANGE_CONTEXT))
def test_record_help_states_the_ranges_it_checks(option: str) -> None:
    """Just inside each end of the range --help states is accepted, just outside refused
    with one line naming the option; the default --help states is the one applied."""
    from monopic.errors import UserError

    opening, low, high, text = _help_ranges()[option]
    integer = option == "--seed"
    step = 1 if integer else 0.01
    inside = [low + step if opening == "(" else low, high]
    outside = [low if opening == "(" else low - step, high + step]
    context = RANGE_CONTEXT[option]
    for value in inside:
        shown = str(int(value)) if integer else f"{value:g}"
        record_scenario(*context, option, shown)
    for value in outside:
        shown = str(int(value)) if integer else f"{value:g}"
        with pytest.raises(UserError) as err:
            record_scenario(*context, option, shown)
        assert str(err.value).startswith(f"{option} {shown}"), str(err.value)
    default = text.rsplit("default ", 1)[1]
    assert record_scenario(*context, option, default) == record_scenario(*context)


def test_record_applies_a_files_own_values_and_refuses_what_cannot_apply(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Options given with a scenario file replace its values, through its checks; without
    them the file's own apply."""
    car = SCENARIOS / "families" / "car" / "cpna25.toml"  # a crossing at 8.33 m/s
    base = record_scenario(str(car))
    assert base.robot.speed == 8.33
    given = record_scenario(str(car), "--robot-speed", "5", "--duration", "5", "--seed", "7",
                            "--pedestrian-speed", "1.2")  # fmt: skip
    assert (given.robot.speed, given.duration, given.seed) == (5.0, 5.0, 7)
    assert given.pedestrian.speed == 1.2 and given.name == base.name
    # A case placement's options on a case file; on a crossing, one line.
    placed = record_scenario(str(CASE5), "--distance", "6", "--lateral-offset", "0.5")
    assert placed.pedestrian.anchor is not None
    assert (placed.pedestrian.anchor.x, placed.pedestrian.anchor.y) == (6.0, 0.5)
    argv = ["record", str(car), "--distance", "6"]
    assert main(argv) == 2
    assert one_line_error(capsys) == (
        f"monopic record: error: --distance 6: {car}: path.distance is a case placement's "
        "(path.kind = 'case'); this file's path.kind is 'crossing', which has no distance"
    )
    assert main(["record", str(car), "--robot-speed", "25"]) == 2
    assert one_line_error(capsys) == (
        f"monopic record: error: --robot-speed 25: {car}: robot.speed = 25.0: must be <= "
        "20 m/s (robot.max_speed)"
    )


def test_ray_log_lines_go_above_the_progress_bar_not_into_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Ray logs its start and code upload through the 'ray' logger while the sweep's bar is
    drawn; inside the sweep they are written by tqdm, which clears the bar line first."""
    import logging

    from tqdm import tqdm

    from sim.commands.executor_options import logs_above_the_bar

    pytest.importorskip("ray")
    ray_logger = logging.getLogger("ray")
    before = list(ray_logger.handlers)
    with logs_above_the_bar("ray"), tqdm(total=2, desc="sweep", ncols=60) as bar:
        bar.update(1)
        logging.getLogger("ray._private.worker").warning("Started a local Ray instance.")
        bar.update(1)
    assert ray_logger.handlers == before  # restored after the sweep
    # Joining a cluster: ray is imported under the executor's connect timeouts, which do
    # not outlive the import (a local instance's processes must not inherit them).
    from sim.runs.executors import RAY_CONNECT_ENV

    with logs_above_the_bar("ray", "127.0.0.1:1"):
        assert not set(RAY_CONNECT_ENV) & set(os.environ)
    err = capsys.readouterr().err
    (logged,) = [seg for seg in err.split("\r") if "Started a local" in seg]
    # tqdm.write: the bar's line cleared, the message on a line of its own, the bar redrawn
    # after it; without the redirect the message is glued to the bar's text ("| 1/2 [...]").
    assert logged.endswith("Started a local Ray instance.\n") and "|" not in logged, err


@pytest.mark.slow
def test_closed_loop_and_dataset_make_their_output_folders(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The output rule for the two commands the walkthrough runs without --out."""
    scenario = tmp_path / "tiny.toml"
    scenario.write_text(TINY.split("[sweep]")[0])
    table = tmp_path / "a" / "b" / "table.md"
    rrd_dir = tmp_path / "c" / "rrd"
    argv = ["closed-loop", str(scenario), "--robot-speeds", "1", "--policies", "none,truth"]
    assert main([*argv, "--out", str(table), "--rrd-dir", str(rrd_dir)]) == 0
    assert table.read_text().startswith("# Closed loop") and rrd_dir.is_dir()
    spec = tmp_path / "spec.toml"
    spec.write_text('name = "t"\n[[include]]\nfiles = ["tiny.toml"]\nsampling = "base"\n')
    out = tmp_path / "d" / "e" / "dataset"
    capsys.readouterr()
    assert main(["dataset", str(spec), "--out", str(out)]) == 0
    assert (out / "README.md").is_file() and (out / "runs").is_dir()
    printed = capsys.readouterr().out
    assert "time: about 8 s on 1 worker: 8 s to start, then up to 6 frames x " in printed


def test_output_piped_into_a_reader_that_stops_early_ends_quietly() -> None:
    # `monopic sweep large.toml --dry-run | head -1`: the reader has gone; the command stops
    # with 141 and no traceback (Python's would be two). Standard output is a pipe whose
    # read end is closed before the command starts, so the first write fails, every time.
    import subprocess
    import sys

    code = (
        "import os, sys\n"
        "r, w = os.pipe(); os.close(r); os.dup2(w, 1)\n"
        "from monopic.cli.main import main\n"
        f"sys.exit(main(['sweep', {str(SCENARIOS / 'sweeps/large.toml')!r}, '--dry-run']))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr


def test_a_dataset_estimate_refuses_what_the_build_refuses_with_the_same_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import json

    import sim.dataset.build

    def no_render(*args: object, **kwargs: object) -> None:
        raise AssertionError("a run was rendered before the folder was checked")

    monkeypatch.setattr(sim.dataset.build, "render_run", no_render)
    (tmp_path / "tiny.toml").write_text(TINY.split("[sweep]")[0])
    spec = tmp_path / "spec.toml"
    spec.write_text('name = "t"\n[[include]]\nfiles = ["tiny.toml"]\nsampling = "base"\n')
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("x")
    another = tmp_path / "another"
    another.mkdir()
    (another / "dataset.json").write_text(json.dumps({"name": "o", "spec_digest": "0"}))
    for out, expected in [
        (a_file, f"--out {a_file}: is a file, not a dataset folder"),
        (a_file / "ds", f"--out {a_file}: a file is in the way of this folder"),
        (other, f"{other}: exists and is not empty (and is not a dataset of this spec)"),
        (another, f"{another}: holds dataset 'o' made from another spec (digest 0 vs "),
    ]:
        lines = []
        for estimate in (["--estimate-only"], []):
            assert main(["dataset", str(spec), "--out", str(out), *estimate]) == 2
            lines.append(one_line_error(capsys))
        assert lines[0] == lines[1]
        assert lines[0].startswith(f"monopic dataset: error: {expected}"), lines[0]
