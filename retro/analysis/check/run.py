"""A whole check: the case plan, blocks of calls over worker processes on the engine the one rule
picks, the engine agreement, the totals and the verdicts of bounds and budget."""

from __future__ import annotations

import os
import time
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from itertools import islice

from retro.analysis.check.engines import (
    AGREEMENT_PER_PART,
    AUTO_BATCH_CASES,
    BATCH_LANES,
    SceneStart,
    batched,
    check_engine,
    failure_trace,
    routine_key,
    routine_of,
    run_on_batched_core,
    run_on_machine,
    runner_for,
)
from retro.analysis.check.results import PartRun, RoutineCheck
from retro.analysis.check.tally import Tally, count_block
from retro.analysis.check.verdicts import bounds_violations, budget_violations, static_bounds
from retro.analysis.row_check import RowsCheck, check_rows, merged_agreement, rows_only_static
from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines.registry import select
from retro.routines.spec import Routine
from retro.routines.where import require_inside
from retro.workers import worker_pool

PROGRESS_SECONDS = 1.0  # at most one progress line a second


# ---- what a worker does: one block of calls, tallied ------------------------------------------------

def machine_chunk(spec: str, seed: int, cases: list[tuple], start: SceneStart | None = None) -> Tally:
    """Cases on Machine, tallied (a pure function of its arguments, run in worker processes)."""
    runner = runner_for(spec, seed, start)
    columns = case_sets.cases_to_columns(runner.routine, cases)
    return count_block(runner.routine, run_on_machine(runner, cases), columns, cases, runner.memory_values)


def batch_chunk(spec: str, seed: int, columns: list, start: SceneStart | None = None) -> Tally:
    """A column block on the batched core, tallied (run in worker processes)."""
    runner = runner_for(spec, seed, start)
    return count_block(runner.routine, run_on_batched_core(runner, columns), columns, None, runner.memory_values)


def agreement_chunk(spec: str, seed: int, cases: list[tuple], start: SceneStart | None = None) -> Tally:
    """Cases on both engines: Machine's tally (timing model included), its block compared with the
    batched core's call for call."""
    runner = runner_for(spec, seed, start)
    columns = case_sets.cases_to_columns(runner.routine, cases)
    against = run_on_batched_core(runner, columns, confirm_stop=False)
    return count_block(runner.routine, run_on_machine(runner, cases), columns, cases, runner.memory_values, against)


# ---- a whole check ------------------------------------------------------------------------------------

