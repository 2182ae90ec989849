"""Where runs execute: spawned local worker processes, or a Ray cluster.

Both call the same `work(spec)` and hand each finished result to the sweep as it
arrives; results depend only on the RunSpec (its seed included), never on the executor.
Workers render with their own EGL context (created in the worker: contexts do not
survive fork, hence spawn) and run onnxruntime with one thread, so N workers use N cores.
A local worker keeps its GL context from run to run (sim.world.render.KeptRenderContext: a
fresh one costs about 0.2 s of shader compilation per run on llvmpipe).

Stopping is bounded: a stopped sweep (Ctrl-C, SIGTERM, an error) sends its workers
SIGTERM, gives them STOP_GRACE_S to exit and then SIGKILLs the rest; a worker that dies
mid-run (killed, out of memory) has its run given once more to a fresh worker and, if
that dies too, reported as failed while the sweep goes on. A worker stopped so deletes
nothing: the temporary file it was writing is the caller's to clear once `execute`
returns, its workers gone (monopic.output.stale_temporaries_cleared, as sim.runs.sweep
does for its recordings).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import socket
import threading
import time
import traceback
from collections import Counter, deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from multiprocessing import resource_tracker
from multiprocessing.connection import Connection
from multiprocessing.connection import wait as wait_for_any
from multiprocessing.context import SpawnContext
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import Any

from monopic.errors import UserError
from sim.runs.run_spec import RunSpec
from sim.world.render import KeptRenderContext

# What every worker's environment needs before it imports MuJoCo or numpy.
WORKER_ENV = {
    "MUJOCO_GL": "egl",
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "LP_NUM_THREADS": "1",  # Mesa's software rasteriser: one thread per worker
    # OpenCV's own pool (the crops' warps) ignores OMP_NUM_THREADS: without this each of
    # two workers on two cores ran its warps on two threads, 1.4x the CPU time of one.
    "OPENCV_FOR_THREADS_NUM": "1",
    # pygame (highway-env) initialises SDL, which catches SIGTERM while it is up and only
    # queues a quit event: a worker stopped then would run on. Keep SIGTERM fatal.
    "SDL_NO_SIGNAL_HANDLERS": "1",
}
RAY_PIN = "2.60.0"
STOP_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})
# A stopped worker dies at once (SIGTERM is fatal to it); one still alive after this long
# is blocked in start-up or caught SIGTERM, and gets SIGKILL.
STOP_GRACE_S = 2.0
EXIT_WAIT_S = 10.0  # for a worker that got its stop sign to free its GL context and exit
RERUNS = 1  # times a run whose worker died is given to a fresh worker before it counts as failed

RunFunction = Callable[[RunSpec, KeptRenderContext | None], dict[str, Any]]


def work(spec: RunSpec, kept: KeptRenderContext | None = None) -> dict[str, Any]:
    """One run in a worker; a failure comes back as {"id", "error"} instead of ending the sweep.

    `kept`: the worker's GL context, lent to the run.
    """
    from sim.runs.runner import run

    try:
        camera = spec.scenario.robot.camera
        context = kept.fitting(camera.width, camera.height) if kept is not None else None
        return run(spec, render_context=context).to_json()
    except Exception:  # noqa: BLE001 - reported per run; the sweep goes on
        return {"id": spec.id, "error": traceback.format_exc()}


def _worker(conn: Connection, run: RunFunction) -> None:
    """A local worker process: runs each spec the parent sends, until None or the parent is gone.

    It starts with SIGINT blocked (the parent blocks it while it spawns): Ctrl-C is the
    parent's (a terminal sends it to the whole process group), so a pending one is dropped
    here. SIGTERM (the parent's stop) is fatal at any time.
    If the parent dies without stopping it (kill -9, out of memory), the worker notices
    between runs and exits instead of running the rest of the sweep for nobody.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
    parent = multiprocessing.parent_process()
    with KeptRenderContext() as kept:
        while (spec := _next_task(conn, parent)) is not None:
            try:
                conn.send(run(spec, kept))
            except OSError:  # the parent is gone (BrokenPipeError) or stopped reading
                return


def _next_task(conn: Connection, parent: BaseProcess | None) -> RunSpec | None:
    """The next spec, or None at the stop sign or once the parent is gone."""
    while parent is None or parent.is_alive():
        try:
            if conn.poll(1.0):
                return conn.recv()
        except (EOFError, OSError):
            return None
    return None


@contextlib.contextmanager
def _environment(env: dict[str, str]) -> Iterator[None]:
    """os.environ with `env` while child processes start (spawn copies it), then restored.

    Set before the child's interpreter starts, so numpy's BLAS and Mesa read it at import.
    """
    saved = {key: os.environ.get(key) for key in env}
    os.environ.update(env)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


@contextlib.contextmanager
def _stop_signals_deferred() -> Iterator[None]:
    """SIGINT and SIGTERM held back while workers spawn, raised on leaving.

    A stop raised inside Process.start() leaves a started worker the sweep does not know
    about, or one that never gets its start-up data (an EOFError traceback of its own);
    held back, it is raised once every worker is on the list to stop. The signal may be
    delivered to any of this process's threads, so the handlers are swapped for one that
    notes it (main thread only: elsewhere none can be set). SIGINT is also blocked in the
    main thread's mask, which the children start with: a terminal's Ctrl-C reaches the
    whole process group, and a worker still loading would die of it with a traceback
    (_worker drops it and unblocks). SIGTERM stays deliverable, so a stop kills a
    loading worker at once.
    """
    resource_tracker.ensure_running()  # starting it later would unblock SIGINT again
    held: list[int] = []

    def hold(signum: int, frame: object) -> None:
        held.append(signum)

    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {s: signal.signal(s, hold) for s in STOP_SIGNALS}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        for signum, handler in previous.items():
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)
        for signum in dict.fromkeys(held):
            signal.raise_signal(signum)  # now to the handlers held back


