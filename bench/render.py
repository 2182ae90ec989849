"""BENCHMARKS.md from the benchmark history: the goals, the latest run of each benchmark.

The file is rewritten whole from bench/history.jsonl, never appended to: first where each
goal stands (bench/goals.py, read from the latest runs), then the ratio against the
reference per host (a ratio holds for the CPU it was measured on), then the
latest result of each benchmark with its command, date, machine, CPU flags, load and code
digest, then an index of every run in the history. Nothing in it depends on when or
where it is rendered: the same history gives the same file, byte for byte.

    .venv/bin/python -m bench.render [--history bench/history.jsonl] [--out BENCHMARKS.md]
        [--check]
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from bench.goals import GOALS, cpu_ratio, landmark_error, ratio_at
from bench.history import BENCHMARKS, HISTORY, ROOT, BenchRun, Machine, read

NARRATIVE = "docs/benchmarks.md"
# Sections in this order; benchmarks not listed follow by name.
ORDER = (
    "compare_reference",
    "goal_runs",
    "landmark_profile",
    "model_choices",
    "int8_landmarks",
    "pipeline_latency",
    "people",
    "ncap_latency",
    "post_pose",
    "simulator",
    "simulator_people",
    "found_share",
    "ground_replay",
    "suite_time",
)


def shown(path: Path) -> str:
    """A path as the rendered file names it: relative to the repository when inside it."""
    try:
        return str(path.resolve().relative_to(ROOT))
    except ValueError:
        return path.name


def latest(runs: Sequence[BenchRun]) -> dict[str, BenchRun]:
    """The newest run of each benchmark: by date, a later line winning a tie."""
    best: dict[str, tuple[str, int, BenchRun]] = {}
    for k, run in enumerate(runs):
        key = (run.date, k)
        if run.benchmark not in best or key > best[run.benchmark][:2]:
            best[run.benchmark] = (run.date, k, run)
    return {name: entry[2] for name, entry in best.items()}


def ordered(names: Sequence[str]) -> list[str]:
    known = [n for n in ORDER if n in names]
    return known + sorted(n for n in names if n not in ORDER)


def host_key(m: Machine) -> tuple[str, int, tuple[str, ...]]:
    """Hosts are told apart by what decides the speed: CPU model, core count, flags."""
    return (m.cpu_model, m.cpu_cores, m.cpu_flags)


def when_iso(date: str) -> str:
    """'2026-11-22 12:31 UTC' from a stored ISO date."""
    return date.replace("T", " ").removesuffix("Z")[:16] + " UTC"


def when(run: BenchRun) -> str:
    return when_iso(run.date)


def load_text(run: BenchRun) -> str:
    def f(x: float | None) -> str:
        return "-" if x is None else f"{x:.1f}"

    return f"{f(run.load_before)} before, {f(run.load_after)} after"


def code_text(run: BenchRun) -> str:
    text = f"`{run.code}`"
    if run.commit:
        text += f" (commit `{run.commit[:12]}`{', with uncommitted changes' if run.dirty else ''})"
    return text


def quiet(run: BenchRun) -> bool:
    """A run fit to judge a goal by: the load average at most the cores it could use, before
    and after (unknown counts as quiet: the oldest lines did not record it). Figures taken
    at a load of 12 on 2 cores measure the scheduler, not the kernels."""
    cores = run.machine.cpu_allowed or run.machine.cpu_cores or 1
    return all(load is None or load <= cores for load in (run.load_before, run.load_after))


def goal_table(runs: Sequence[BenchRun]) -> list[str]:
    """Each goal judged on the latest quiet run of its benchmark; a newer loaded run is named
    but not judged, and with no quiet run at all the figure is shown, not judged."""
    lines = ["| goal | measured | met | run |", "| --- | --- | --- | --- |"]
    newest = latest(runs)
    newest_quiet = latest([r for r in runs if quiet(r)])
    for goal in GOALS:
        run = newest_quiet.get(goal.benchmark) or newest.get(goal.benchmark)
        if run is None:
            lines.append(f"| {goal.text} | not measured yet | - | no `{goal.benchmark}` run |")
            continue
        standing = goal.read(run.results)
        where = f"`{goal.benchmark}`, {when(run)}, {run.machine.label()}"
        loaded = newest[goal.benchmark]
        if loaded is not run:
            where += f" (a newer run, {when(loaded)}, ran at load {load_text(loaded)}: not judged)"
        if standing is None:
            lines.append(f"| {goal.text} | not in the latest run | - | {where} |")
            continue
        if quiet(run):
            met = "yes" if standing.met else "no"
        else:
            met = f"not judged: load {load_text(run)} on {run.machine.cpu_allowed} cores"
        lines.append(f"| {goal.text} | {standing.measured} | {met} | {where} |")
    return lines


def host_table(runs: Sequence[BenchRun]) -> list[str]:
    """The latest compare_reference run on each host, newest host first."""
    by_host: dict[tuple, list[BenchRun]] = {}
    for run in runs:
        if run.benchmark == "compare_reference":
            by_host.setdefault(host_key(run.machine), []).append(run)
    if not by_host:
        return ["No `compare_reference` run in the history yet."]
    lines = [
        "| host | vector units | runs | latest | load before / after | 1 thread | 2 threads "
        "| CPU-s per frame, 1 / 2 threads | landmark error |",
        "| --- | --- | ---: | --- | --- | --- | --- | --- | --- |",
    ]
    rows = []
    for host_runs in by_host.values():
        run = latest(host_runs)["compare_reference"]
        cells = []
        for reader in (ratio_at(1), ratio_at(2), landmark_error):
            s = reader(run.results)
            cells.append("-" if s is None else f"{s.measured}{'' if s.met else ' (misses)'}")
        cpu = [cpu_ratio(run.results, t) for t in (1, 2)]
        cells.insert(2, " / ".join("-" if c is None else f"{c:.2f}" for c in cpu))
        rows.append(
            (
                run.date,
                f"| {run.machine.label()} | {run.machine.vector_summary()} | {len(host_runs)} "
                f"| {when(run)} | {load_text(run)} | {' | '.join(cells)} |",
            )
        )
    return lines + [row for _, row in sorted(rows, reverse=True)]


def runnable(command: str) -> str:
    """A stored command as it runs today: lines written while the benchmarks ran as scripts
    (`python -m bench.x`) name the script's path; they run now as modules of the bench
    package (`python -m bench.x`). The history keeps what was typed."""
    return re.sub(r"^(\S*python) bench/(\w+)\.py\b", r"\1 -m bench.\2", command)


def section(run: BenchRun, count: int, first: BenchRun) -> list[str]:
    m = run.machine
    flags = " ".join(m.cpu_flags) or "none of the tracked vector flags"
    earlier = (
        f"{count} runs of this benchmark in the history, the first on {when(first)}"
        if count > 1
        else "the only run of this benchmark in the history"
    )
    return [
        f"### {run.title}",
        "",
        f"`{runnable(run.command)}`",
        "",
        f"- run: {when(run)}, {run.duration_s:.0f} s; load average {load_text(run)}",
        f"- machine: {m.label()} ({m.cpu_allowed} allowed){', virtual' if m.virtual else ''}; "
        f"{m.os}; Python {m.python}; host `{m.host}`",
        f"- CPU flags: `{flags}` ({m.vector_summary()})",
        f"- code: {code_text(run)}",
        f"- {earlier}",
        "",
        run.table,
    ]


def index_table(runs: Sequence[BenchRun]) -> list[str]:
    lines = [
        "| date | benchmark | host | vector units | code | load before / after |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for _, _, run in sorted(((r.date, k, r) for k, r in enumerate(runs)), reverse=True):
        lines.append(
            f"| {when(run)} | `{run.benchmark}` | {run.machine.label()} "
            f"| {run.machine.vector_summary()} | `{run.code}` | {load_text(run)} |"
        )
    return lines


def render(runs: Sequence[BenchRun], history: Path = HISTORY) -> str:
    """The whole of BENCHMARKS.md for these runs (in history file order)."""
    name = shown(history)
    head = [
        "# Benchmarks",
        "",
        "<!-- Rendered by bench/render.py from the history; do not edit by hand. -->",
        "",
        f"Rendered by `bench/render.py` from `{name}`, one JSON line per benchmark run "
        "(command, date, machine with its CPU flags, load, code digest, results). "
        "`make bench` runs the benchmarks, and every benchmark script appends its line and "
        "renders this file when it finishes. What each benchmark measures, the notes and "
        "experiments, and the figures measured before the history began (other hosts): "
        f"[{NARRATIVE}]({NARRATIVE}).",
        "",
    ]
    if not runs:
        return "\n".join([*head, f"No runs in `{name}` yet: run `make bench`.", ""])
    last = latest(runs)
    first_of: dict[str, BenchRun] = {}
    count: dict[str, int] = {}
    for run in sorted(runs, key=lambda r: r.date):
        first_of.setdefault(run.benchmark, run)
        count[run.benchmark] = count.get(run.benchmark, 0) + 1
    lines = [
        *head,
        "## Where the goals stand",
        "",
        "Each goal read from the latest run of the benchmark in its row whose load average "
        "stayed at most its core count (a run on a busier machine is named, not judged). A "
        "ratio holds for the host it was measured on (next table); this VM is shared, so "
        "read each figure with the load average it ran at.",
        "",
        *goal_table(runs),
        "",
        "## Ours / reference by host",
        "",
        "The latest `compare_reference` run on each host (CPU model, core count and flags): "
        "ours / reference in whole-frame p50 on frames both pipelines found, and in process "
        "CPU-seconds per frame.",
        "",
        *host_table(runs),
        "",
        "## Latest result of each benchmark",
        "",
    ]
    for bench in ordered(list(last)):
        lines += [*section(last[bench], count[bench], first_of[bench]), ""]
    dates = sorted(r.date for r in runs)
    lines += [
        "## Every run in the history",
        "",
        f"{len(runs)} runs in `{name}`, {when_iso(dates[0])} to {when_iso(dates[-1])}, "
        "newest first; each line there holds the run's full results and table.",
        "",
        *index_table(runs),
        "",
    ]
    return "\n".join(lines)


def render_file(history: Path = HISTORY, out: Path = BENCHMARKS) -> str:
    """Render `history` into `out` (whole or not at all); return the text."""
    from monopic.output import write_text_atomically

    text = render(read(history), history)
    write_text_atomically(out, text)
    return text


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--history", type=Path, default=HISTORY)
    ap.add_argument("--out", type=Path, default=BENCHMARKS)
    ap.add_argument("--check", action="store_true", help="fail if --out is not up to date")
    args = ap.parse_args()
    if args.check:
        text = render(read(args.history), args.history)
        if not args.out.exists() or args.out.read_text(encoding="utf-8") != text:
            sys.exit(
                f"{args.out} is not rendered from {args.history}: "
                "run .venv/bin/python -m bench.render"
            )
        return
    render_file(args.history, args.out)
    print(f"{args.out}: rendered from {args.history}")


if __name__ == "__main__":
    main()
