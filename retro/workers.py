"""Worker processes for the long commands (check, chart, stability, advise): one pool maker for all.

A worker ignores Ctrl-C (the parent stops the pool and reports one line) and, on Linux, dies with its
parent: when `retro chart` is killed, its workers get SIGTERM from the kernel instead of running on
(prctl PR_SET_PDEATHSIG, Linux man page prctl(2)).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import signal
import sys
import time
from concurrent.futures import ProcessPoolExecutor

from retro import interrupts

PR_SET_PDEATHSIG = 1  # prctl(2): the signal the calling process gets when its parent dies
MAX_WORKERS = 2  # each worker holds its own emulator, case blocks and study corpus (70-320 MB): 2 keep a command's
# whole process tree under 1 GiB (benchmarks/peak_memory.py, docs/limits.md)


def _prepare_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in ("SIGTERM", "SIGHUP"):  # the parent's handlers raise; a worker just ends
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        except (OSError, AttributeError):  # no libc to ask: the worker just lacks the safeguard
            pass


class _Pool(ProcessPoolExecutor):
    """Stopped, not drained, on a stop signal: `shutdown` after Ctrl-C or SIGTERM (and leaving a
    `with` block on KeyboardInterrupt) cancels what is queued and ends the workers at once, instead
    of waiting for their tasks (up to 30 s for a chart's)."""

    def submit(self, *args, **kwargs):
        interrupts.raise_if_stopping()  # a stop the handler's exception did not carry out
        return super().submit(*args, **kwargs)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        if interrupts.stopping():
            self.stop_workers()
        else:
            super().shutdown(wait=wait, cancel_futures=cancel_futures)

    def __exit__(self, exc_type, exc, tb):
        if exc_type is not None and issubclass(exc_type, KeyboardInterrupt):
            self.stop_workers()
            return False
        return super().__exit__(exc_type, exc, tb)

    def stop_workers(self) -> None:
        processes = list((self._processes or {}).values())  # the pool's own list: no public one before 3.14
        super().shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()
        deadline = time.monotonic() + WORKER_STOP_SECONDS
        for process in processes:
            process.join(max(0.0, deadline - time.monotonic()))
            if process.is_alive():
                process.kill()
                process.join(1)


WORKER_STOP_SECONDS = 1.0  # SIGTERM ends a worker at once (it has no handler); SIGKILL after this


def worker_pool(workers: int) -> ProcessPoolExecutor:
    """A process pool whose workers ignore Ctrl-C, die with their parent, and are stopped at once
    when the command is."""
    return _Pool(max_workers=workers, initializer=_prepare_worker)
