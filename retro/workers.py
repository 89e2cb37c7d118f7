"""Where the long commands' parallel work runs (check, chart, advise): in this process, or as Dask tasks.

A run small enough for one process runs its tasks here, in order, and never imports Dask. A larger one
runs them on a Dask cluster: an embedded `LocalCluster` of `count` worker processes on this machine
(nothing to start or configure), or the existing cluster whose scheduler is at `--scheduler ADDRESS` or
in the environment variable RETRO_SCHEDULER. Either way the results come back in task order, whatever
the order the tasks finish in, with at most IN_FLIGHT tasks per worker thread submitted at once (memory
stays bounded whatever the run's size). On Ctrl-C (or SIGTERM) the pending tasks are cancelled and the
embedded cluster's workers are stopped; they ignore Ctrl-C themselves (the parent stops them) and exit
when their parent dies (distributed's worker processes watch a pipe from it).
"""

from __future__ import annotations

import logging
import os
import signal
import sys
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from typing import Any

from retro import interrupts

MAX_WORKERS = 2  # each worker holds its own emulator, case blocks and study corpus (70-320 MB): 2 keep a command's
# whole process tree under 1 GiB (benchmarks/peak_memory.py, docs/limits.md)
SCHEDULER_ENV = "RETRO_SCHEDULER"  # the address of an existing Dask scheduler, when --scheduler is not given
IN_FLIGHT = 2  # tasks submitted per worker thread: one running, one ready (results are merged in order)
CONNECT_SECONDS = 10  # how long a scheduler address may take to answer
CLOSE_SECONDS = 20  # and this long after a run (then its workers are killed)
STOP_CLOSE_SECONDS = 2  # and this long on a stop, its workers already killed


@dataclass(frozen=True)
class Workers:
    """Where a run's tasks go: `count` local worker processes, or the cluster at `scheduler`."""

    count: int = 1
    scheduler: str | None = None

    @property
    def parallel(self) -> bool:
        return self.scheduler is not None or self.count > 1


def default_count() -> int:
    return max(1, min(MAX_WORKERS, os.cpu_count() or 1))


def configured(jobs: int | None, scheduler: str | None) -> Workers:
    """The workers of a command: its --jobs (None: up to MAX_WORKERS) and --scheduler, which when absent
    comes from RETRO_SCHEDULER (an empty value: none)."""
    address = scheduler if scheduler is not None else os.environ.get(SCHEDULER_ENV)
    return Workers(default_count() if jobs is None else jobs, address.strip() or None if address else None)


def as_workers(workers: Workers | int | None) -> Workers:
    """A plain count (the library's `jobs`/`workers` arguments) as local workers; None: the default."""
    if isinstance(workers, Workers):
        return workers
    return Workers(default_count() if workers is None else workers)


def only(workers: Workers | int | None, needed: bool) -> Workers:
    """`workers` when the run is big enough to need them, else this process alone (no cluster, no import)."""
    return as_workers(workers) if needed else Workers(1)


def run_in_order(function: Callable, tasks: Iterable[tuple], workers: Workers | int | None,
                 report: Callable[[Any], bool | None]) -> None:
    """`report(function(*task))` for each task, in task order; a `report` returning True ends the run
    (the tasks still pending are cancelled). With one local worker (and no scheduler) the tasks run in
    this process; else as Dask tasks, at most IN_FLIGHT per worker thread at once."""
    workers = as_workers(workers)
    if not workers.parallel:
        for task in tasks:
            interrupts.raise_if_stopping()
            if report(function(*task)):
                return
        return
    _preload(function.__module__)
    if _session is not None:  # one cluster for the whole command (`session`)
        if workers not in _session:
            _session[workers] = _session_stack.enter_context(_client(workers))
        _run_on(_session[workers], function, tasks, report)
        return
    with _client(workers) as client:
        _run_on(client, function, tasks, report)


_session: dict | None = None
_session_stack = ExitStack()