@dataclass
class _Slot:
    """One local worker process, its end of the pipe, and the run it is doing."""

    proc: BaseProcess
    conn: Connection
    spec: RunSpec | None = None

    def give(self, spec: RunSpec | None) -> None:
        """Send the next spec (None: the stop sign); a dead worker is found by its sentinel."""
        self.spec = spec
        with contextlib.suppress(OSError):
            self.conn.send(spec)


def _start_worker(ctx: SpawnContext, run: RunFunction) -> _Slot:
    ours, theirs = ctx.Pipe()
    proc = ctx.Process(target=_worker, args=(theirs, run), daemon=True)
    with _environment(WORKER_ENV):
        proc.start()
    theirs.close()
    return _Slot(proc, ours)


def _died(proc: BaseProcess) -> str:
    code = proc.exitcode
    if code is not None and code < 0:
        return f"killed by {signal.Signals(-code).name}"
    return f"exit code {code}"


def _stop_workers(slots: list[_Slot], grace: float, finished: bool) -> None:
    """End every worker: SIGTERM, then after `grace` SIGKILL for the stubborn.

    `finished`: every worker got its stop sign and is first given EXIT_WAIT_S to exit by
    itself; otherwise (a stop or an error) they are terminated at once.
    """
    if finished:
        _join(slots, EXIT_WAIT_S)
    for stop in (BaseProcess.terminate, BaseProcess.kill):
        for slot in slots:
            if slot.proc.is_alive():
                stop(slot.proc)
        _join(slots, grace)
    for slot in slots:
        slot.conn.close()


def _join(slots: list[_Slot], seconds: float) -> None:
    deadline = time.monotonic() + seconds
    for slot in slots:
        slot.proc.join(max(0.0, deadline - time.monotonic()))


