"""Host microseconds per test of each method's Python reference (a secondary figure: the 6502
cycles are the primary cost). Median over repeated timings of the sampled cases, this host, one core.
The calls themselves come from the method (`Method.host_calls`)."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

from retro.analysis.study.corpus import Pair

REPEATS = 5


def _time_per_call(calls: list[Callable[[], object]]) -> float:
    """Median over REPEATS of (time to run every call once) / number of calls, in microseconds."""
    runs = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        for call in calls:
            call()
        runs.append((time.perf_counter() - start) / len(calls) * 1e6)
    return statistics.median(runs)


def host_microseconds(method, pairs: list[Pair], samples: int) -> float:
    calls: list[Callable[[], object]] = []
    for pair in pairs:
        step = max(1, pair.cases // samples)
        calls += method.host_calls(pair, list(range(0, pair.cases, step))[:samples])
    return _time_per_call(calls) if calls else float("nan")
