"""The benchmark history (bench/history.py) and BENCHMARKS.md rendered from it (bench/render.py).

No benchmark runs here: the histories are written by the tests, except the two checks at
the end, which read the committed history that real `make bench` runs wrote.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bench.goals import GOALS
from bench.history import (
    BENCHMARKS,
    HISTORY,
    SCHEMA,
    BenchRun,
    HistoryError,
    Machine,
    append,
    jsonable,
    parse_cpuinfo,
    read,
)
from bench.recorder import Recorder, this_command
from bench.render import latest, render, runnable
from tests.paths import ROOT

XEON = Machine(
    host="vm-a",
    cpu_model="Intel(R) Xeon(R) Processor",
    cpu_cores=2,
    cpu_allowed=2,
    cpu_flags=("avx2", "avx512f", "avx512_vnni", "avx512_bf16", "amx_tile", "amx_int8"),
    virtual=True,
    os="Linux 6.1 x86_64",
    python="3.11.9",
)
EPYC = Machine(
    host="vm-b",
    cpu_model="AMD EPYC",
    cpu_cores=2,
    cpu_allowed=2,
    cpu_flags=("avx2",),
    virtual=True,
    os="Linux 6.1 x86_64",
    python="3.11.9",
)


def latency(threads: int, ours_ms: float, ref_ms: float) -> list[dict[str, Any]]:
    """compare_reference's latency rows for the whole frame on frames both found."""
    base = {"threads": threads, "frames": "both found", "stage": "whole frame"}
    return [
        {**base, "side": "ours", "p50_ms": ours_ms, "p95_ms": ours_ms * 1.2,
         "ratio_p50_x": ours_ms / ref_ms, "ratio_p95_x": 1.0},
        {**base, "side": "reference", "p50_ms": ref_ms, "p95_ms": ref_ms * 1.2,
         "ratio_p50_x": None, "ratio_p95_x": None},
    ]  # fmt: skip


def error_row(group: str, landmarks: str, verdict: str | None) -> dict[str, Any]:
    return {"group": group, "landmarks": landmarks, "verdict": verdict, "difference_px": 0.1}


def comparison(ratio1: tuple[float, float], ratio2: tuple[float, float], verdicts) -> dict:
    """compare_reference's results: latency rows, CPU time (= the wall time here), errors."""
    cpu = [
        {"threads": t, "side": side, "cpu_ms_per_frame": ms}
        for t, pair in ((1, ratio1), (2, ratio2))
        for side, ms in zip(("ours", "reference"), pair, strict=True)
    ]
    return {
        "latency": latency(1, *ratio1) + latency(2, *ratio2),
        "cpu": cpu,
        "landmark_error": [error_row(g, k, v) for g, k, v in verdicts],
    }


def bench_run(
    benchmark: str,
    date: str,
    results: dict[str, Any],
    table: str,
    machine: Machine = XEON,
    code: str = "0123456789ab",
) -> BenchRun:
    return BenchRun(
        benchmark=benchmark,
        title=f"Title of {benchmark}",
        date=date,
        duration_s=12.5,
        command=f".venv/bin/python bench/{benchmark}.py --rounds 4",
        code=code,
        commit="f" * 40,
        dirty=False,
        machine=machine,
        load_before=0.5,
        load_after=1.75,
        results=jsonable(results),
        table=table,
    )


def scenario(fps: float) -> dict[str, Any]:
    row = {"frames": 60, "runs": 4, "fps_median": fps, "fps_min": fps - 0.5}
    return {
        "scenario_runs": [
            {**row, "ablation": False, "shadows": True, "fps_max": fps + 0.5},
            {**row, "ablation": True, "shadows": True, "fps_max": fps + 0.5, "fps_median": 3.0},
        ]
    }