def _kill_workers(slots: list[_Slot]) -> None:
    """A second stop while stopping: no more grace."""
    for slot in slots:
        with contextlib.suppress(Exception):
            if slot.proc.is_alive():
                slot.proc.kill()
    for slot in slots:
        with contextlib.suppress(Exception):
            slot.proc.join(5.0)


def local_executor(
    workers: int | None = None, run: RunFunction = work, grace: float = STOP_GRACE_S
) -> Callable[..., None]:
    """Spawned processes on this machine (default: one per core).

    `run` is what a worker calls per spec (a module-level function: it is pickled by name;
    tests pass one that misbehaves); `grace` is how long a stopped worker has to exit
    before it is killed.
    """
    count = workers or os.cpu_count() or 1

    def execute(specs: Sequence[RunSpec], on_result: Callable[[dict[str, Any]], None]) -> None:
        if not specs:
            return
        ctx = multiprocessing.get_context("spawn")
        todo = deque(specs)
        deaths: Counter[str] = Counter()
        slots: list[_Slot] = []
        finished = False
        try:
            with _stop_signals_deferred():
                for _ in range(min(count, len(specs))):
                    slots.append(_start_worker(ctx, run))
            for slot in slots:
                slot.give(todo.popleft() if todo else None)
            while any(s.spec is not None for s in slots):
                busy = [s for s in slots if s.spec is not None]
                wait_for_any([s.conn for s in busy] + [s.proc.sentinel for s in busy], 1.0)
                for slot in busy:
                    result = _result(slot)
                    if result is not None:
                        on_result(result)
                        slot.give(todo.popleft() if todo else None)
                    elif not slot.proc.is_alive():
                        lost = slot.spec
                        assert lost is not None
                        deaths[lost.id] += 1
                        slot.spec = None
                        slot.proc.join()
                        if deaths[lost.id] <= RERUNS:
                            todo.appendleft(lost)
                        else:
                            on_result(
                                {
                                    "id": lost.id,
                                    "error": f"its worker process died during the run "
                                    f"{deaths[lost.id]} times (last: {_died(slot.proc)})",
                                }
                            )
                        slots.remove(slot)
                        slot.conn.close()
                        if todo:
                            with _stop_signals_deferred():
                                fresh = _start_worker(ctx, run)
                                slots.append(fresh)
                            fresh.give(todo.popleft())
            finished = True
        finally:
            try:
                _stop_workers(slots, grace, finished)
            except BaseException:
                _kill_workers(slots)
                raise

    return execute


def _result(slot: _Slot) -> dict[str, Any] | None:
    """The worker's result if one has come, else None (not yet, or the worker is gone)."""
    try:
        if slot.conn.poll():
            return slot.conn.recv()
    except (EOFError, OSError):
        pass
    return None


def ray_runtime_env(upload_code: bool = True) -> dict[str, Any]:
    """The workers' environment: thread and GL settings, and this checkout's packages.

    The nodes need the project's dependencies installed (the same image or venv, e.g.
    `pip install monopic[ray]`); `py_modules` ships this checkout's monopic and sim
    (models and trees included) so the cluster runs exactly this code.
    """
    env: dict[str, Any] = {"env_vars": dict(WORKER_ENV)}
    if upload_code:
        import monopic
        import sim

        env["py_modules"] = [
            str(Path(monopic.__file__).parent),
            str(Path(sim.__file__).parent),
        ]
    return env


# How long joining a cluster may take. Ray's own defaults retry an address that does not
# answer for over ten minutes, deaf to Ctrl-C for 30 s at a time; a value already in the
# environment wins.
RAY_CONNECT_TIMEOUT_S = 5.0
RAY_CONNECT_ENV = {
    "RAY_gcs_rpc_server_connect_timeout_s": "3",  # one gRPC connection attempt
    "RAY_py_gcs_connect_timeout_s": "3",  # the driver's wait for the cluster's id
    "RAY_gcs_server_port_wait_time_s": "1",  # attempts of the two above
}


