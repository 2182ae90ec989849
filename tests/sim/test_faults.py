"""Faults injected on purpose, each with the outcome it must have.

Stopping: a sweep stopped by SIGINT (sent to its process group, as a terminal's Ctrl-C
is) or SIGTERM, while its workers spawn, mid-run or during its last run, exits within
5 s with its one line and exit code (130, 143), and so do `monopic dataset` (its workers
gone too), `monopic closed-loop` and `monopic record`, leaving no temporary file (the
sweep's workers die mid-recording: the sweep deletes theirs); a worker that ignores its
SIGTERM is killed after the grace.
Dead workers and killed sweeps: a worker SIGKILLed mid-run has its run done again; a
run that kills its worker every time is reported failed and the sweep goes on; a sweep
SIGKILLed and resumed loses no finished run and gets the same results, and its
temporaries are removed by the next run, not those of a process that still runs; a run
that fails drops its partial recording.
Files: a torn last line resumes, a corrupt middle line is refused with its number; no
space left while appending, a read-only folder, results of a newer schema and a second
sweep on the same file each end in one clear line; an unreachable Ray address too,
within seconds.

Every sweep here is real (spawned workers rendering MuJoCo frames) but tiny: 6-frame
runs on a 256x144 camera.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import pickle
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from monopic.output import host_tag
from sim.runs.code_version import code_version
from sim.runs.executors import WORKER_ENV, local_executor, work
from sim.runs.result import RunResult
from sim.runs.results_file import ResultsWriter, read_results
from sim.runs.run_spec import RunSpec
from sim.runs.sweep import expand_spec, load_spec, run_sweep
from sim.world.render import KeptRenderContext
from tests.paths import ROOT
from tests.processes import dead_pid, live_pid

# A 6-frame crossing (case 5) on a 256x144 camera without buildings: about a second a run.
SCENARIO = """
name = "{name}"
kind = "collision"
scale = "small"
duration = {duration}
fps = 15
[robot]
speed = {speed}
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
{parameters}
"""
SPEC = """
name = "{name}"
ablation = false
licence = "CC-BY-4.0"
[[include]]
files = ["{name}.toml"]
"""
STOP_BOUND_S = 5.0  # every stop ends the process within this
PIPE_BUFFER = 64 * 1024  # Linux's pipe: the tasks queue that used to block held more


def sweep_spec(folder: Path, name: str, parameters: str, **base: Any) -> Path:
    """A sweep spec over the tiny scenario, `parameters` as its [sweep.parameters] lines."""
    values = {"duration": 0.4, "speed": 2.0, **base}
    (folder / f"{name}.toml").write_text(
        SCENARIO.format(name=name, parameters=parameters, **values)
    )
    path = folder / f"{name}-spec.toml"
    path.write_text(SPEC.format(name=name))
    return path


def speeds(n: int) -> str:
    """A grid of `n` robot speeds, each a run of its own."""
    return '"robot.speed" = [' + ", ".join(f"{3.0 * k / max(n - 1, 1):.4f}" for k in range(n)) + "]"


@pytest.fixture()
def many(tmp_path: Path) -> Path:
    """80 runs: more specs than a pipe holds; a stopped sweep never reaches the end."""
    return sweep_spec(tmp_path, "many", speeds(80))


@pytest.fixture()
def four(tmp_path: Path) -> Path:
    return sweep_spec(tmp_path, "four", speeds(4))


@pytest.fixture()
def long_last(tmp_path: Path) -> Path:
    """Three runs with a standing robot; the last (45 frames) is still running when the
    other two are done."""
    return sweep_spec(tmp_path, "longlast", '"duration" = [0.4, 0.5, 3.0]', speed=0.0)


# -- processes ---------------------------------------------------------------------------


def monopic_command() -> list[str]:
    """The `monopic` console script beside this Python (as a user runs it)."""
    script = Path(sys.executable).with_name("monopic")
    return [str(script)] if script.exists() else [sys.executable, "-m", "monopic"]


def alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has exited


def gone_within(pids: set[int], seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while any(alive(p) for p in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


@dataclass
class Command:
    """A `monopic` command in its own session (process group), its stderr in a file."""

    proc: subprocess.Popen
    stderr: Path

    @classmethod
    def start(
        cls, args: list[str], folder: Path, name: str = "cmd", prefix: list[str] | None = None
    ) -> Command:
        err = folder / f"{name}.stderr"
        with err.open("wb") as fh:
            proc = subprocess.Popen(
                [*(prefix or monopic_command()), *args],
                stdout=subprocess.DEVNULL,
                stderr=fh,
                cwd=ROOT,
                start_new_session=True,
            )
        return cls(proc, err)

    def workers(self) -> set[int]:
        """The sweep's worker processes (multiprocessing's spawned children)."""
        pid = self.proc.pid
        try:
            children = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
        except FileNotFoundError:
            return set()
        found = set()
        for child in map(int, children):
            with contextlib.suppress(FileNotFoundError):
                if b"spawn_main" in Path(f"/proc/{child}/cmdline").read_bytes():
                    found.add(child)
        return found

    def wait_for(self, ready: Callable[[], bool], what: str, timeout: float = 240) -> None:
        deadline = time.monotonic() + timeout
        while not ready():
            assert self.proc.poll() is None, f"it ended (code {self.proc.returncode}) before {what}"
            assert time.monotonic() < deadline, f"no {what} within {timeout} s"
            time.sleep(0.05)

    def stop(self, sig: int) -> float:
        """Send `sig` as a user would (SIGINT to the group, as Ctrl-C; SIGTERM to the
        process, as kill); the seconds until it exited (at most STOP_BOUND_S + 25)."""
        sent = time.monotonic()
        if sig == signal.SIGINT:
            os.killpg(self.proc.pid, sig)
        else:
            self.proc.send_signal(sig)
        try:
            self.proc.wait(timeout=STOP_BOUND_S + 25)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"still running {STOP_BOUND_S + 25:.0f} s after {signal.Signals(sig).name}")
        return time.monotonic() - sent

    def kill(self) -> None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait()

    def finish(self, timeout: float = 300) -> int:
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"did not finish within {timeout} s")

    def last_line(self) -> str:
        """What the user sees last (progress bars redraw with carriage returns)."""
        text = self.stderr.read_text(errors="replace")
        lines = [ln.strip() for ln in text.replace("\r", "\n").splitlines() if ln.strip()]
        return lines[-1] if lines else ""

    def text(self) -> str:
        return self.stderr.read_text(errors="replace")


@pytest.fixture()
def commands() -> Iterator[list[Command]]:
    """Every command a test starts is gone when it ends, whatever happened."""
    started: list[Command] = []
    yield started
    for command in started:
        if command.proc.poll() is None:
            command.kill()


def lines(path: Path) -> int:
    return path.read_bytes().count(b"\n") if path.exists() else 0


def whole_lines(path: Path) -> list[dict]:
    """The file's lines, each parsed; the file ends with a complete line (or is empty)."""
    data = path.read_bytes() if path.exists() else b""
    assert not data or data.endswith(b"\n"), "a torn last line"
    return [json.loads(raw) for raw in data.splitlines()]