def test_a_history_line_round_trips(tmp_path: Path) -> None:
    run = bench_run(
        "post_pose",
        "2026-11-23T10:00:00Z",
        {"sets": [{"set": "rules, image", "total_us": 312.7, "spread": None}], "n": 3},
        "| stage | µs |\n| --- | ---: |",
    )
    back = BenchRun.from_line(run.to_line())
    assert back == run
    for name in run.__dataclass_fields__:
        assert getattr(back, name) == getattr(run, name), name
    path = tmp_path / "history.jsonl"
    append(path, run)
    append(path, run)
    assert read(path) == [run, run]
    assert path.read_text(encoding="utf-8").count("\n") == 2


def test_results_are_stored_as_plain_json() -> None:
    clean = jsonable({"a": (1, 2.5), "b": float("nan"), "c": np.float64(3.25), "d": np.int64(4)})
    assert clean == {"a": [1, 2.5], "b": None, "c": 3.25, "d": 4}
    assert type(clean["c"]) is float and type(clean["d"]) is int
    with pytest.raises(TypeError, match="not a result value"):
        jsonable({"a": object()})
    line = bench_run("x", "2026-11-23T10:00:00Z", {"v": math.inf}, "").to_line()
    assert '"v": null' in line


def test_a_torn_last_line_is_skipped_and_cut_before_the_next_append(tmp_path: Path) -> None:
    path = tmp_path / "history.jsonl"
    first = bench_run("a", "2026-11-23T10:00:00Z", {}, "")
    second = bench_run("b", "2026-11-23T11:00:00Z", {}, "")
    append(path, first)
    with path.open("ab") as fh:
        fh.write(second.to_line().encode()[:40])  # a crash mid-write
    assert read(path) == [first]
    append(path, second)
    assert read(path) == [first, second]
    assert len(path.read_bytes().splitlines()) == 2


def test_a_bad_line_is_named_not_dropped(tmp_path: Path) -> None:
    path = tmp_path / "history.jsonl"
    good = bench_run("a", "2026-11-23T10:00:00Z", {}, "").to_line()
    path.write_text(good + '{"not": "a run"}\n' + good)
    with pytest.raises(HistoryError, match=r"history.jsonl:2: not a benchmark history line"):
        read(path)
    path.write_text(good.replace(f'"schema": {SCHEMA}', f'"schema": {SCHEMA + 1}'))
    with pytest.raises(HistoryError, match=r":1: .*schema 2, this code reads 1"):
        read(path)


def test_cpuinfo_gives_the_model_and_the_vector_flags() -> None:
    x86 = (
        "processor\t: 0\nmodel name\t: Intel(R) Xeon(R) Processor\n"
        "flags\t\t: fpu sse4_2 avx2 hypervisor avx512f avx512_vnni avx512_bf16 amx_tile "
        "amx_int8 avx_vnni\n\nprocessor\t: 1\nmodel name\t: other\nflags\t\t: fpu\n"
    )
    model, flags, virtual = parse_cpuinfo(x86)
    assert model == "Intel(R) Xeon(R) Processor"
    assert flags == (
        "sse4_2", "avx2", "avx_vnni", "avx512f", "avx512_vnni", "avx512_bf16",
        "amx_tile", "amx_int8",
    )  # fmt: skip
    assert virtual
    arm = "processor\t: 0\nFeatures\t: fp asimd asimddp sve i8mm\nCPU part\t: 0xd0c\n"
    assert parse_cpuinfo(arm) == (None, ("asimd", "asimddp", "i8mm", "sve"), False)
    m = replace(XEON, cpu_flags=flags)
    assert m.vector_summary() == "AVX2 with AVX-VNNI, AVX-512 (VNNI, BF16), AMX (INT8)"
    assert EPYC.vector_summary() == "AVX2, no AVX-512"
    neon = replace(XEON, cpu_flags=("asimd", "asimddp", "sve"))
    assert neon.vector_summary() == "NEON with dot product, SVE"