@contextmanager
def session() -> Iterator[None]:
    """The runs inside share their cluster: started by the first that needs one, closed on leaving (a
    command's several parallel steps, or its several routines, pay for one start)."""
    global _session
    if _session is not None:  # already inside one
        yield
        return
    _session = {}
    try:
        yield
    finally:
        _session = None
        _session_stack.close()


def _run_on(client, function: Callable, tasks: Iterable[tuple], report: Callable[[Any], bool | None]) -> None:
    limit = IN_FLIGHT * max(1, sum(client.nthreads().values()))
    pending: deque = deque()
    iterator: Iterator[tuple] = iter(tasks)
    try:
        while True:
            while len(pending) < limit:
                task = next(iterator, None)
                if task is None:
                    break
                interrupts.raise_if_stopping()
                pending.append(client.submit(function, *task, pure=False))
            if not pending:
                return
            if report(pending.popleft().result()):  # in order: ties (the first fastest case) do not depend on timing
                return
    finally:
        # an embedded cluster's workers are killed on a stop (cancelling first would hold up its closing)
        if pending and not (interrupts.stopping() and getattr(client, "cluster", None) is not None):
            client.cancel(list(pending))


# glibc's allocator in the embedded workers: a task's blocks are arrays of up to BLOCK_BYTES (8 MiB) made and
# freed per block; with glibc's defaults in a fresh process (or Dask's MALLOC_TRIM_THRESHOLD_=65536, which it
# sets for its workers) they are mapped and unmapped, or their memory handed back, each time, and every block
# faults its pages in again: about 4 times the page faults and a quarter more CPU per task than in a process
# whose thresholds have grown (measured on aabb8's sweep: tests of 30 tasks, 139,000 page faults against 33,000).
# Up to WORKER_TRIM_THRESHOLD of freed memory stays with each worker.
WORKER_MMAP_THRESHOLD = 32 << 20  # allocations from this size on get their own mapping
WORKER_TRIM_THRESHOLD = 64 << 20  # free memory kept before it is handed back

# The embedded cluster's Dask settings: its workers hold one long task at a time, so Dask's own sampling
# profiler (every 10 ms), event-loop tick check (20 ms), system monitor (500 ms), memory monitor (100 ms),
# work stealing and active memory manager only cost CPU: together about 0.1 CPU-second per second of an
# idle two-worker cluster, measured (benchmarks/dask_cpu.py); with these, about a tenth of it.
EMBEDDED_CONFIG = {
    "distributed.worker.multiprocessing-method": "forkserver",  # workers forked from a server process (a
    # fraction of spawn's start, which imports everything again per worker)
    "distributed.logging.distributed": "critical",  # errors reach us as exceptions
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "10s",
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.worker.memory.monitor-interval": "10s",
    "distributed.scheduler.work-stealing": False,  # tasks go out IN_FLIGHT per thread: nothing to steal
    "distributed.scheduler.active-memory-manager.start": False,
    # the environment the workers start with (read by glibc and the numeric libraries as a process starts)
    "distributed.nanny.pre-spawn-environ": {"OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1,
                                            "MALLOC_MMAP_THRESHOLD_": WORKER_MMAP_THRESHOLD,
                                            "MALLOC_TRIM_THRESHOLD_": WORKER_TRIM_THRESHOLD},
}


def _preload(module: str) -> None:
    """The worker processes of this process's embedded clusters are forked from a server process that
    imports `module` (the tasks' code, and numba when this process uses it) once, before the first
    cluster starts: each worker inherits it rather than importing it again (about 0.4 CPU-second per
    worker for the check). No effect once
    that server runs (a later cluster in the same process), nor on another machine's workers."""
    import multiprocessing

    import dask
    from distributed.utils import get_mp_context  # (before setting its keys: its defaults come with it)

    global _preloaded
    if _preloaded or module == "__main__":  # (a script's main module is imported by each worker anyway)
        return
    _preloaded = True
    with dask.config.set(EMBEDDED_CONFIG):
        context = get_mp_context()  # distributed sets its own list first (itself, numpy, ...)
    if isinstance(context, type(multiprocessing.get_context("forkserver"))):
        context.set_forkserver_preload(server_preload(module))


