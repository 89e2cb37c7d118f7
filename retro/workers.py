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
from concurrent.futures import ProcessPoolExecutor

PR_SET_PDEATHSIG = 1  # prctl(2): the signal the calling process gets when its parent dies
MAX_WORKERS = 2  # each worker holds its own emulator, case blocks and study corpus (70-320 MB): 2 keep a command's
# whole process tree under 1 GiB (benchmarks/peak_memory.py, docs/limits.md)


def _prepare_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        except (OSError, AttributeError):  # no libc to ask: the worker just lacks the safeguard
            pass


def worker_pool(workers: int) -> ProcessPoolExecutor:
    """A process pool whose workers ignore Ctrl-C and die with their parent."""
    return ProcessPoolExecutor(max_workers=workers, initializer=_prepare_worker)
