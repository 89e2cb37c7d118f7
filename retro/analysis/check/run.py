"""A whole check: the case plan, chunks over worker processes, the engine agreement, the totals and
the verdicts of bounds and budget."""

from __future__ import annotations

import os
import time
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from itertools import islice

from retro.analysis.check import engines
from retro.analysis.check.engines import (
    AGREEMENT_PER_PART,
    AUTO_BATCH_CASES,
    BATCH_LANES,
    ENGINES,
    SceneStart,
    agreement_chunk,
    check_batch,
    check_chunk,
    failure_trace,
    routine_key,
    routine_of,
    runner_for,
)
from retro.analysis.check.results import ChunkResult, PartRun, RoutineCheck, describe_case
from retro.analysis.check.verdicts import static_bounds
from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines.registry import select
from retro.routines.spec import Routine
from retro.workers import worker_pool

PROGRESS_SECONDS = 1.0  # at most one progress line a second


def _run_work(work: Iterator[tuple], jobs: int, report: Callable[[ChunkResult], None],
              stop: Callable[[], int]) -> None:
    """Run (function, arguments) items in order, over `jobs` worker processes when more than one,
    with at most 2 * jobs items in flight; stop early once `stop()` is true (a run error)."""
    if jobs <= 1:
        for function, arguments in work:
            report(function(*arguments))
            if stop():
                return
        return
    pool = worker_pool(jobs)
    pending: deque[Future] = deque()
    try:
        for function, arguments in work:
            pending.append(pool.submit(function, *arguments))
            if len(pending) >= 2 * jobs:  # bounded: cases are made as workers take them
                report(pending.popleft().result())  # in order: ties (first fastest case) do not depend on timing
            if stop():
                break
        while pending:
            report(pending.popleft().result())
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _chunks(parts: list[case_sets.Part]) -> Iterator[list[tuple]]:
    for part in parts:
        yield from case_sets.chunks(part.cases)


def check_routine(spec: str | Routine, *, exhaustive: bool = False, seed: int | None = None,
                  random_count: int | None = None, jobs: int = 1, progress: Callable[[str], None] | None = None,
                  start: SceneStart | None = None, bounded_product: int = case_sets.BOUNDED_PRODUCT,
                  engine: str | None = None) -> RoutineCheck:
    """Check one routine: a spec path, or a Routine built in Python (then in this process only).
    `engine`: "scalar" (Machine), "batch" (the batched core, checked against Machine on the first
    AGREEMENT_PER_PART cases of each part) or "auto" (batch from AUTO_BATCH_CASES planned cases)."""
    engine = engines.DEFAULT_ENGINE if engine is None else engine
    if engine not in ENGINES:
        raise InputError(f"--engine: {engine!r} is not one of {', '.join(ENGINES)}")
    if isinstance(spec, Routine):
        jobs = 1
    spec = routine_key(spec)
    routine = routine_of(spec)
    seed = routine.seed if seed is None else seed
    parts = case_sets.plan(routine, exhaustive=exhaustive, seed=seed, random=random_count,
                           bounded_product=bounded_product)
    known = sum(p.count for p in parts if p.count is not None)
    unknown = any(p.count is None for p in parts)
    runner = runner_for(spec, seed, start)  # loads and validates in this process before any worker starts
    if engine == "batch" and not runner.batchable:
        raise InputError("--engine batch: with --scene the calls run on Machine (the batched core models no chips); "
                         "use --engine scalar or auto")
    batched = runner.batchable and (engine == "batch" or (engine == "auto" and (unknown or known >= AUTO_BATCH_CASES)))
    totals = ChunkResult()
    done = 0
    shown = [time.monotonic()]

    def report(result: ChunkResult) -> None:
        nonlocal done
        totals.merge(result)
        done += result.cases
        now = time.monotonic()
        if progress and now - shown[0] >= PROGRESS_SECONDS:
            shown[0] = now
            progress(f"check {routine.name}: {done:,} cases ({known:,} planned, plus the sweep)" if unknown else
                     f"check {routine.name}: {done:,}/{known:,} cases")

    agreement = None
    if batched:
        agreement = ChunkResult()
        for part in parts:  # Machine first: the reference engine's verdict on a prefix of every part
            for chunk in case_sets.chunks(islice(part.cases, AGREEMENT_PER_PART)):
                agreement.merge(agreement_chunk(spec, seed, chunk))
                if agreement.run_errors:
                    break
        work = ((check_batch, (spec, seed, block)) for block in case_sets.batches(parts, BATCH_LANES))
    else:
        work = ((check_chunk, (spec, seed, chunk, start)) for chunk in _chunks(parts))
    _run_work(work, jobs if (known > case_sets.CHUNK or unknown) else 1, report, lambda: totals.run_errors)
    part_runs = [PartRun(p.name, p.count if p.count is not None else 0, p.total) for p in parts]
    if unknown:  # the sweep's count is whatever was left after the counted parts
        counted = sum(p.cases for p in part_runs if p.name != "sweep")
        part_runs = [PartRun(p.name, max(totals.cases - counted, 0), max(totals.cases - counted, 0))
                     if p.name == "sweep" else p for p in part_runs]
    static = static_bounds(routine, runner)
    violations = []
    t = totals
    if static is not None and t.cycles_count and t.cpu_min < static.best:
        violations.append(f"{routine.name}: measured minimum {t.cpu_min} is below the static best case {static.best}")
    if static is not None and t.cycles_count and t.cpu_max > static.worst:
        violations.append(f"{routine.name}: measured maximum {t.cpu_max} is above the static worst case {static.worst}")
    budget_violations = []
    if routine.budget is not None:
        if t.cycles_count and t.cycles_max > routine.budget:
            budget_violations.append(f"{routine.name}: measured maximum {t.cycles_max} cycles is over the budget of "
                                     f"{routine.budget} (inputs {describe_case(routine, t.max_case)})")
        if static is not None and static.worst > routine.budget:
            budget_violations.append(f"{routine.name}: the static worst case {static.worst} cycles is over the budget "
                                     f"of {routine.budget}")
    check = RoutineCheck(routine, runner.size(), static, totals, violations, budget_violations, part_runs,
                         start=runner.start, engine="batch" if batched else "scalar", agreement=agreement)
    if agreement is not None and agreement.failure is not None and totals.failure is None:
        totals.failure = agreement.failure  # the timing model or the engines disagreed on a call
    if totals.failure is not None:
        check.trace = failure_trace(spec, seed, totals.failure.case, start)
    return check


def default_jobs() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def run_checks(names: list[str] | None, *, exhaustive: bool = False, seed: int | None = None,
               random_count: int | None = None, jobs: int | None = None,
               progress: Callable[[str], None] | None = None, start: SceneStart | None = None,
               bounded_product: int = case_sets.BOUNDED_PRODUCT, engine: str | None = None) -> list[RoutineCheck]:
    """Check the named routines (built-in names or spec paths; all built-ins when none are named);
    every name is loaded and validated before any work starts."""
    specs = select(names)
    workers = default_jobs() if jobs is None else jobs
    return [check_routine(spec, exhaustive=exhaustive, seed=seed, random_count=random_count, jobs=workers,
                          progress=progress, start=start, bounded_product=bounded_product, engine=engine)
            for spec in specs]