def by_id(path: Path) -> dict[str, dict]:
    rows = list(read_results(path))
    assert len({r.id for r in rows}) == len(rows), "a run twice"
    return {r.id: r.deterministic() for r in rows}


def temporaries(folder: Path) -> list[Path]:
    """Every temporary file under `folder` (monopic.output names them NAME.PID@HOST.tmp...)."""
    return sorted(p for p in folder.rglob("*") if ".tmp" in p.name)


SWEEP_FLAGS = ["--workers", "2"]
SIGNALS = [
    pytest.param(signal.SIGINT, 130, "interrupted", id="SIGINT"),
    pytest.param(signal.SIGTERM, 143, "terminated", id="SIGTERM"),
]


# -- stopping ------------------------------------------------------------------------------


@pytest.mark.slow
def test_the_issue_reproduction_sigterm_mid_sweep_exits_within_5_s(
    many: Path, tmp_path: Path, commands: list[Command]
) -> None:
    # `monopic sweep SPEC --out x.jsonl & sleep 20; kill -TERM $!` used to print its line
    # and then hang for good: the tasks not yet taken filled the pipe of a queue whose
    # feeder thread the exiting process joined.
    specs = expand_spec(load_spec(many))
    assert sum(len(pickle.dumps(s)) for s in specs) > PIPE_BUFFER
    out = tmp_path / "x.jsonl"
    sweep = Command.start(["sweep", str(many), "--out", str(out), *SWEEP_FLAGS], tmp_path)
    commands.append(sweep)
    sweep.wait_for(lambda: lines(out) >= 1, "first result")  # the workers are mid-run
    workers = sweep.workers()
    assert len(workers) == 2
    seconds = sweep.stop(signal.SIGTERM)
    assert seconds < STOP_BOUND_S, f"exited {seconds:.1f} s after SIGTERM"
    assert sweep.proc.returncode == 143
    assert sweep.last_line() == "monopic sweep: terminated"
    assert "Traceback" not in sweep.text()
    assert gone_within(workers, STOP_BOUND_S)
    assert 1 <= len(whole_lines(out)) < len(specs)


