"""Where runs execute: spawned local worker processes, or a Ray cluster.

Both call the same `work(spec)` and hand each finished result to the sweep as it
arrives; results depend only on the RunSpec (its seed included), never on the executor.
Workers render with their own EGL context (created in the worker: contexts do not
survive fork, hence spawn) and run onnxruntime with one thread, so N workers use N cores.
A local worker keeps its GL context from run to run (sim.world.render.KeptRenderContext: a
fresh one costs about 0.2 s of shader compilation per run on llvmpipe).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import queue
import signal
import traceback
from collections.abc import Callable, Iterator, Sequence
from multiprocessing.process import BaseProcess
from multiprocessing.queues import Queue
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
}
RAY_PIN = "2.60.0"


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


def _worker(tasks: Queue, results: Queue) -> None:
    """A local worker process: runs specs from `tasks` until None; Ctrl-C is the parent's.

    If the parent dies without stopping it (kill -9, out of memory), the worker notices
    between runs and exits instead of running the rest of the sweep for nobody.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = multiprocessing.parent_process()
    with KeptRenderContext() as kept:
        while (spec := _next_task(tasks, parent)) is not None:
            results.put(work(spec, kept))
    if parent is not None and not parent.is_alive():
        results.cancel_join_thread()  # nobody will read what is still queued


def _next_task(tasks: Queue, parent: BaseProcess | None) -> RunSpec | None:
    """The next spec, or None at the stop sign or once the parent is gone."""
    while parent is None or parent.is_alive():
        try:
            return tasks.get(timeout=1.0)
        except queue.Empty:
            continue
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


def _next_result(results: Queue, workers: list[BaseProcess]) -> dict[str, Any]:
    while True:
        try:
            return results.get(timeout=1.0)
        except queue.Empty:
            if not any(w.is_alive() for w in workers):
                codes = ", ".join(str(w.exitcode) for w in workers)
                raise RuntimeError(
                    f"every sweep worker exited before its runs were done (exit codes {codes}); "
                    "rerun the sweep to resume"
                ) from None


def local_executor(workers: int | None = None) -> Callable[..., None]:
    """Spawned processes on this machine (default: one per core)."""
    count = workers or os.cpu_count() or 1

    def execute(specs: Sequence[RunSpec], on_result: Callable[[dict[str, Any]], None]) -> None:
        if not specs:
            return
        ctx = multiprocessing.get_context("spawn")
        tasks: Queue = ctx.Queue()
        results: Queue = ctx.Queue()
        procs = [
            ctx.Process(target=_worker, args=(tasks, results), daemon=True)
            for _ in range(min(count, len(specs)))
        ]
        for spec in specs:
            tasks.put(spec)
        for _ in procs:
            tasks.put(None)  # one stop sign per worker, after the runs
        try:
            with _environment(WORKER_ENV):
                for proc in procs:
                    proc.start()
            for _ in specs:
                on_result(_next_result(results, procs))
        except BaseException:
            for proc in procs:
                proc.terminate()
            raise
        finally:
            for proc in procs:
                proc.join()

    return execute


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


def ray_executor(address: str | None, upload_code: bool = True) -> Callable[..., None]:
    """Runs as Ray tasks (one CPU each) on the cluster at `address` (None: RAY_ADDRESS or local).

    If this process already called ray.init (e.g. a test's local instance), that
    connection is used as it is.
    """

    def execute(specs: Sequence[RunSpec], on_result: Callable[[dict[str, Any]], None]) -> None:
        try:
            import ray
        except ImportError:
            raise UserError(
                f"--executor ray needs Ray: pip install 'ray[default]=={RAY_PIN}' "
                "(or the project's [ray] extra)"
            ) from None
        if not ray.is_initialized():
            try:
                # Joining a cluster takes its settings; a local instance gets no dashboard.
                extra = {} if address else {"include_dashboard": False}
                ray.init(
                    address=address,
                    runtime_env=ray_runtime_env(upload_code),
                    log_to_driver=False,
                    **extra,
                )
            except ConnectionError as err:
                raise UserError(
                    f"--address {address}: cannot reach a Ray cluster ({err})"
                ) from None
        remote = ray.remote(num_cpus=1)(work)
        pending = [remote.remote(spec) for spec in specs]
        try:
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                on_result(ray.get(done[0]))
        except BaseException:
            for ref in pending:
                ray.cancel(ref, force=True)
            raise

    return execute