def test_the_latest_run_of_each_benchmark_wins_by_date_not_file_order() -> None:
    new = bench_run("compare_reference", "2026-11-23T10:00:00Z", {}, "NEW")
    old = bench_run("compare_reference", "2026-11-22T10:00:00Z", {}, "OLD")
    same_date = bench_run("compare_reference", "2026-11-23T10:00:00Z", {}, "SAME DATE, LATER")
    assert latest([new, old])["compare_reference"].table == "NEW"
    assert latest([new, old, same_date])["compare_reference"].table == "SAME DATE, LATER"


def test_benchmarks_md_shows_goals_latest_results_and_flags() -> None:
    equal = [("clip", "hips", "equal"), ("rendered, 3 m", "hips", "equal"), ("10 m", "hips", None)]
    worse = [("clip", "hips", "worse"), ("rendered, 3 m", "hips", "equal")]
    runs = [
        # Newest first in the file: the renderer goes by date.
        bench_run(
            "compare_reference",
            "2026-11-23T09:30:00Z",
            comparison((12.05, 17.95), (9.51, 11.74), worse),
            "NEWEST COMPARISON TABLE",
        ),
        bench_run("simulator", "2026-11-23T09:40:00Z", scenario(17.3), "SIMULATOR TABLE"),
        bench_run(
            "compare_reference",
            "2026-11-22T11:20:00Z",
            comparison((12.60, 32.83), (7.62, 18.23), equal),
            "OLDER COMPARISON TABLE",
            machine=EPYC,
            code="aaaaaaaaaaaa",
        ),
    ]
    text = render(runs, HISTORY)
    assert text == render(runs, HISTORY)  # deterministic
    goals, rest = text.split("## Ours / reference by host")
    by_host, rest = rest.split("## Latest result of each benchmark")
    latest_part, index = rest.split("## Every run in the history")
    # The goal table reads the latest runs: 12.05 / 17.95 = 0.67 misses, 0.81 misses, a
    # worse landmark group misses (named), 17.3 fps meets.
    assert "| 0.67 (12.05 vs 17.95 ms) | no |" in goals
    assert "| 0.81 (9.51 vs 11.74 ms) | no |" in goals
    assert (
        "2 judged (group x landmarks): 0 better, 1 equal, 1 worse (worse: clip hips) | no" in goals
    )
    assert "| 17.3 fps (16.8-17.8 over 4 runs) | yes |" in goals
    assert "0.38" not in goals  # the older host's ratio is not the latest
    # Per host, the latest comparison on each: newest host first.
    xeon = by_host.index("Intel(R) Xeon(R) Processor, 2 cores")
    epyc = by_host.index("AMD EPYC, 2 cores")
    assert xeon < epyc
    assert "0.38 (12.60 vs 32.83 ms)" in by_host and "AVX2, no AVX-512" in by_host
    assert "0.67 (12.05 vs 17.95 ms) (misses)" in by_host
    assert "| 0.67 / 0.81 |" in by_host
    # Latest results: the newest table only, with command, date, machine, flags, code.
    assert "NEWEST COMPARISON TABLE" in latest_part and "SIMULATOR TABLE" in latest_part
    assert "OLDER COMPARISON TABLE" not in text
    assert latest_part.index("Title of compare_reference") < latest_part.index("Title of simulator")
    # Stored as the script's path (how older lines name it), shown as it runs today.
    assert "`.venv/bin/python -m bench.compare_reference --rounds 4`" in latest_part
    assert "- run: 2026-11-23 09:30 UTC, 12 s; load average 0.5 before, 1.8 after" in latest_part
    assert (
        "- CPU flags: `avx2 avx512f avx512_vnni avx512_bf16 amx_tile amx_int8` "
        "(AVX2, AVX-512 (VNNI, BF16), AMX (INT8))" in latest_part
    )
    assert "- code: `0123456789ab` (commit `ffffffffffff`)" in latest_part
    assert "2 runs of this benchmark in the history, the first on 2026-11-22 11:20 UTC" in text
    # The index lists every run, newest first.
    assert "3 runs in `bench/history.jsonl`, 2026-11-22 11:20 UTC to 2026-11-23 09:40 UTC" in index
    rows = index.split("| --- |", 1)[1]
    assert rows.index("2026-11-23 09:40") < rows.index("2026-11-23 09:30")
    assert rows.index("2026-11-23 09:30") < rows.index("2026-11-22 11:20")
    assert "docs/benchmarks.md" in text