def _stop_once(
    spec: Path, folder: Path, commands: list[Command], sig: int, ready: Callable[[Path], bool],
    name: str,
) -> tuple[Command, float, set[int], int, Path]:  # fmt: skip
    out = folder / f"{name}.jsonl"
    sweep = Command.start(["sweep", str(spec), "--out", str(out), *SWEEP_FLAGS], folder, name)
    commands.append(sweep)
    holder: dict[str, set[int]] = {}

    def reached() -> bool:
        holder["workers"] = sweep.workers()
        return ready(out) and bool(holder["workers"])

    sweep.wait_for(reached, f"the moment to stop ({name})")
    at_signal = lines(out)
    seconds = sweep.stop(sig)
    return sweep, seconds, holder["workers"], at_signal, out


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code", "word"), SIGNALS)
def test_every_stop_ends_the_sweep_within_seconds_with_its_line(
    sig: int, code: int, word: str, many: Path, long_last: Path, tmp_path: Path,
    commands: list[Command],
) -> None:  # fmt: skip
    # Start-up (workers spawning, no result yet) is where the races were: three times.
    # Mid-run twice, the last run once. The default --record (failed) starts a
    # recording every run, with pygame's SDL up in the worker for part of it.
    phases = [
        ("start-up", many, lambda out: lines(out) == 0, 3),
        ("mid-run", many, lambda out: lines(out) >= 1, 2),
        ("last-run", long_last, lambda out: lines(out) >= 2, 1),
    ]
    for phase, spec, ready, repeats in phases:
        for k in range(repeats):
            name = f"{phase}-{k}"
            sweep, seconds, workers, at_signal, out = _stop_once(
                spec, tmp_path, commands, sig, ready, name
            )
            where = f"{signal.Signals(sig).name} at {phase} (try {k + 1})"
            if phase == "start-up":
                assert at_signal == 0, where
            if phase == "last-run":
                assert at_signal == 2 and lines(out) == 2, f"{where}: the last run was done"
            assert seconds < STOP_BOUND_S, f"{where}: exited after {seconds:.1f} s"
            assert sweep.proc.returncode == code, f"{where}: {sweep.text()[-500:]}"
            assert sweep.last_line() == f"monopic sweep: {word}", where
            assert "Traceback" not in sweep.text(), where
            assert gone_within(workers, STOP_BOUND_S), f"{where}: a worker lives on"
            whole_lines(out)
            assert not temporaries(tmp_path), f"{where}: {temporaries(tmp_path)}"


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code", "word"), SIGNALS)
def test_a_sweep_stopped_mid_run_leaves_no_temporary_file(
    sig: int, code: int, word: str, many: Path, tmp_path: Path, commands: list[Command]
) -> None:
    # Its workers die of their SIGTERM (or SIGKILL) in the middle of a recording, without
    # deleting its temporary: the sweep deletes what they leave.
    out = tmp_path / "x.jsonl"
    args = ["sweep", str(many), "--out", str(out), "--record", "all", *SWEEP_FLAGS]
    sweep = Command.start(args, tmp_path)
    commands.append(sweep)
    folder = tmp_path / "x_rrd"
    sweep.wait_for(lambda: lines(out) >= 1 and bool(temporaries(folder)), "a run recording")
    workers = sweep.workers()
    sweep.stop(sig)
    assert sweep.proc.returncode == code and sweep.last_line() == f"monopic sweep: {word}"
    assert gone_within(workers, STOP_BOUND_S)
    assert temporaries(tmp_path) == []
    assert len(list(folder.rglob("*.rrd"))) >= 1  # the finished runs' recordings stay


@pytest.mark.slow
def test_the_temporaries_of_a_killed_sweep_are_removed_by_the_next_run(
    tmp_path: Path, commands: list[Command], capsys: pytest.CaptureFixture[str]
) -> None:
    # SIGKILL gives nobody a chance to clean: the next sweep on the same results does.
    spec_path = sweep_spec(tmp_path, "two", '"duration" = [0.4, 4.0]', speed=0.0)
    out = tmp_path / "killed.jsonl"
    args = ["sweep", str(spec_path), "--out", str(out), "--record", "all", *SWEEP_FLAGS]
    sweep = Command.start(args, tmp_path, "killed")
    commands.append(sweep)
    folder = tmp_path / "killed_rrd"
    sweep.wait_for(lambda: lines(out) >= 1 and bool(temporaries(folder)), "the second recording")
    sweep.kill()  # the sweep and its workers (one process group)
    assert temporaries(folder), "no temporary was left: nothing was tested"
    assert main(args) == 0
    assert temporaries(tmp_path) == []
    assert capsys.readouterr().out.splitlines()[-1] == f"recordings (every run): 2 in {folder}"


