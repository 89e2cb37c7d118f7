"""Measure each method's 6502 cost in the emulator: cycles per test on the corpus inputs, bytes.

For every pair, an evenly spread sample of its cases is turned into the inputs of the method's
routine (per the calling conventions in the asm/ headers, see routine_inputs.py), the routine is
called in py65, and its cycles (first instruction through RTS, the caller's JSR excluded) are
recorded. Every call's answer is compared with the study's verdict for that case: a mismatch means
the study does not model the routine it charges for, and is an error, not a statistic.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from itertools import combinations_with_replacement

from retro.analysis.study.corpus import Pair, Shape, make_pair
from retro.analysis.study.costs import CycleStats, MethodCost
from retro.analysis.study.evaluate import Progress, default_workers, quiet
from retro.analysis.study.host_timing import host_microseconds
from retro.analysis.study.methods import METHODS
from retro.analysis.study.routine_inputs import ADAPTERS, Adapter
from retro.errors import RunError


def sample_indices(pair: Pair, samples: int) -> list[int]:
    """`samples` case indices spread evenly over the pair's cases (all of them if fewer)."""
    if samples >= pair.cases:
        return list(range(pair.cases))
    return [round(i * (pair.cases - 1) / (samples - 1)) for i in range(samples)] if samples > 1 else [0]


def _measure_pair(adapter_key: str, a: Shape, b: Shape, samples: int) -> tuple[str, list[int]]:
    adapter = ADAPTERS[adapter_key]
    pair = make_pair(a, b)
    session = adapter.session(pair)
    cycles = []
    for index in sample_indices(pair, samples):
        answer, expected, spent = session.run(index)
        if answer != expected:
            raise RunError(f"{adapter.routine}: on {pair.name} at offset ({int(pair.dx[index])}, {int(pair.dy[index])}) "
                           f"the routine says {answer}, the study's {adapter_key} method says {expected}")
        cycles.append(spent)
    return pair.name, cycles


def measure_costs(shapes: list[Shape], samples: int, workers: int | None = None, progress: Progress = quiet,
                  pair_list: list[tuple[Shape, Shape]] | None = None) -> dict[str, MethodCost]:
    """MethodCost for every method; a method whose routine is missing gets no cycles and says so."""
    jobs = pair_list if pair_list is not None else list(combinations_with_replacement(shapes, 2))
    workers = default_workers() if workers is None else workers
    costs: dict[str, MethodCost] = {}
    pairs = [make_pair(a, b) for a, b in jobs]
    for m in METHODS:
        adapter: Adapter | None = ADAPTERS.get(m.key)
        host = host_microseconds(m.key, pairs, max(4, samples // 4))
        if m.host_only or adapter is None:
            why = "host-only: no 6502 routine exists for it"
            costs[m.key] = MethodCost(key=m.key, routine="", overall=CycleStats.of([]), host_us=host, counted=why)
            continue
        per_pair: dict[str, CycleStats] = {}
        every: list[int] = []
        if workers > 1 and len(jobs) > 1:
            with ProcessPoolExecutor(max_workers=workers) as pool:
                futures = [pool.submit(_measure_pair, m.key, a, b, samples) for a, b in jobs]
                results = [f.result() for f in futures]
        else:
            results = [_measure_pair(m.key, a, b, samples) for a, b in jobs]
        for name, cycles in results:
            per_pair[name] = CycleStats.of(cycles)
            every += cycles
        code, tables = adapter.size()
        costs[m.key] = MethodCost(key=m.key, routine=adapter.routine, overall=CycleStats.of(every), per_pair=per_pair,
                                  code_bytes=code, table_bytes=tables, host_us=host, counted=adapter.counted)
        progress(f"cost: {m.key} ({adapter.routine}) {len(every)} calls, mean {sum(every) / len(every):.1f} cycles")
    return costs