def server_preload(module: str) -> list[str]:
    """The modules the workers' server imports: Dask's, the tasks' `module`, and what PRELOAD_IF_IMPORTED
    adds for what this process has imported."""
    extra = [name for used, names in PRELOAD_IF_IMPORTED.items() if used in sys.modules for name in names]
    return ["distributed", module, *extra]


_preloaded = False
PRELOAD_IF_IMPORTED = {"numba.np.arraymath": ("numba", "retro.cpu.numba_ready")}  # imported by the server too when
# this process has imported the first: numba's array implementations come in when numba's CPU target is made ready
# to load compiled code (the compiled engine in use here; any check imports numba itself, to ask whether it can be
# used). Then the server imports numba (about 0.25 CPU-second per worker otherwise) and makes its target ready
# (retro/cpu/numba_ready.py: about 0.4 CPU-second more per worker, when it loads its first routine)


@contextmanager
def _client(workers: Workers) -> Iterator[Any]:
    """A Dask client of the scheduler at `workers.scheduler`, else of an embedded local cluster of
    `workers.count` single-threaded worker processes (closed, its workers stopped, on leaving)."""
    from retro.errors import InputError

    import dask
    from distributed import Client, LocalCluster

    if workers.scheduler is not None:
        try:
            client = Client(workers.scheduler, timeout=CONNECT_SECONDS, set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"--scheduler {workers.scheduler}: no Dask scheduler answers there ({exc})") from None
        try:
            yield client
        finally:
            client.close()
        return
    dask.config.set(EMBEDDED_CONFIG)  # for this process's clusters
    cluster = LocalCluster(n_workers=workers.count, threads_per_worker=1, processes=True, dashboard_address=":0",
                           preload=[__name__], silence_logs=logging.CRITICAL, memory_limit=0)
    client = Client(cluster, set_as_default=False)
    pids = list(client.run(os.getpid).values())
    try:
        yield client
    finally:
        _close(client, cluster, pids)


def _close(client, cluster, pids: list[int]) -> None:
    """Close the client and the embedded cluster (its workers killed when they do not end within
    CLOSE_SECONDS). On a stop the workers are killed at once (they hold nothing to save), then the
    cluster is closed, for at most STOP_CLOSE_SECONDS (about 0.05 s, measured): that releases what its
    nannies hold in this process, the named semaphores of their queues among them (the command then
    ends with os._exit, which runs no finalizer: else multiprocessing's resource tracker reports them
    as leaked)."""
    if interrupts.stopping():
        # the teardown cuts the cluster's connections on purpose: distributed's loggers would print each
        # cut as a traceback (its comms log from their own threads until the process ends), so they are
        # silenced for the rest of this process (retro itself does not log)
        logging.disable(logging.CRITICAL)
        for nanny in cluster.workers.values():
            nanny.close_gracefully(reason="retro-stop")  # else a nanny restarts a worker that dies
        _kill(pids)
        cluster.shutdown_on_close = False  # nor is the cluster closed again at exit (distributed's atexit)
        try:
            cluster.close(timeout=STOP_CLOSE_SECONDS)
        except (TimeoutError, OSError, RuntimeError):  # the process ends anyway
            pass
        return
    try:
        client.close(timeout=CLOSE_SECONDS)
        cluster.close(timeout=CLOSE_SECONDS)
    except (TimeoutError, OSError, RuntimeError):
        _kill(pids)


def _kill(pids: list[int]) -> None:
    for pid in pids:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:  # already gone
            pass


def dask_setup(worker) -> None:
    """Run by each worker of the embedded cluster as it starts (its `preload`): Ctrl-C in the terminal
    reaches the whole process group, and the parent, not the worker, decides what stops."""
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the worker process's main thread: it keeps the default
        pass
