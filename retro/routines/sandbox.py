"""Users' Python code (a spec's reference and generators, a method's hitbox rule) run under guard.

A user's function can do things no `except Exception` sees: `sys.exit(0)` (SystemExit), `os._exit(0)`
(the process ends with status 0 and prints nothing: a check that "passed"), loop forever, recurse
without end, or allocate gigabytes. `guarded(function, label, seconds)` returns a function that calls
the user's one with these guards, each paid per call (benchmarks/sandbox_overhead.py measures them):

- time: an interval timer (SIGALRM, main thread only) stops a call after `seconds` (a spec's
  `[reference] time_limit`, a method file's `[hitbox] time_limit`; default DEFAULT_SECONDS);
- memory: the address space may grow by at most USER_MEMORY_BYTES during a call (RLIMIT_AS, Linux
  getrlimit(2)): past it, allocations fail with MemoryError inside the user's code;
- exits: `sys.exit` (any status) and `os._exit`/`os.abort` inside a call become errors;
- a C call that holds the interpreter past the limit (the timer's Python handler cannot run, e.g. one
  huge integer power) is ended by a CPU-time timer GRACE_SECONDS later (ITIMER_VIRTUAL, whose
  SIGVTALRM ends the process by default: killed by a signal, never exit status 0, but no line).

Every such failure is a `UserCodeError` (an InputError: exit 2), one line naming the function
(`refs.py:boxhit`) and the call's arguments (the case). An ordinary exception (ValueError, ...)
passes through unchanged when the caller gives it a meaning (a reference refusing a case outside the
domain); with `faults_only=False` it becomes a UserCodeError too (generators, where any exception is
a fault).
"""

from __future__ import annotations

import functools
import os
import resource
import signal
import _signal
import sys
import threading
import time
from collections.abc import Callable, Iterator

import numpy as np

from retro.errors import InputError

DEFAULT_SECONDS = 20  # a case or a block of 65,536 cases takes milliseconds; 20 s is a hang
MAX_SECONDS = 3_600
USER_MEMORY_BYTES = 512 << 20  # what one call may add to the process's address space
TIMER_SLACK = 0.01  # seconds: a timer's signal may come this early
GRACE_SECONDS = 5  # after the limit, before the watchdog ends a call stuck in C code
SHOWN_CHARACTERS = 60  # of a value in an error line
SHOWN_ARGUMENTS = 8  # items of a list or dict in an error line
SHOWN_CALL_ARGUMENTS = 32  # arguments of a call: every input of any built-in routine

_PLAIN = (list, tuple, dict, np.ndarray, bytes, bytearray, str, range)
_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


class UserCodeError(InputError):
    """A user's function failed in a way that stops the run: the message names it and the call."""


class _TimeUp(BaseException):  # BaseException: a user's `except Exception` does not swallow it
    pass


class _Exited(BaseException):
    def __init__(self, how: str) -> None:
        super().__init__(how)
        self.how = how


_inside = False  # a guarded call is running (in this process): os._exit and os.abort raise instead


def _exit_instead(original: Callable, name: str) -> Callable:
    @functools.wraps(original)
    def replacement(*args):
        if _inside:
            raise _Exited(f"called {name}({', '.join(map(str, args))})")
        return original(*args)
    return replacement


def _install_exit_guards() -> None:
    """os._exit and os.abort raise inside guarded calls (outside them they are the originals: pool
    workers end with os._exit)."""
    import posix

    for module in (os, posix):
        for name in ("_exit", "abort"):
            current = getattr(module, name, None)
            if current is not None and not getattr(current, "_retro_guard", False):
                replacement = _exit_instead(current, f"os.{name}")
                replacement._retro_guard = True
                setattr(module, name, replacement)


_install_exit_guards()


# ---- showing values in one line --------------------------------------------------------------------

def shown(value, limit: int = SHOWN_CHARACTERS) -> str:
    """A value as an error line shows it: short, and never failing (a 5,000-digit integer has no repr
    under Python's int_max_str_digits; an array is summarised)."""
    if isinstance(value, np.generic) and value.dtype.kind in "biuf":
        value = value.item()
    if isinstance(value, bool) or value is None:
        return repr(value)
    if isinstance(value, int):
        if value.bit_length() > 128:
            return f"an integer of {value.bit_length()} bits"
        text = repr(value)
    elif isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} ({value.dtype})"
    elif isinstance(value, np.random.Generator):
        return "rng"
    elif isinstance(value, (list, tuple)) and len(value) > SHOWN_ARGUMENTS:
        return f"{len(value)} items"
    elif isinstance(value, (list, tuple)):
        inner = ", ".join(shown(v, limit) for v in value)
        text = f"[{inner}]" if isinstance(value, list) else f"({inner})"
    elif isinstance(value, dict):
        text = "{" + ", ".join(f"{k!s:.20}: {shown(v, limit)}" for k, v in list(value.items())[:SHOWN_ARGUMENTS]) + "}"
    elif isinstance(value, (str, float, bytes)):
        text = repr(value[:limit] if isinstance(value, (str, bytes)) else value)
    else:  # a user's object: its own repr could fail, hang or run for pages
        text = f"a {type(value).__name__}"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def describe_call(args: tuple, kwargs: dict) -> str:
    """The arguments of a call (a reference's: the case's inputs by name, then its memory blocks)."""
    parts = [shown(a) for a in args[:SHOWN_CALL_ARGUMENTS]]
    parts += [f"{k}={shown(v)}" for k, v in list(kwargs.items())[:SHOWN_CALL_ARGUMENTS - len(parts)]]
    return ", ".join(parts) or "no arguments"