def test_a_goal_without_a_run_says_so() -> None:
    text = render([bench_run("simulator", "2026-11-23T09:40:00Z", scenario(12.0), "T")], HISTORY)
    compare_goals = sum(goal.benchmark == "compare_reference" for goal in GOALS)
    assert compare_goals == 5  # 1 and 2 threads, CPU-seconds at 1 and 2, landmark error
    assert text.count("| not measured yet | - | no `compare_reference` run |") == compare_goals
    assert "| 12.0 fps (11.5-12.5 over 4 runs) | no |" in text
    assert "No runs in `bench/history.jsonl` yet" in render([], HISTORY)


def test_a_finished_recorder_appends_one_line_and_renders(tmp_path: Path) -> None:
    history, out = tmp_path / "history.jsonl", tmp_path / "BENCHMARKS.md"
    recorder = Recorder("post_pose", "Stage after pose", history=history, rendered=out)
    run = recorder.finish({"total_us": np.float64(312.5), "missing": float("nan")}, "TABLE\n")
    assert read(history) == [run]
    assert run.results == {"total_us": 312.5, "missing": None}
    assert run.table == "TABLE"
    assert len(run.code) == 12 and run.machine.cpu_cores >= 1 and run.machine.cpu_model
    assert run.date <= read(history)[0].date and run.date.endswith("Z")
    text = out.read_text(encoding="utf-8")
    assert "### Stage after pose" in text and "TABLE" in text
    recorder.finish({}, "NOT WRITTEN", write=False)
    assert len(read(history)) == 1


def test_a_run_records_the_command_that_runs_it_again_from_the_top_folder() -> None:
    argv = [str(ROOT / "bench" / "spin.py"), "--rounds", "2", "--gap-ms", "0.5"]
    assert (
        this_command(argv, "bench.spin") == ".venv/bin/python -m bench.spin --rounds 2 --gap-ms 0.5"
    )
    assert this_command(argv, "") == ".venv/bin/python bench/spin.py --rounds 2 --gap-ms 0.5"


@pytest.mark.parametrize(
    ("stored", "shown"),
    [
        (".venv/bin/python bench/spin.py --busy 2", ".venv/bin/python -m bench.spin --busy 2"),
        (".venv/bin/python -m bench.spin", ".venv/bin/python -m bench.spin"),
        (
            ".venv/bin/python bench/post_pose.py --intent-tree monopic/tree/ground_tree.json",
            ".venv/bin/python -m bench.post_pose --intent-tree monopic/tree/ground_tree.json",
        ),
    ],
)
def test_a_stored_script_path_is_shown_as_the_module_that_runs_today(stored: str, shown: str):
    assert runnable(stored) == shown


def test_every_command_benchmarks_md_shows_names_a_module_that_exists() -> None:
    commands = re.findall(r"^`(\.venv/bin/python [^`]*)`$", BENCHMARKS.read_text(), re.M)
    assert commands
    for command in commands:
        module = command.split()[2]
        assert command.split()[1] == "-m" and module.startswith("bench."), command
        assert (ROOT / (module.replace(".", "/") + ".py")).is_file(), command


def test_the_committed_benchmarks_md_is_rendered_from_the_committed_history() -> None:
    expected = render(read(HISTORY), HISTORY)
    assert BENCHMARKS.read_text(encoding="utf-8") == expected, (
        "BENCHMARKS.md is not rendered from bench/history.jsonl: run "
        ".venv/bin/python -m bench.render"
    )


