"""Measure each method's 6502 cost in the emulator: cycles per test on the corpus inputs, bytes.

For every pair, the method's routine is called in py65 on the pair's cases (every case, or an
evenly spread sample), with the inputs the method makes of each case (`Method.case_maker`, passed
through the routine's spec), and its cycles (first instruction through RTS, the caller's JSR
excluded) are recorded. Every call's answer is compared with the method's verdict for that case: a
mismatch means the study does not model the routine it charges for, and is an error, not a
statistic. The verdict is computed on the measured cases only.
"""

from __future__ import annotations

from itertools import combinations_with_replacement

from retro.analysis.study.corpus import Pair, Shape, make_pair
from retro.analysis.study.costs import CycleStats, MethodCost
from retro.progress import Progress, quiet
from retro.analysis.study.host_timing import host_microseconds
from retro.analysis.study.methods import METHODS, Method, sub_pair
from retro.errors import RunError
from retro.workers import Workers, only, run_in_order

HOST_SAMPLES = 48  # cases per pair timed on the host (a secondary figure)


def sample_indices(pair: Pair, samples: int | None) -> list[int]:
    """`samples` case indices spread evenly over the pair's cases (all of them if None or fewer)."""
    if samples is None or samples >= pair.cases:
        return list(range(pair.cases))
    return [round(i * (pair.cases - 1) / (samples - 1)) for i in range(samples)] if samples > 1 else [0]


def method_samples(method: Method, samples: int | None) -> int | None:
    """The cases per pair measured for a method: the run's figure, capped by the method's own."""
    cap = method.max_cost_samples
    if cap is None:
        return samples
    return cap if samples is None else min(samples, cap)


def _measure_pair(method: Method, a: Shape, b: Shape, samples: int | None,
                  engine: str = "auto") -> tuple[str, list[int]]:
    pair = make_pair(a, b)
    if method.unmeasurable(pair):
        return pair.name, []
    indices = sample_indices(pair, method_samples(method, samples))
    session = method.session(pair)
    verdict = None if method.averaged else method.verdict(sub_pair(pair, indices)) > 0
    cycles = []
    answers, spent_cycles = session.run_many(indices, engine)
    for k, (index, answer, spent) in enumerate(zip(indices, answers, spent_cycles)):
        expected = session.expected(index) if verdict is None else bool(verdict[k])
        if answer != expected:
            raise RunError(f"{method.routine}: on {pair.name} at offset ({int(pair.dx[index])}, {int(pair.dy[index])}) "
                           f"the routine says {answer}, the rule of method {method.key} says {expected}")
        cycles.append(spent)
    return pair.name, cycles


def measure_costs(shapes: list[Shape], samples: int | None, workers: Workers | int | None = None, progress: Progress = quiet,
                  pair_list: list[tuple[Shape, Shape]] | None = None,
                  methods: tuple[Method, ...] = METHODS, engine: str = "auto") -> dict[str, MethodCost]:
    """MethodCost for every method; a host-only method gets no cycles and says so. `samples`: cases
    measured per pair (None: every case)."""
    jobs = pair_list if pair_list is not None else list(combinations_with_replacement(shapes, 2))
    pairs = [make_pair(a, b) for a, b in jobs]
    measured = [m for m in methods if not m.host_only]
    tasks = [(m, a, b) for m in measured for a, b in jobs]
    results = _run_pairs(tasks, samples, engine, workers, len(jobs), progress)
    by_method = {m.key: results[i * len(jobs):(i + 1) * len(jobs)] for i, m in enumerate(measured)}
    return {m.key: _method_cost(m, pairs, jobs, by_method.get(m.key, []), samples) for m in methods}


def _run_pairs(tasks: list, samples: int | None, engine: str, workers: Workers | int | None, per_method: int,
               progress: Progress) -> list[tuple[str, list[int]]]:
    """Each (method, shape, shape) measured, in order, over `workers` (retro.workers) when more than one."""
    results = []

    def report(result: tuple[str, list[int]]) -> None:
        results.append(result)
        if len(results) % per_method == 0:
            m = tasks[len(results) - 1][0]
            progress(f"cost: {m.key} ({m.routine}) measured on {per_method} pairs")
    run_in_order(_measure_pair, ((m, a, b, samples, engine) for m, a, b in tasks), only(workers, len(tasks) > 1),
                 report)
    return results


def _method_cost(m: Method, pairs: list, jobs: list, measured: list[tuple[str, list[int]]],
                 samples: int | None) -> MethodCost:
    """One method's cycles per pair and overall, bytes and host time (no cycles for a host-only one)."""
    host = host_microseconds(m, pairs, HOST_SAMPLES if samples is None else max(4, samples // 4))
    if m.host_only:
        return MethodCost(key=m.key, routine="", overall=CycleStats.of([]), host_us=host, counted=m.counted)
    per_pair: dict[str, CycleStats] = {}
    every: list[int] = []
    skipped = []
    for (name, cycles), (a, b) in zip(measured, jobs):
        per_pair[name] = CycleStats.of(cycles)
        every += cycles
        if not cycles:
            skipped.append(f"{name} ({m.unmeasurable(make_pair(a, b))})")
    code, tables = m.size()
    counted = m.counted + (f"; not measured on {', '.join(skipped)}" if skipped else "")
    return MethodCost(key=m.key, routine=m.routine, overall=CycleStats.of(every), per_pair=per_pair,
                      code_bytes=code, table_bytes=tables, host_us=host, counted=counted, prepare=m.prepare)