def _run_work(work: Iterator[tuple], jobs: int, report: Callable[[Tally], None],
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


def _reporter(routine: Routine, totals: Tally, known: int, unknown: bool,
              progress: Callable[[str], None] | None) -> Callable[[Tally], None]:
    """Merge a block's tally into the totals, with at most one progress line a second."""
    done = 0
    shown = time.monotonic()

    def report(result: Tally) -> None:
        nonlocal done, shown
        totals.merge(result)
        done += result.cases
        now = time.monotonic()
        if progress and now - shown >= PROGRESS_SECONDS:
            shown = now
            progress(f"check {routine.name}: {done:,} cases ({known:,} planned, plus the sweep)" if unknown else
                     f"check {routine.name}: {done:,}/{known:,} cases")
    return report


def _agreement(spec: str, seed: int, parts: list[case_sets.Part], start: SceneStart | None = None) -> Tally:
    """Machine first: the reference engine's verdict on a prefix of every part, both engines compared."""
    agreement = Tally()
    for part in parts:
        for chunk in case_sets.chunks(islice(part.cases, AGREEMENT_PER_PART)):
            agreement.merge(agreement_chunk(spec, seed, chunk, start))
            if agreement.run_errors:
                break
    return agreement


def _part_runs(parts: list[case_sets.Part], totals: Tally, unknown: bool, rows: RowsCheck | None) -> list[PartRun]:
    part_runs = [PartRun(p.name, p.count if p.count is not None else 0, p.total) for p in parts]
    if rows is not None:  # the rows ran first, as a part of their own
        part_runs.insert(0, PartRun("rows", sum(o.checked for o in rows.outcomes), len(rows.outcomes)))
    if unknown:  # the sweep's count is whatever was left after the counted parts
        counted = sum(p.cases for p in part_runs if p.name != "sweep")
        part_runs = [PartRun(p.name, max(totals.cases - counted, 0), max(totals.cases - counted, 0))
                     if p.name == "sweep" else p for p in part_runs]
    return part_runs


def check_routine(spec: str | Routine, *, exhaustive: bool = False, seed: int | None = None,
                  random_count: int | None = None, jobs: int = 1, progress: Callable[[str], None] | None = None,
                  start: SceneStart | None = None, bounded_product: int = case_sets.BOUNDED_PRODUCT,
                  engine: str = "auto") -> RoutineCheck:
    """Check one routine: a spec path, or a Routine built in Python (then in this process only).
    `engine`: "scalar" (Machine), "batch" (the batched core, checked against Machine on the first
    AGREEMENT_PER_PART cases of each part) or "auto" (batch from AUTO_BATCH_CASES planned cases)."""
    began = time.monotonic()
    check_engine(engine)
    if isinstance(spec, Routine):
        jobs = 1
    spec = routine_key(spec)
    routine = routine_of(spec)
    seed = routine.seed if seed is None else seed
    if routine.reference is None:  # rows only: no answer is known for a generated case, whatever --random says
        random_count = 0
    parts = case_sets.plan(routine, exhaustive=exhaustive, seed=seed, random=random_count,
                           bounded_product=bounded_product)
    known = sum(p.count for p in parts if p.count is not None)
    unknown = any(p.count is None for p in parts)
    runner = runner_for(spec, seed, start)  # loads and validates in this process before any worker starts
    on_batch = batched(engine, None if unknown else known, runner.batchable, AUTO_BATCH_CASES)
    if engine == "batch" and not on_batch:
        raise InputError(f"--engine batch: with --scene the calls of {routine.name} run on Machine "
                         f"({runner.engine_reason}); use --engine scalar or auto")
    totals = Tally()
    report = _reporter(routine, totals, known, unknown, progress)
    rows = None
    if routine.rows:  # the spec's expected rows run first, in this process (retro.analysis.row_check)
        rows, rows_totals = check_rows(spec, seed, start, on_batch)
        report(rows_totals)
        if totals.run_errors:  # a row's call that stopped stops the check
            parts = []
    agreement = _agreement(spec, seed, parts, start) if on_batch else None
    work = (((batch_chunk, (spec, seed, block, start)) for block in case_sets.batches(parts, BATCH_LANES)) if on_batch else
            ((machine_chunk, (spec, seed, chunk, start)) for chunk in _chunks(parts)))
    _run_work(work, jobs if (known > case_sets.CHUNK or unknown) else 1, report, lambda: totals.run_errors)
    require_inside(f"{routine.spec_path}: cases.where", routine.domain, totals.cases, totals.outside,
                   totals.constraint_cases)
    if routine.reference is None:  # rows only: unknown static bounds are said, not an error
        static, rows.static_note = rows_only_static(routine, runner)
    else:
        static = static_bounds(routine, runner)
    check = RoutineCheck(routine, runner.size(), static, totals, bounds_violations(routine, static, totals),
                         budget_violations(routine, static, totals), _part_runs(parts, totals, unknown, rows),
                         start=runner.start, engine="batch" if on_batch else "scalar", agreement=agreement, rows=rows,
                         engine_reason=runner.engine_reason)
    if rows is not None and rows.agreement is not None:
        check.agreement = agreement = merged_agreement(agreement, rows)
    if agreement is not None and agreement.failure is not None and totals.failure is None:
        totals.failure = agreement.failure  # the timing model or the engines disagreed on a call
    if totals.failure is not None:
        check.trace = failure_trace(spec, seed, totals.failure.case, start)
    check.seconds = time.monotonic() - began
    return check


def default_jobs() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def run_checks(names: list[str] | None, *, exhaustive: bool = False, seed: int | None = None,
               random_count: int | None = None, jobs: int | None = None,
               progress: Callable[[str], None] | None = None, start: SceneStart | None = None,
               bounded_product: int = case_sets.BOUNDED_PRODUCT, engine: str = "auto") -> list[RoutineCheck]:
    """Check the named routines (built-in names or spec paths; all built-ins when none are named);
    every name is loaded and validated before any work starts."""
    specs = select(names)
    workers = default_jobs() if jobs is None else jobs
    return [check_routine(spec, exhaustive=exhaustive, seed=seed, random_count=random_count, jobs=workers,
                          progress=progress, start=start, bounded_product=bounded_product, engine=engine)
            for spec in specs]
