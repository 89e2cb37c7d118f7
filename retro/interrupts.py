"""Stopping on a signal: SIGINT (Ctrl-C), SIGTERM (`timeout`, CI cancellation, `docker stop`) and
SIGHUP (the terminal closed) all raise `Interrupted`, so every `finally` runs (temp files removed,
worker pools stopped) and the command ends with one line and exit 128 + the signal's number (130
for Ctrl-C, the shells' convention).

Only the standard library here: `retro.entry` installs the handlers before anything heavy is
imported, and `retro.fileio` and `retro.workers` use it from below every other layer.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager

STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


class Interrupted(KeyboardInterrupt):
    """A stop signal arrived; `exit_code` is what the process should end with."""

    def __init__(self, signum: int = signal.SIGINT) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


_stopping = False


def stopping() -> bool:
    """True once a stop signal has arrived: cleanup that would wait (a worker pool finishing its
    tasks) stops its workers instead."""
    return _stopping


_signum = 0


def _raise(signum: int, frame) -> None:
    global _stopping, _signum
    _stopping, _signum = True, signum
    raise Interrupted(signum)


def stop_exit_code() -> int | None:
    """128 + the stop signal's number once one arrived, else None."""
    return 128 + _signum if _stopping else None


def raise_if_stopping() -> None:
    """Raise `Interrupted` again if a stop signal arrived. The handler's exception can be lost: when
    the signal lands in Python code that C code runs with its errors cleared (an attribute lookup
    through `PyObject_HasAttr`, a key's `__eq__` under `PyDict_GetItem`), Python drops it. So places
    the work passes often (a task handed to a worker, an output about to be written or committed)
    ask again."""
    if _stopping:
        raise Interrupted(_signum)


def install() -> None:
    """Make every stop signal raise `Interrupted` (a KeyboardInterrupt, so code that cleans up on
    Ctrl-C cleans up on SIGTERM too). A signal that the parent set to be ignored stays ignored
    (`nohup` works)."""
    for signum in STOP_SIGNALS:
        if signal.getsignal(signum) is not signal.SIG_IGN:
            signal.signal(signum, _raise)


def exit_code(exc: BaseException) -> int:
    return exc.exit_code if isinstance(exc, Interrupted) else 128 + signal.SIGINT


def describe(exc: BaseException) -> str:
    """'interrupted' for Ctrl-C, 'stopped by SIGTERM' for the others: the end of the one line."""
    signum = exc.signum if isinstance(exc, Interrupted) else signal.SIGINT
    return "interrupted" if signum == signal.SIGINT else f"stopped by {signal.Signals(signum).name}"


@contextmanager
def deferred() -> Iterator[None]:
    """Stop signals wait until the block ends (then they are delivered): for the few system calls
    that must run together or not at all (renaming a set of files into place, registering a temp
    file). Outside the main thread, or without pthread_sigmask, the block runs as it is."""
    can_block = hasattr(signal, "pthread_sigmask") and _in_main_thread()
    if can_block:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        yield
    finally:
        if can_block:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _in_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def exit_now_on_signal(stream=None) -> None:
    """After the command has finished: a stop signal during interpreter shutdown ends the process at
    once with its one line and exit code, instead of an 'Exception ignored' report."""
    stream = stream or sys.stderr

    def handler(signum: int, frame) -> None:
        try:
            stream.write(f"retro: {describe(Interrupted(signum))}\n")
            stream.flush()
        finally:
            os._exit(128 + signum)

    for signum in STOP_SIGNALS:
        if signal.getsignal(signum) is not signal.SIG_IGN:
            signal.signal(signum, handler)