# ---- the guard -----------------------------------------------------------------------------------

SIGALRM = int(signal.SIGALRM)
_previous_alarm = None  # the SIGALRM handler ours replaced: called when our timer is not running


_deadline = 0.0  # when the running guarded call's time is up (time.monotonic)


def _alarm(signum, frame) -> None:
    if _inside and time.monotonic() >= _deadline - TIMER_SLACK:
        raise _TimeUp()
    if callable(_previous_alarm):  # the timer of whoever had SIGALRM before (it ran out first)
        _previous_alarm(signum, frame)
    if _inside:  # their handler returned: our own limit still holds
        signal.setitimer(signal.ITIMER_REAL, max(_deadline - time.monotonic(), TIMER_SLACK))


def _install_alarm() -> None:
    global _previous_alarm
    current = _signal.getsignal(SIGALRM)  # the C function: signal.getsignal's enum costs microseconds
    if current is not _alarm:
        _previous_alarm = current
        signal.signal(signal.SIGALRM, _alarm)
        # the backstop: SIGVTALRM's default action ends the process (signal(7)); nothing may catch it
        signal.signal(signal.SIGVTALRM, signal.SIG_DFL)


_statm = None  # a file descriptor on /proc/self/statm (read with pread: no open per call) ...
_statm_pid = 0  # ... of this process: a forked worker opens its own (the parent's would read the parent)
_space = (0.0, 0)  # (when, bytes): the address space, measured at most every SPACE_SECONDS
SPACE_SECONDS = 1.0
SPACE_SLACK = 256 << 20  # what the process may have grown since it was measured


def _address_space(now: float) -> int | None:
    global _statm, _statm_pid, _space
    if now - _space[0] < SPACE_SECONDS and _statm_pid == os.getpid():
        return _space[1]
    try:
        if _statm is None or _statm_pid != os.getpid():
            _statm, _statm_pid = os.open("/proc/self/statm", os.O_RDONLY), os.getpid()
        _space = (now, int(os.pread(_statm, 64, 0).split()[0]) * _PAGE)
    except (OSError, ValueError, IndexError):  # no /proc: no memory guard
        return None
    return _space[1]


def _limit_memory(now: float) -> tuple[int, int] | None:
    """Lower RLIMIT_AS to the address space + USER_MEMORY_BYTES (+ SPACE_SLACK for growth since it
    was measured); the limits before, to restore."""
    space = _address_space(now)
    if space is None:
        return None
    before = resource.getrlimit(resource.RLIMIT_AS) if _rlimit is None else _rlimit
    limit = space + USER_MEMORY_BYTES + SPACE_SLACK
    soft, hard = before
    if (soft != resource.RLIM_INFINITY and soft <= limit) or (hard != resource.RLIM_INFINITY and hard < limit):
        return None
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    return before


_rlimit = None  # RLIMIT_AS outside guarded calls, read once per process


def call_guarded(function: Callable, label: str, seconds: float, args: tuple, kwargs: dict,
                 faults_only: bool = True, case: str | None = None):
    """Call a user's function under the guards; a fault becomes a UserCodeError naming `label` and the
    case (`case`, or else the arguments)."""
    global _inside, _rlimit, _deadline
    if _inside:  # a guarded function calling another: the outer guard already holds
        return function(*args, **kwargs)
    timed = threading.current_thread() is threading.main_thread()
    previous_timer = memory = None
    started = time.monotonic()
    try:
        try:
            if timed:
                _install_alarm()
                _deadline = started + seconds
                previous_timer = signal.setitimer(signal.ITIMER_REAL, seconds)
                if 0 < previous_timer[0] < seconds:  # someone else's timer runs out first: it keeps its time
                    signal.setitimer(signal.ITIMER_REAL, previous_timer[0])
                signal.setitimer(signal.ITIMER_VIRTUAL, seconds + GRACE_SECONDS)
            if _rlimit is None:
                _rlimit = resource.getrlimit(resource.RLIMIT_AS)
            memory = _limit_memory(started)
            _inside = True
            return function(*args, **kwargs)
        finally:
            _inside = False
            if memory is not None:
                resource.setrlimit(resource.RLIMIT_AS, memory)
            if timed:
                signal.setitimer(signal.ITIMER_VIRTUAL, 0)
                signal.setitimer(signal.ITIMER_REAL, 0)
                if previous_timer[0] > 0:  # someone else's timer was running: let it go on
                    remaining = previous_timer[0] - (time.monotonic() - started)
                    signal.setitimer(signal.ITIMER_REAL, max(remaining, 1e-3), previous_timer[1])
    except _TimeUp:
        reason = f"took more than {seconds:g} s (raise the limit with time_limit)"
    except _Exited as exc:
        reason = exc.how
    except SystemExit as exc:
        reason = f"called sys.exit({shown(exc.code)})"
    except KeyboardInterrupt:
        raise
    except RecursionError:
        reason = "recursed without end (RecursionError)"
    except MemoryError:
        reason = f"allocated more than {USER_MEMORY_BYTES >> 20} MiB (MemoryError)"
    except Exception as exc:
        if faults_only:
            raise
        reason = f"raised {type(exc).__name__}: {str(exc)[:200]}"
    except BaseException as exc:  # GeneratorExit and the like, raised by hand
        reason = f"raised {type(exc).__name__}"
    called = f" ({case})" if case else f" (called with {describe_call(args, kwargs)})" if args or kwargs else ""
    raise UserCodeError(f"{label} {reason}{called}") from None