def test_stale_temporaries_go_live_ones_stay_and_only_recordings_are_counted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A killed sweep's temporaries (of runs it will not redo, as after --limit) go
    # when the next sweep on the same results starts; one whose process runs (another
    # sweep sharing --recordings) stays, and neither is a recording.
    spec_path = sweep_spec(tmp_path, "one", speeds(1))
    out, folder = tmp_path / "one.jsonl", tmp_path / "one_rrd"
    (folder / "one").mkdir(parents=True)
    dead = dead_pid()
    stale = [
        folder / "one" / f".0009-dead.{dead}@{host_tag()}.tmp.rrd",
        folder / f".0008-old.{dead}.tmp.rrd",  # named by older code, without the host
    ]
    args = ["sweep", str(spec_path), "--out", str(out), "--record", "all", "--workers", "1"]
    with live_pid() as running:
        live = folder / "one" / f".0007-live.{running}@{host_tag()}.tmp.rrd"
        for path in (*stale, live):
            path.write_bytes(b"partial")
        assert main(args) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"recordings (every run): 1 in {folder}"
    assert not any(p.exists() for p in stale) and live.exists()


def test_a_run_that_fails_mid_run_drops_its_partial_recording(tmp_path: Path) -> None:
    # A worker reports a failed run and goes on: the recording it had started must go.
    from sim.runs.runner import run

    (spec,) = expand_spec(load_spec(sweep_spec(tmp_path, "fails", speeds(1))))
    folder = tmp_path / "rrd"
    spec = replace(spec, record="all", record_dir=str(folder))

    def fail(frame: int) -> None:
        if frame == 2:
            assert temporaries(folder), "the recording has not started: nothing is tested"
            raise RuntimeError("the run broke")

    with pytest.raises(RuntimeError, match="the run broke"):
        run(spec, on_frame=fail)
    assert [p for p in folder.rglob("*") if p.is_file()] == []


def stubborn_work(spec: RunSpec, kept: KeptRenderContext | None) -> dict[str, Any]:
    """A worker's run that ignores SIGTERM from its first run on (as SDL made them do)."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    return work(spec, kept)


STUBBORN_MAIN = """
import functools, sys
import sim.runs.executors as executors
from tests.sim.test_faults import stubborn_work
executors.local_executor = functools.partial(
    executors.local_executor, run=stubborn_work, grace={grace}
)
from monopic.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.slow
def test_a_worker_that_ignores_its_stop_is_killed_after_the_grace(
    many: Path, tmp_path: Path, commands: list[Command]
) -> None:
    grace = 1.0
    out = tmp_path / "stubborn.jsonl"
    sweep = Command.start(
        ["sweep", str(many), "--out", str(out), *SWEEP_FLAGS],
        tmp_path,
        prefix=[sys.executable, "-c", STUBBORN_MAIN.format(grace=grace)],
    )
    commands.append(sweep)
    sweep.wait_for(lambda: lines(out) >= 1, "first result")
    workers = sweep.workers()
    assert len(workers) == 2
    seconds = sweep.stop(signal.SIGTERM)
    assert seconds >= grace * 0.9, "the workers did not ignore SIGTERM: nothing was tested"
    assert seconds < grace + STOP_BOUND_S
    assert sweep.proc.returncode == 143 and sweep.last_line() == "monopic sweep: terminated"
    assert gone_within(workers, 1.0)


SIGTERM_CAUGHT = """
import pygame, signal
signal.signal(signal.SIGINT, signal.SIG_IGN)  # as in a worker
pygame.init()
status = open("/proc/self/status").read().split("SigCgt:")[1].split()[0]
print(bool(int(status, 16) & (1 << (signal.SIGTERM - 1))))
"""


