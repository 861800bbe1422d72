"""Where the chunks of a study run (:mod:`sixdof.chunks`): in this process, or on Dask distributed.

:func:`task_runner` gives the place they run, as a context manager:

- in this process (the default): chunk after chunk (:class:`sixdof.chunks.InProcess`);
- ``workers=N``: a local Dask cluster of N worker processes, one thread each, started and closed here;
- ``scheduler="tcp://host:8786"``: an existing Dask cluster (its workers must have sixdof installed);
- ``client=``: an existing :class:`distributed.Client`.

On Dask, every chunk is one task: at most two per worker thread of the cluster (as it is when a chunk
finishes: a cluster may grow) are in flight, so the client holds only those chunks' results; a chunk
whose worker dies is computed again by the scheduler and a chunk whose computation raises is retried
:data:`RETRIES` times. Workers started here run with one BLAS and one XLA
thread each (N workers on N cores do not oversubscribe) and with JAX's persistent compilation cache on, so
that a worker loads the compiled solvers instead of compiling them anew (:class:`WorkerSetup`); they ignore
SIGINT, which this process handles (:func:`dask_setup`), and log nothing (this process reports failures).

This is the only module that imports Dask; the batch engine knows nothing of it.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing.resource_tracker
import os
import signal
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from sixdof.chunks import Finished, InProcess
from sixdof.errors import InputError, Plain, SolverError, integer, memory_check
from sixdof.interrupts import held_signals

#: Recomputations of a chunk whose task raised (a worker that dies costs no retry: the scheduler moves its
#: chunks to another worker, up to Dask's ``distributed.scheduler.allowed-failures`` deaths per chunk).
RETRIES = 2
#: Chunks in flight per worker thread: one computing, one queued, so that no worker waits for the client.
IN_FLIGHT_PER_THREAD = 2
#: Seconds to wait for an existing scheduler to answer.
CONNECT_TIMEOUT_S = 10
#: The environment of the workers of a local cluster: one thread for BLAS and for XLA's CPU backend each.
WORKER_ENV = {
    "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
    "XLA_FLAGS": "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1",
}
#: The most local worker processes per CPU core (``--workers``): each runs one thread, so beyond a few per core
#: they only take turns on the cores while each holds its own memory.
WORKERS_PER_CORE = 4
#: The least memory a local worker process holds [bytes]: 262 MiB measured once it has imported JAX, Dask
#: and the batch engine, before its first chunk.
WORKER_BYTES = 262 * 2**20


def check_workers(workers: int) -> None:
    """Refuse up front a local cluster of more than :data:`WORKERS_PER_CORE` worker processes per CPU core, or
    one whose processes (:data:`WORKER_BYTES` each) cannot fit in this machine's memory.

    Raises
    ------
    InputError
        Naming ``--workers``, with this machine's cores or memory.
    """
    cores = os.cpu_count() or 1
    if workers > WORKERS_PER_CORE * cores:
        raise InputError("--workers", f"at most {WORKERS_PER_CORE * cores:,} worker processes ({WORKERS_PER_CORE} per "
                         f"core of this machine's {cores}; each runs one thread)", workers)
    memory_check("--workers", workers * WORKER_BYTES, "a local cluster", f"{workers:,} worker processes of at least "
                 f"{WORKER_BYTES / 2**20:.0f} MiB each")


class OnDask:
    """Chunks computed as tasks of a Dask cluster (see the module).

    Parameters
    ----------
    client : distributed.Client
    backend : {"dask-local", "dask"}
    """

    def __init__(self, client, backend: str) -> None:
        self.client, self.backend = client, backend

    @property
    def workers(self) -> int:
        """Worker processes of the cluster now."""
        return len(self.client.scheduler_info(n_workers=-1)["workers"])

    def _threads(self) -> int:
        return max(1, sum(self.client.nthreads().values()))

    def run(self, task: Callable, jobs: Iterable[tuple[int, tuple]]) -> Iterator[Finished]:
        """``task(*args)`` for each ``(index, args)`` of ``jobs`` as tasks, yielded as each finishes (in any
        order). Pending tasks are cancelled when the caller stops early (an error, Ctrl-C)."""
        from distributed import as_completed
        from distributed.scheduler import KilledWorker

        jobs = iter(jobs)
        token = f"{task.__name__}-{os.getpid()}-{time.monotonic_ns()}"
        pending: dict = {}
        done = as_completed(with_results=False)

        def top_up() -> None:
            """Submit jobs until each worker thread of the cluster now (it may grow) has its share in flight."""
            while len(pending) < IN_FLIGHT_PER_THREAD * self._threads():
                index, args = next(jobs, (None, None))
                if index is None:
                    return
                future = self.client.submit(task, *args, key=f"sixdof-{token}-{index}", pure=False, retries=RETRIES)
                pending[future] = index
                done.add(future)

        top_up()
        try:
            for future in done:
                index = pending.pop(future)
                try:
                    result = future.result()
                except KilledWorker as exc:
                    raise SolverError(f"chunk {index} was lost with the worker computing it, too many times for Dask "
                                      f"({exc}): a worker that runs out of memory or crashes on it (see the workers' "
                                      "logs)") from None
                future.release()
                top_up()
                yield Finished(index, result)
        finally:
            if pending:
                self.client.cancel(list(pending))


class WorkerSetup:
    """Run on each worker as it starts (a Dask worker plugin): JAX's persistent compilation cache on, so a
    worker loads the solvers that another worker or an earlier run compiled."""

    name = "sixdof-worker-setup"
    idempotent = True

    def setup(self, worker) -> None:
        from sixdof._jax import enable_compilation_cache

        enable_compilation_cache()

    def teardown(self, worker) -> None:
        pass


def dask_setup(worker) -> None:
    """Dask's preload hook, run in each worker process of a local cluster as it starts (``preload`` of
    :func:`task_runner`'s ``LocalCluster``): the worker ignores SIGINT. Ctrl-C reaches the whole process group;
    this process alone handles it and closes the cluster, as the figure workers leave it to this process
    (:mod:`sixdof.cli.figures`). Without it each worker's event loop stops on the KeyboardInterrupt and prints
    its traceback, some 30 lines a worker, before sixdof's one line.

    Not on a cluster sixdof did not start (``--scheduler``, ``client=``): its workers' Ctrl-C is their owner's."""
    if threading.current_thread() is threading.main_thread():  # where a signal handler can be set
        signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def _sigint_blocked():
    """SIGINT held back during the block and delivered when it ends, blocked meanwhile in this (the main) thread:
    the cluster's threads started meanwhile, and the worker processes they start, inherit the mask. A Ctrl-C in
    the second or two before a worker has run :func:`dask_setup` then neither kills it (a worker killed while it
    starts fails the cluster's start with some 100 lines of tracebacks) nor is lost to this process."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return

    # The thread that starts multiprocessing's resource tracker unblocks SIGINT when it has (the cluster's event
    # loop would, on its first queue): started here first, it is left alone.
    multiprocessing.resource_tracker.ensure_running()
    # Held too: a thread started before the block, which does not block it, may be the one the kernel gives it to.
    with held_signals():
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _plugin():
    """:class:`WorkerSetup` as a :class:`distributed.WorkerPlugin` (the class is made where Dask is imported)."""
    from distributed.diagnostics.plugin import WorkerPlugin

    return type("SixdofWorkerSetup", (WorkerSetup, WorkerPlugin), {})()


def _import_distributed(field: str, value: Any) -> None:
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise InputError(field, "Dask distributed installed (pip install 'sixdof[dask]')",
                         Plain(f"{value}, but the package distributed is not importable")) from None


@contextlib.contextmanager
def task_runner(workers: int | None = None, scheduler: str | None = None, client=None):
    """Where a study's chunks run (see the module): yields an :class:`InProcess` or :class:`OnDask`.

    Parameters
    ----------
    workers : int, optional
        Start a local cluster of that many worker processes (closed on exit).
    scheduler : str, optional
        Address of an existing Dask scheduler.
    client : distributed.Client, optional
        An existing client (left open on exit).

    Raises
    ------
    InputError
        More than one of them given, a number of workers < 1, Dask not installed, or a scheduler that
        does not answer within :data:`CONNECT_TIMEOUT_S` (before any chunk is computed).
    """
    given = [name for name, value in (("--workers", workers), ("--scheduler", scheduler), ("client", client))
             if value is not None]
    if len(given) > 1:
        raise InputError(given[1], f"one place to run the chunks (not with {given[0]})", Plain("both given"))
    if workers is None and scheduler is None and client is None:
        yield InProcess()
        return
    if client is not None:
        client.register_plugin(_plugin())
        yield OnDask(client, "dask")
        return
    if workers is not None:
        workers = integer(workers, "--workers", "a number of worker processes >= 1", 1)
        check_workers(workers)
        _import_distributed("--workers", workers)
    else:
        if not isinstance(scheduler, str) or not scheduler.strip():
            raise InputError("--scheduler", "the address of a Dask scheduler (tcp://host:8786)", scheduler)
        _import_distributed("--scheduler", scheduler)
    import dask
    from distributed import Client, LocalCluster

    with contextlib.ExitStack() as stack:
        if workers is not None:
            # Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which fixes glibc's mmap threshold at 128 kB:
            # every large temporary array of the exact engine is then mapped and unmapped anew, and a chunk
            # takes 1.34x as long (measured). sixdof's workers keep glibc's adaptive default.
            # Ctrl-C reaches the workers too (the whole process group): they ignore it from their start
            # (_sigint_blocked) and once started (dask_setup, restarted workers too); this process handles it and
            # closes the client, then the cluster (the stack's order). Dask's own logs are off: each failure of a
            # chunk reaches this process (its future re-raises the exception, a lost worker is a KilledWorker),
            # which says it in one line; beside that Dask logs races of its own shutdown, a worker's heartbeat in
            # flight as the scheduler closes on a loaded machine ("Failed to communicate with scheduler during
            # heartbeat", dask/distributed#7105), and each failed chunk's traceback a second time.
            with _sigint_blocked(), dask.config.set(
                    {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
                cluster = stack.enter_context(LocalCluster(
                    n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                    silence_logs=logging.CRITICAL, env={**WORKER_ENV, **_passed_env()}, preload=[__name__]))
            client = stack.enter_context(Client(cluster))
            backend = "dask-local"
        else:
            try:
                client = stack.enter_context(Client(scheduler, timeout=CONNECT_TIMEOUT_S))
            except (OSError, TimeoutError) as exc:
                raise InputError("--scheduler", "the address of a running Dask scheduler",
                                 Plain(f"{scheduler} ({exc.__class__.__name__}: {exc})")) from None
            backend = "dask"
        client.register_plugin(_plugin())
        yield OnDask(client, backend)


def _passed_env() -> dict[str, str]:
    """The settings of sixdof's that a worker process must share with this one."""
    return {k: v for k, v in os.environ.items() if k in ("SIXDOF_JAX_CACHE", "XDG_CACHE_HOME", "EQX_ON_ERROR")}


__all__ = ["OnDask", "RETRIES", "WorkerSetup", "check_workers", "task_runner"]