class _GuardedIterator:
    """A user's iterator (a generator function's result) whose every step runs under the guard."""

    def __init__(self, iterator: Iterator, label: str, seconds: float) -> None:
        self._iterator, self._label, self._seconds, self._step = iterator, label, seconds, 0

    def __iter__(self):
        return self

    def __next__(self):
        self._step += 1
        item = call_guarded(next, f"{self._label} (item {self._step})", self._seconds, (self._iterator, _END), {},
                            faults_only=False, case="while making it")
        if item is _END:
            raise StopIteration
        return item


_END = object()  # what next() gives at the end of a user's iterator (StopIteration is no fault)


def guarded(function: Callable, label: str, seconds: float = DEFAULT_SECONDS, *, faults_only: bool = True) -> Callable:
    """`function` under the guards (`label` names it in errors: `spec.toml: reference.function
    refs.py:ref`). An iterator it returns (a generator function, a class with __iter__) is iterated
    under the guard too."""
    if getattr(function, "_retro_guarded", False):
        return function

    @functools.wraps(function)
    def call(*args, **kwargs):
        result = call_guarded(function, label, seconds, args, kwargs, faults_only)
        if isinstance(result, _PLAIN) or result is None or isinstance(result, (int, float, np.generic)):
            return result
        if not hasattr(result, "__iter__"):
            return result
        iterator = call_guarded(iter, label, seconds, (result,), {}, faults_only=False)
        return _GuardedIterator(iterator, label, seconds)

    call._retro_guarded = True
    return call


def import_guarded(load: Callable, label: str, seconds: float = DEFAULT_SECONDS):
    """Run a user's module (import) under the guards: any failure is one line."""
    return call_guarded(load, label, seconds, (), {}, faults_only=True)


def bytes_of(made, label: str, most: int) -> tuple[int, ...]:
    """A generator's bytes, checked by size before they are converted (a 256 MB answer is refused as
    it is, not after it became a list of Python ints): 1..`most` whole numbers 0..255."""
    if isinstance(made, np.ndarray):
        size = made.size
        whole = made.dtype != bool and np.issubdtype(made.dtype, np.integer)
    elif isinstance(made, (bytes, bytearray)):
        return tuple(made) if 0 < len(made) <= most else _too_many(label, len(made), most)
    else:
        try:
            size = len(made)
        except TypeError:
            raise UserCodeError(f"{label} returned {shown(made)}: expected a sequence of bytes") from None
        whole = None
    if not 0 < size <= most:
        _too_many(label, size, most)
    if whole is not None:
        if not whole or made.ndim != 1:
            raise UserCodeError(f"{label} returned an array of shape {made.shape} ({made.dtype}): expected "
                                "one row of whole numbers 0..255")
        values = made.astype(np.int64)
        if values.min() < 0 or values.max() > 0xFF:
            bad = int(values.min() if values.min() < 0 else values.max())
            raise UserCodeError(f"{label} returned {bad}: bytes are 0..255")
        return tuple(values.tolist())
    out = []
    for i, value in enumerate(made):
        if isinstance(value, np.integer):
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 0xFF:
            raise UserCodeError(f"{label} returned {shown(value)} at index {i}: bytes are whole numbers 0..255")
        out.append(value)
    return tuple(out)


def _too_many(label: str, size: int, most: int):
    raise UserCodeError(f"{label} returned {size:,} bytes: expected 1 to {most:,}")


def time_limit(fields, doc: dict, field: str) -> int:
    """The `time_limit` key of a table (seconds per call of the user's functions), checked by `fields`."""
    if "time_limit" not in doc:
        return DEFAULT_SECONDS
    return fields.integer(doc["time_limit"], f"{field}.time_limit", 1, MAX_SECONDS)