@pytest.mark.parametrize(("env", "caught"), [({}, "True"), (WORKER_ENV, "False")])
def test_sdl_catches_sigterm_unless_the_worker_environment_says_not_to(
    env: dict[str, str], caught: str
) -> None:
    # The cause of the Ctrl-C hangs: highway-env's pygame starts SDL in the worker, and
    # SDL installs a SIGTERM handler that only queues a quit event.
    clean = {k: v for k, v in os.environ.items() if k != "SDL_NO_SIGNAL_HANDLERS"}
    result = subprocess.run(
        [sys.executable, "-c", SIGTERM_CAUGHT],
        env={
            **clean,
            "SDL_VIDEODRIVER": "dummy",
            "SDL_AUDIODRIVER": "dummy",
            # pygame prints its banner unless told not to (highway-env's import tells it,
            # so the test passed only after a test that imported highway-env).
            "PYGAME_HIDE_SUPPORT_PROMPT": "1",
            **env,
        },
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.stdout.strip() == caught, result.stderr[-500:]


def test_a_stop_inside_an_except_exception_block_is_not_swallowed() -> None:
    # The renderer wraps any Exception from making a GL context as "cannot create an
    # offscreen OpenGL context": a SIGTERM landing there ended the closed loop with exit 1.
    from monopic.cli.main import Terminated, _terminate

    with pytest.raises(Terminated):
        try:
            _terminate(signal.SIGTERM, None)
        except Exception:  # noqa: BLE001 - what the wrappers do
            pytest.fail("the stop was caught as an error")


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code", "word"), SIGNALS)
def test_dataset_and_closed_loop_stop_within_seconds_with_their_line(
    sig: int, code: int, word: str, four: Path, tmp_path: Path, commands: list[Command]
) -> None:
    folder = tmp_path / "ds"
    dataset = Command.start(
        ["dataset", str(four), "--out", str(folder), *SWEEP_FLAGS], tmp_path, "dataset"
    )
    commands.append(dataset)
    workers: set[int] = set()

    def a_finished_run() -> bool:
        workers.update(dataset.workers())
        return any((folder / "runs").rglob("*.json"))

    dataset.wait_for(a_finished_run, "a finished run")
    assert len(workers) == 2  # the runs render on two spawned workers
    seconds = dataset.stop(sig)
    assert seconds < STOP_BOUND_S and dataset.proc.returncode == code
    assert dataset.last_line() == f"monopic dataset: {word}"
    assert "Traceback" not in dataset.text()
    assert gone_within(workers, STOP_BOUND_S), "a dataset worker lives on"
    assert temporaries(folder) == []

    scenario = sweep_spec(tmp_path, "loop", speeds(1), duration=3.0).with_name("loop.toml")
    rrd, results = tmp_path / "loop_rrd", tmp_path / "loop.jsonl"
    rrd.mkdir()
    loop = Command.start(
        ["closed-loop", str(scenario), "--robot-speeds", "1,2", "--policies", "none,truth",
         "--rrd-dir", str(rrd), "--results", str(results), *SWEEP_FLAGS],
        tmp_path,
        "loop",
    )  # fmt: skip
    commands.append(loop)
    loop_workers: set[int] = set()

    def a_finished_loop_run() -> bool:
        loop_workers.update(loop.workers())
        return "| 1/4 [" in loop.text()

    loop.wait_for(a_finished_loop_run, "a finished run")
    assert len(loop_workers) == 2  # the closed loop's runs render on two spawned workers
    seconds = loop.stop(sig)
    assert seconds < STOP_BOUND_S and loop.proc.returncode == code
    assert loop.last_line() == f"monopic closed-loop: {word}"
    assert "Traceback" not in loop.text()
    assert gone_within(loop_workers, STOP_BOUND_S), "a closed-loop worker lives on"
    assert temporaries(rrd) == []
    assert lines(results) >= 1  # the finished run is kept

    out = tmp_path / "record" / "loop.rrd"
    out.parent.mkdir()
    # All 45 frames (not the 19 to contact), so the stop lands mid-run on a loaded machine
    # too: one that lands after the work is done finds nothing left to stop.
    record = Command.start(
        ["record", str(scenario), "--out", str(out), "--after-contact"], tmp_path, "record"
    )
    commands.append(record)
    record.wait_for(lambda: bool(temporaries(out.parent)), "the recording started")
    seconds = record.stop(sig)
    assert seconds < STOP_BOUND_S and record.proc.returncode == code
    assert record.last_line() == f"monopic record: {word}"
    assert list(out.parent.iterdir()) == []  # neither the file nor its temporary


# -- dead workers, killed sweeps -------------------------------------------------------------


@pytest.mark.slow
def test_workers_killed_mid_run_have_their_runs_done_again(
    tmp_path: Path, commands: list[Command]
) -> None:
    three = sweep_spec(tmp_path, "three", speeds(3))
    out = tmp_path / "k.jsonl"
    sweep = Command.start(
        ["sweep", str(three), "--out", str(out), "--record", "none", *SWEEP_FLAGS], tmp_path
    )
    commands.append(sweep)
    sweep.wait_for(lambda: lines(out) >= 1, "first result")
    workers = sweep.workers()
    for pid in workers:  # both are mid-run: one on its second run, one on its first
        os.kill(pid, signal.SIGKILL)
    assert sweep.finish() == 0, sweep.text()[-800:]
    assert "Traceback" not in sweep.text()
    assert sorted(by_id(out)) == sorted(s.id for s in expand_spec(load_spec(three)))


def dies_mid_run(spec: RunSpec, kept: KeptRenderContext | None) -> dict[str, Any]:
    """The run at robot speed 1 kills its worker (SIGKILL at frame 2), every time."""
    from sim.runs.runner import run

    if spec.params["robot.speed"] == 1.0:
        camera = spec.scenario.robot.camera
        context = kept.fitting(camera.width, camera.height) if kept is not None else None

        def die(frame: int) -> None:
            if frame == 2:
                os.kill(os.getpid(), signal.SIGKILL)

        run(spec, on_frame=die, render_context=context)
    return work(spec, kept)


@pytest.mark.slow
def test_a_run_that_kills_its_worker_every_time_is_failed_and_the_sweep_goes_on(
    tmp_path: Path,
) -> None:
    spec = load_spec(sweep_spec(tmp_path, "deaths", '"robot.speed" = [0.0, 1.0, 2.0]'))
    ids = {s.params["robot.speed"]: s.id for s in expand_spec(spec)}
    out = tmp_path / "deaths.jsonl"
    start = time.monotonic()
    outcome = run_sweep(spec, out, local_executor(2, run=dies_mid_run), progress=False)
    assert time.monotonic() - start < 240
    assert outcome.finished == 2 and sorted(by_id(out)) == sorted([ids[0.0], ids[2.0]])
    ((failed_id, error),) = outcome.failed
    assert failed_id == ids[1.0]
    assert error == "its worker process died during the run 2 times (last: killed by SIGKILL)"


@pytest.mark.slow
def test_a_sweep_killed_with_sigkill_resumes_without_loss_to_the_same_results(
    tmp_path: Path, commands: list[Command]
) -> None:
    # Two runs of a standing robot: the second (60 frames) is mid-run when the first ends.
    # (At 23 frames it once finished first on a loaded CI host: the two workers start
    # a second or two apart, so the margin must be longer than that.)
    spec_path = sweep_spec(tmp_path, "two", '"duration" = [0.4, 4.0]', speed=0.0)
    out = tmp_path / "killed.jsonl"
    args = ["sweep", str(spec_path), "--out", str(out), "--record", "none", *SWEEP_FLAGS]
    sweep = Command.start(args, tmp_path, "killed")
    commands.append(sweep)
    sweep.wait_for(lambda: lines(out) >= 1, "first result")
    os.kill(sweep.proc.pid, signal.SIGKILL)
    sweep.proc.wait(timeout=10)
    before = out.read_bytes()
    assert before.endswith(b"\n") and lines(out) == 1, "the second run was not cut short"
    resumed = Command.start(args, tmp_path, "resumed")
    commands.append(resumed)
    assert resumed.finish() == 0, resumed.text()[-800:]
    assert out.read_bytes().startswith(before)  # no finished run lost or changed
    rows = by_id(out)
    (done,) = [spec for spec in expand_spec(load_spec(spec_path)) if spec.id not in before.decode()]
    fresh = work(replace(done, record="none", code=code_version()))
    assert rows[done.id] == RunResult.from_json(fresh, "fresh").deterministic()  # as run alone
    assert len(rows) == 2


@pytest.mark.slow
def test_a_second_sweep_on_the_same_results_file_is_one_line(
    many: Path, tmp_path: Path, commands: list[Command]
) -> None:
    out = tmp_path / "shared.jsonl"
    args = ["sweep", str(many), "--out", str(out), "--record", "none", *SWEEP_FLAGS]
    first = Command.start(args, tmp_path, "first")
    commands.append(first)
    first.wait_for(lambda: lines(out) >= 1, "first result")
    second = Command.start(args, tmp_path, "second")
    commands.append(second)
    assert second.finish(timeout=60) == 2
    assert first.proc.poll() is None, "the first sweep ended: nothing was shared"
    assert second.text().strip() == (
        f"monopic sweep: error: {out}: another sweep is writing to it; wait for it or use "
        "another --out"
    )
    first.stop(signal.SIGTERM)
    rows = whole_lines(out)
    assert len({r["id"] for r in rows}) == len(rows) >= 1


# -- the results file ------------------------------------------------------------------------


def resumable_lines(ids: list[str], **fields: Any) -> bytes:
    """Result lines as far as resuming reads them (id, code, schema) for `ids`."""
    row = {"code": code_version(), "schema": 1, **fields}
    return b"".join(json.dumps({"id": i, **row}).encode() + b"\n" for i in ids)


def test_a_torn_last_line_resumes_and_a_corrupt_middle_line_is_refused_with_its_number(
    four: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = load_spec(four)
    ids = [s.id for s in expand_spec(spec)]
    out = tmp_path / "r.jsonl"
    good = resumable_lines(ids[:2])
    out.write_bytes(good + resumable_lines(ids[2:3])[:25])  # killed mid-write
    outcome = run_sweep(spec, out, local_executor(1), progress=False, limit=0)
    assert (outcome.skipped, outcome.finished) == (2, 0)
    assert out.read_bytes() == good  # cut back to the last whole line
    out.write_bytes(good[:-1] + b',"tr\n' + resumable_lines(ids[2:3]))  # line 2 is corrupt
    assert main(["sweep", str(four), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"monopic sweep: error: {out}:2: not a result line (")
    assert err.endswith("remove it or use another --out") and "\n" not in err


def test_results_of_a_newer_schema_are_refused_saying_how_to_redo_them(
    four: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = load_spec(four)
    ids = [s.id for s in expand_spec(spec)]
    out = tmp_path / "newer.jsonl"
    out.write_bytes(resumable_lines(ids[:1]) + resumable_lines(ids[1:2], schema=2))
    args = ["sweep", str(four), "--out", str(out), "--limit", "1", "--workers", "1"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"monopic sweep: error: {out}:2: a result of schema 2, newer than this code's 1 "
        "(written by newer code, which alone reads it); to redo its runs with this code, use "
        "another --out, or --restart to set the file aside and start over"
    )
    assert lines(out) == 2  # untouched
    outcome = run_sweep(spec, out, local_executor(1), progress=False, limit=0, restart=True)
    assert outcome.skipped == 0 and lines(out) == 0
    assert lines(tmp_path / "newer.schema2.jsonl") == 2


@contextlib.contextmanager
def mounted_tmpfs(folder: Path, options: str) -> Iterator[None]:
    """A small tmpfs at `folder` (root only; skips where mounting is not allowed)."""
    folder.mkdir(exist_ok=True)
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    mount = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True
    )
    if mount.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mount.stderr.decode().strip()}")
    try:
        yield
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)


@contextlib.contextmanager
def read_only(folder: Path) -> Iterator[None]:
    """`folder` read-only: permissions for a user, a read-only tmpfs for root."""
    if os.geteuid() != 0:
        folder.mkdir()
        folder.chmod(0o555)
        try:
            yield
        finally:
            folder.chmod(0o755)
    else:
        with mounted_tmpfs(folder, "ro,size=64k"):
            yield


def test_a_read_only_output_folder_is_one_line(
    four: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "ro"
    with read_only(folder):
        out = folder / "r.jsonl"
        assert main(["sweep", str(four), "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith(f"monopic sweep: error: {out}: cannot write there (")
        assert err.endswith("); use another --out") and "\n" not in err
        assert not out.exists()


def test_no_space_left_while_appending_keeps_every_written_line_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "r.jsonl"
    with ResultsWriter(path) as writer:
        writer.append({"id": "a", "n": 1})
        writer.append({"id": "b", "n": 2})
        kept = path.read_bytes()
        real_write = os.write

        def disk_full(fd: int, data: bytes) -> int:
            """Half the line fits, then the disk is full."""
            if fd != writer._fd:
                return real_write(fd, data)
            if len(data) > 8:
                return real_write(fd, bytes(data[: len(data) // 2]))
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        monkeypatch.setattr(os, "write", disk_full)
        with pytest.raises(UserError) as info:
            writer.append({"id": "c", "n": 3, "pad": "x" * 100})
        monkeypatch.undo()
        assert str(info.value) == (
            f"{path}: cannot append run c (No space left on device); the 2 runs before it "
            "are intact: free some space and run the sweep again to resume"
        )
        assert path.read_bytes() == kept  # the half line is gone
    with ResultsWriter(path) as writer:  # space is back
        assert writer.state.ids == {"a", "b"} and not writer.state.torn
        writer.append({"id": "c", "n": 3})
    assert [r["id"] for r in whole_lines(path)] == ["a", "b", "c"]


@pytest.mark.slow
def test_a_full_disk_while_a_sweep_appends_is_one_line_and_resumes(
    tmp_path: Path, commands: list[Command]
) -> None:
    three = sweep_spec(tmp_path, "three", speeds(3))
    disk = tmp_path / "disk"
    with mounted_tmpfs(disk, "size=8k"):  # two pages: room for two or so result lines
        out = disk / "r.jsonl"
        args = ["sweep", str(three), "--out", str(out), "--record", "none", *SWEEP_FLAGS]
        sweep = Command.start(args, tmp_path, "full")
        commands.append(sweep)
        assert sweep.finish() == 2
        written = whole_lines(out)
        assert 1 <= len(written) < 3
        line = sweep.last_line()
        assert line.startswith(f"monopic sweep: error: {out}: cannot append run ")
        assert line.endswith(
            f"(No space left on device); the {len(written)} runs before it are intact: "
            "free some space and run the sweep again to resume"
        )
        assert "Traceback" not in sweep.text()
        before = out.read_bytes()
        subprocess.run(["mount", "-o", "remount,size=1m", str(disk)], check=True)
        resumed = Command.start(args, tmp_path, "resumed")
        commands.append(resumed)
        assert resumed.finish() == 0, resumed.text()[-800:]
        assert out.read_bytes().startswith(before)
        assert len(by_id(out)) == 3


# -- Ray -----------------------------------------------------------------------------------


@pytest.mark.slow
def test_an_unreachable_ray_address_fails_within_seconds_in_one_line(
    four: Path, tmp_path: Path, commands: list[Command]
) -> None:
    pytest.importorskip("ray", reason="Ray is not installed (the optional [ray] extra)")
    out = tmp_path / "ray.jsonl"
    args = ["sweep", str(four), "--out", str(out), "--executor", "ray", "--address", "127.0.0.1:1"]
    sweep = Command.start(args, tmp_path, "ray")
    commands.append(sweep)
    assert sweep.finish(timeout=60) == 2  # it used to retry for over ten minutes
    assert sweep.last_line() == (
        "monopic sweep: error: --address 127.0.0.1:1: no Ray cluster answers there "
        "(connection refused); give the head node's address as `ray start --head` printed it"
    )
    assert "Traceback" not in sweep.text()


@contextlib.contextmanager
def not_ray() -> Iterator[tuple[int, list[socket.socket]]]:
    """A TCP port that accepts connections and never says anything (no Ray there)."""
    server = socket.create_server(("", 0))
    accepted: list[socket.socket] = []

    def accept() -> None:
        with contextlib.suppress(OSError):
            while True:
                accepted.append(server.accept()[0])

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    try:
        yield server.getsockname()[1], accepted
    finally:
        server.close()
        for conn in accepted:
            conn.close()


@pytest.mark.slow
def test_sigterm_while_joining_a_cluster_that_does_not_answer_is_143_and_its_line(
    four: Path, tmp_path: Path, commands: list[Command]
) -> None:
    pytest.importorskip("ray", reason="Ray is not installed (the optional [ray] extra)")
    with not_ray() as (port, accepted):
        address = f"127.0.0.1:{port}"
        args = ["sweep", str(four), "--out", str(tmp_path / "r.jsonl"), "--executor", "ray"]
        sweep = Command.start([*args, "--address", address], tmp_path, "join")
        commands.append(sweep)
        # The probe's connection, then Ray's own: ray.init is waiting for an answer.
        sweep.wait_for(lambda: len(accepted) >= 2, "Ray connecting", timeout=120)
        seconds = sweep.stop(signal.SIGTERM)
    # ray.init's C++ waits are deaf to signals for up to 3 x 3 s (RAY_CONNECT_ENV).
    assert seconds < 10 + STOP_BOUND_S, f"exited {seconds:.1f} s after SIGTERM"
    assert sweep.proc.returncode == 143  # not Ray's sys.exit(15)
    assert sweep.last_line() == "monopic sweep: terminated"


def test_the_worker_environment_gives_opencv_one_thread() -> None:
    # Two workers on two cores each ran OpenCV's warps on two threads otherwise.
    clean = {k: v for k, v in os.environ.items() if k != "OPENCV_FOR_THREADS_NUM"}
    code = "import cv2; print(cv2.getNumThreads())"
    result = subprocess.run(
        [sys.executable, "-c", code], env={**clean, **WORKER_ENV}, capture_output=True, text=True
    )
    assert result.stdout.strip() == "1", result.stderr[-500:]