def test_every_goal_finds_its_figure_in_the_committed_history() -> None:
    # Ties the goals to what the real scripts write (the tests above only write by hand).
    last = latest(read(HISTORY))
    for goal in GOALS:
        assert goal.benchmark in last, f"no {goal.benchmark} run in {HISTORY}"
        assert goal.read(last[goal.benchmark].results) is not None, goal.text


def test_a_goal_is_judged_on_the_latest_quiet_run_not_a_loaded_one() -> None:
    quiet_run = bench_run(
        "compare_reference", "2026-11-23T09:30:00Z", comparison((12.0, 20.0), (9.0, 12.0), []), ""
    )
    loaded = replace(
        bench_run(
            "compare_reference",
            "2026-11-23T10:30:00Z",
            comparison((17.6, 422.8), (9.0, 12.0), []),
            "",
        ),
        load_before=15.4,
        load_after=13.6,
    )
    goals = render([quiet_run, loaded], HISTORY).split("## Ours / reference by host")[0]
    assert "| 0.60 (12.00 vs 20.00 ms) | no |" in goals  # the quiet run judges
    assert "0.04" not in goals  # 17.6 / 422.8 under load is not a figure to judge by
    assert "a newer run, 2026-11-23 10:30 UTC, ran at load 15.4 before, 13.6 after" in goals
    only_loaded = render([loaded], HISTORY).split("## Ours / reference by host")[0]
    assert "| 0.04 (17.60 vs 422.80 ms) | not judged: load 15.4 before, 13.6 after" in only_loaded


def test_a_goal_names_a_runtime_or_landmark_model_that_is_not_the_default() -> None:
    from bench.goals import _runtime

    assert _runtime({}) == "" and _runtime({"runtime": "cpu", "model": "full"}) == ""
    assert _runtime({"runtime": "openvino"}) == " on openvino"
    assert _runtime({"model": "full-int8"}) == " with full-int8"
    assert _runtime({"detector": "float"}) == ""
    assert _runtime({"detector": "int8"}) == " with the int8 detector"
    both = {"model": "full-int8", "detector": "int8"}
    assert _runtime(both) == " with full-int8 and the int8 detector"
    assert _runtime({"spin": False}) == ""
    assert _runtime({"model": "full-int8", "spin": True}) == " with full-int8, spinning threads"
    window = {"model": "full-int8", "window_detector": "int8"}
    assert _runtime(window) == " with full-int8 and the int8 detector on zooms and tiles"
    assert _runtime({"window_detector": "int8"}) == " with the int8 detector on zooms and tiles"
    assert _runtime({"detector": "int8", "window_detector": "int8"}) == " with the int8 detector"
    assert _runtime({"search": "tiles"}) == ""
    assert _runtime({"search": "whole-frame"}) == ", whole-frame search"


def test_the_cpu_goal_is_judged_on_every_frame_with_the_same_work_beside() -> None:
    """The energy proxy counts every frame (our tile search too); the frames both sides
    found are shown beside, never instead."""
    from bench.goals import cpu_ratio_at

    results = comparison((6.0, 10.0), (5.0, 10.0), [])
    for row, same in zip(results["cpu"], (4.0, 10.0, 4.5, 10.0), strict=True):
        row["cpu_ms_per_both_found_frame"] = same
    one = cpu_ratio_at(1)(results)
    assert one is not None and not one.met
    assert one.measured.startswith("0.60 (6.0 vs 10.0 CPU-ms per frame; 0.40 on frames both found)")
    two = cpu_ratio_at(2)(results)
    assert two is not None and two.met and "; 0.45 on frames both found" in two.measured
    for row in results["cpu"]:
        row["cpu_ms_per_both_found_frame"] = None  # an older run, or no frame both found
    old = cpu_ratio_at(1)(results)
    assert old is not None and old.measured == "0.60 (6.0 vs 10.0 CPU-ms per frame)"