def _probe(address: str, timeout: float = RAY_CONNECT_TIMEOUT_S) -> None:
    """A UserError at once if nothing accepts a TCP connection at a host:port address.

    Names like "auto" or "local" (Ray's own) and unparsable ones are left to Ray.
    """
    host, sep, port = address.removeprefix("ray://").rpartition(":")
    host = host.strip("[]")
    if not sep or not host or not port.isdigit():
        return
    try:
        with socket.create_connection((host, int(port)), timeout=timeout):
            pass
    except OSError as err:
        reason = (
            f"no answer within {timeout:g} s"
            if isinstance(err, TimeoutError)
            else (err.strerror or str(err)).lower()
        )
        raise UserError(
            f"--address {address}: no Ray cluster answers there ({reason}); give the head "
            "node's address as `ray start --head` printed it"
        ) from None


def _connect(ray: Any, address: str | None, upload_code: bool) -> None:
    """ray.init, bounded in time, keeping this process's SIGTERM handler.

    ray.init makes SIGTERM exit the process at once (sys.exit(15)): ours is put back, so
    a stopped sweep cancels its tasks and says so. While ray.init waits inside Ray's C++
    code (at most about 3 x 3 s with RAY_CONNECT_ENV) no Python handler runs.
    """
    if address:
        _probe(address)
    sigterm = signal.getsignal(signal.SIGTERM)
    try:
        # Joining a cluster takes its settings; a local instance gets no dashboard.
        extra = {} if address else {"include_dashboard": False}
        ray.init(
            address=address,
            runtime_env=ray_runtime_env(upload_code),
            log_to_driver=False,
            **extra,
        )
    except (ConnectionError, TimeoutError) as err:
        raise UserError(f"--address {address}: cannot reach a Ray cluster ({err})") from None
    except SystemExit as exit_:
        if exit_.code != signal.SIGTERM or sigterm is None:
            raise
        # A SIGTERM while joining met Ray's handler: answer it with ours instead.
        signal.signal(signal.SIGTERM, sigterm)
        signal.raise_signal(signal.SIGTERM)
        raise
    finally:
        if sigterm is not None:
            with contextlib.suppress(ValueError):  # not the main thread
                signal.signal(signal.SIGTERM, sigterm)


def ray_executor(
    address: str | None, upload_code: bool = True, run: Callable[..., dict[str, Any]] = work
) -> Callable[..., None]:
    """Runs as Ray tasks (one CPU each) on the cluster at `address` (None: RAY_ADDRESS or local).

    If this process already called ray.init (e.g. a test's local instance), that
    connection is used as it is. Joining takes at most a few RAY_CONNECT_TIMEOUT_S.
    `run` is what a task calls per spec (default: a sweep run; `monopic ncap` passes its own).
    """

    def execute(specs: Sequence[RunSpec], on_result: Callable[[dict[str, Any]], None]) -> None:
        # Ray reads its settings when it loads: the connect timeouts go in before (only to
        # join a cluster: a local instance's own processes must not inherit them).
        joining = (address or os.environ.get("RAY_ADDRESS", "local")) != "local"
        unset = {k: v for k, v in RAY_CONNECT_ENV.items() if joining and k not in os.environ}
        with _environment(unset):
            try:
                import ray
            except ImportError:
                raise UserError(
                    f"--executor ray needs Ray: pip install 'ray[default]=={RAY_PIN}' "
                    "(or the project's [ray] extra)"
                ) from None
            if not ray.is_initialized():
                _connect(ray, address, upload_code)
        remote = ray.remote(num_cpus=1)(run)
        pending = [remote.remote(spec) for spec in specs]
        try:
            while pending:
                # A timeout keeps the main thread answering signals between checks.
                done, pending = ray.wait(pending, num_returns=1, timeout=1.0)
                for ref in done:
                    on_result(ray.get(ref))
        except BaseException:
            for ref in pending:
                ray.cancel(ref, force=True)
            raise

    return execute
