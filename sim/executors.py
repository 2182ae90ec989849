"""Where runs execute: spawned local worker processes, or a Ray cluster.

Both call the same `work(spec)` and hand each finished result to the sweep as it
arrives; results depend only on the RunSpec (its seed included), never on the executor.
Workers render with their own EGL context (created in the worker: contexts do not
survive fork, hence spawn) and run onnxruntime with one thread, so N workers use N cores.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from monopic.errors import UserError
from sim.runner import RunSpec

# What every worker's environment needs before it imports MuJoCo or numpy.
WORKER_ENV = {
    "MUJOCO_GL": "egl",
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "LP_NUM_THREADS": "1",  # Mesa's software rasteriser: one thread per worker
}
RAY_PIN = "2.60.0"


def work(spec: RunSpec) -> dict[str, Any]:
    """One run in a worker; a failure comes back as {"id", "error"} instead of killing the pool."""
    from sim.runner import run

    try:
        return run(spec)
    except Exception:  # noqa: BLE001 - reported per run; the sweep goes on
        return {"id": spec.id, "error": traceback.format_exc()}


def _init_worker(env: dict[str, str]) -> None:
    """Worker setup: the environment, and Ctrl-C left to the parent (it stops the pool)."""
    os.environ.update(env)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def local_executor(workers: int | None = None) -> Callable[..., None]:
    """Spawned processes on this machine (default: one per core)."""
    count = workers or os.cpu_count() or 1

    def execute(specs: Sequence[RunSpec], on_result: Callable[[dict[str, Any]], None]) -> None:
        ctx = multiprocessing.get_context("spawn")
        pool = ctx.Pool(min(count, len(specs)), initializer=_init_worker, initargs=(WORKER_ENV,))
        try:
            for row in pool.imap_unordered(work, specs, chunksize=1):
                on_result(row)
            pool.close()
        except BaseException:
            pool.terminate()
            raise
        finally:
            pool.join()

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
