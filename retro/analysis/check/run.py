"""A whole check: the case plan, blocks of calls over worker processes on the engine the one rule
picks, the engine agreement, the totals and the verdicts of bounds and budget."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from itertools import chain, islice

from retro.analysis.check.engines import (
    AGREEMENT_PER_PART,
    AUTO_BATCH_CASES,
    BATCH_LANES,
    SceneStart,
    array_engine,
    batched,
    check_engine,
    compiled_or_why,
    failure_trace,
    routine_key,
    routine_of,
    run_on_batched_core,
    run_on_machine,
    runner_for,
)
from retro.analysis.check.coverage import completed, worst_path
from retro.analysis.check.entry_runs import (
    VARIANTS,
    entry_block_on_batched_core,
    entry_block_on_machine,
    entry_every,
    name_dependence,
)
from retro.analysis.check.results import PartRun, RoutineCheck
from retro.analysis.check.search import DEFAULT_SEARCH, SearchResult, search
from retro.analysis.check.tally import Tally, count_block
from retro.analysis.check.verdicts import bounds_violations, budget_violations, static_bounds
from retro.analysis.row_check import RowsCheck, check_rows, merged_agreement, rows_only_static
from retro.errors import InputError, RunError
from retro.routines import cases as case_sets
from retro.routines.registry import select
from retro.routines.runner import PROBE_CASES, RoutineRunner
from retro.routines.spec import Routine
from retro.routines.where import require_inside
from retro.workers import Workers, as_workers, only, run_in_order, session

PROGRESS_SECONDS = 1.0  # at most one progress line a second
PARALLEL_CALLS = {"scalar": 200_000, "batch": 2_000_000, "compiled": 2_000_000}  # planned calls from which a check
# runs on workers: at Machine's ~50,000 and the array engines' 1-10 million calls per CPU-second, seconds of work,
# well above a local cluster's start (about 1 CPU-second); a sweep (uncounted, --exhaustive) always does


# ---- what a worker does: one block of calls, tallied ------------------------------------------------

def machine_chunk(spec: str, seed: int, cases: list[tuple], start: SceneStart | None = None, first: int = 0,
                  every: int = 0) -> Tally:
    """Cases on Machine, tallied (a pure function of its arguments, run in worker processes); `first`
    is the index of the first case in the check, and every `every`-th case of the check is run again
    with the entry state varied (0: none)."""
    runner = runner_for(spec, seed, start)
    columns = case_sets.cases_to_columns(runner.routine, cases)
    block = run_on_machine(runner, cases)
    entry = None
    if every:
        entry = entry_block_on_machine(_variants(spec, seed, start), cases[:block.calls], first, every, seed)
    return _named(spec, seed, start, count_block(runner.routine, block, columns, cases, runner.memory_values,
                                                 entry=entry))


def batch_chunk(spec: str, seed: int, columns: list, first: int = 0, every: int = 0, engine: str = "batch",
                start: SceneStart | None = None) -> Tally:
    """A column block on an array engine ("batch" or "compiled"), tallied (run in worker processes);
    `first` and `every` as for machine_chunk (the entry-state runs are the batched core's); `start`:
    the scene, whose stalls the batched core applies per lane."""
    runner = runner_for(spec, seed, start)
    block = run_on_batched_core(runner, columns, engine=engine)
    entry = None
    if every:
        entry = entry_block_on_batched_core(_variants(spec, seed, start), [c[:block.calls] for c in columns], first,
                                            every, seed)
    return _named(spec, seed, start, count_block(runner.routine, block, columns, None, runner.memory_values,
                                                 entry=entry))


def _variants(spec: str, seed: int, start: SceneStart | None) -> dict[str, RoutineRunner]:
    """The runners of the entry-state variants; an `init` that stops on their memory is a run error."""
    runners = {}
    for variant in VARIANTS:
        try:
            runners[variant] = runner_for(spec, seed, start, variant)
        except RunError as exc:
            raise RunError(f"{routine_of(spec).spec_path}: init stops when the memory nothing sets is {variant} "
                           f"instead of 0 (it depends on the entry state): {exc}") from None
    return runners


def _named(spec: str, seed: int, start: SceneStart | None, tally: Tally) -> Tally:
    """Name what the first changed case of each entry-state variant depends on (on Machine)."""
    for variant, finding in tally.entry_first.items():
        if finding.needs is None:
            base = RoutineRunner(routine_of(spec), seed, start.raster_start() if start else None)
            varied = bytes(runner_for(spec, seed, start, variant).call_image)
            finding.needs = name_dependence(base, varied, finding, seed)
    return tally


def agreement_chunk(spec: str, seed: int, cases: list[tuple], engine: str = "batch",
                    start: SceneStart | None = None) -> Tally:
    """Cases on both engines: Machine's tally (timing model included), its block compared with the
    array engine's call for call."""
    runner = runner_for(spec, seed, start)
    columns = case_sets.cases_to_columns(runner.routine, cases)
    against = run_on_batched_core(runner, columns, confirm_stop=False, coverage=False, engine=engine)
    return count_block(runner.routine, run_on_machine(runner, cases, coverage=False), columns, cases,
                       runner.memory_values, against)  # (the array engine counts these cases' coverage)


# ---- a whole check ------------------------------------------------------------------------------------

def _run_work(work: Iterator[tuple], workers: Workers | int, report: Callable[[Tally], None],
              stop: Callable[[], int]) -> None:
    """Run (function, arguments) items in order, on `workers` (retro.workers: this process, or Dask tasks
    with a bounded number in flight); stop early once `stop()` is true (a run error)."""
    def merged(result: Tally) -> bool:
        report(result)
        return bool(stop())
    run_in_order(_call, work, workers, merged)


def _call(function: Callable, arguments: tuple) -> Tally:
    return function(*arguments)


def _chunks(parts: list[case_sets.Part]) -> Iterator[tuple[list[tuple], int]]:
    """The parts' cases in chunks, each with the index of its first case in the check."""
    first = 0
    for part in parts:
        for chunk in case_sets.chunks(part.cases):
            yield chunk, first
            first += len(chunk)


def _blocks(parts: list[case_sets.Part]) -> Iterator[tuple[list, int]]:
    """The parts' cases in column blocks for the batched core, each with its first case's index."""
    first = 0
    for block in case_sets.batches(parts, BATCH_LANES):
        yield block, first
        first += len(block[0])


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


def _agreement(spec: str, seed: int, parts: list[case_sets.Part], engine: str,
               start: SceneStart | None = None) -> Tally:
    """Machine first: the reference engine's verdict on a prefix of every part, both engines compared."""
    agreement = Tally()
    for part in parts:
        for chunk in case_sets.chunks(islice(part.cases, AGREEMENT_PER_PART)):
            agreement.merge(agreement_chunk(spec, seed, chunk, engine, start))
            if agreement.run_errors:
                break
    return agreement


def _part_runs(parts: list[case_sets.Part], totals: Tally, unknown: bool, rows: RowsCheck | None) -> list[PartRun]:
    part_runs = [PartRun(p.name, p.count if p.count is not None else 0, p.total, p.inside) for p in parts]
    if rows is not None:  # the rows ran first, as a part of their own
        part_runs.insert(0, PartRun("rows", sum(o.checked for o in rows.outcomes), len(rows.outcomes)))
    if unknown:  # the sweep's count is whatever was left after the counted parts
        counted = sum(p.cases for p in part_runs if p.name != "sweep")
        part_runs = [PartRun(p.name, max(totals.cases - counted, 0), max(totals.cases - counted, 0))
                     if p.name == "sweep" else p for p in part_runs]
    return part_runs


def check_routine(spec: str | Routine, *, exhaustive: bool = False, seed: int | None = None,
                  random_count: int | None = None, jobs: Workers | int = 1, progress: Callable[[str], None] | None = None,
                  start: SceneStart | None = None, bounded_product: int = case_sets.BOUNDED_PRODUCT,
                  engine: str = "auto", search_budget: int | None = None, entry_state: bool = True) -> RoutineCheck:
    """Check one routine: a spec path, or a Routine built in Python (then in this process only).
    `engine`: "scalar" (Machine), "batch" (the batched core, checked against Machine on the first
    AGREEMENT_PER_PART cases of each part) or "auto" (batch from AUTO_BATCH_CASES planned cases).
    `search_budget`: candidates the coverage-guided search may run after the planned cases (None:
    the spec's `[cases] search`, else DEFAULT_SEARCH; 0: no search). `entry_state`: also run a sample
    of the cases with the entry state the spec leaves arbitrary varied (retro.analysis.check.entry_runs)."""
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
    refusal = runner.batch_refusal if runner.vic is None else None
    engine_note = ""
    if refusal is not None and batched(engine, None if unknown else known, True, AUTO_BATCH_CASES):
        engine_note = f"Machine ran the calls: {refusal}"  # the batched core would have: say why not
    elif engine in ("batch", "compiled") and not on_batch:
        raise InputError(f"--engine {engine}: with --scene the calls of {routine.name} run on Machine "
                         f"({runner.engine_reason}); use --engine scalar or auto")
    used, reason = ("scalar", runner.engine_reason if start is not None else
                    engine_note or (f"{engine}: {known:,} planned calls" if engine == "auto" else f"--engine {engine}"))
    compile_seconds = None
    if on_batch:
        used, reason = array_engine(engine, None if unknown else known)
        if start is not None:
            reason = runner.engine_reason
        if used == "compiled":
            refused = compiled_or_why(runner)
            if refused is not None:
                used, reason = "batch", f"the compiled engine does not take it: {refused}"
            else:
                compile_seconds = runner.compiled().compile_seconds
    totals = Tally()
    report = _reporter(routine, totals, known, unknown, progress)
    rows = None
    if routine.rows:  # the spec's expected rows run first, in this process (retro.analysis.row_check)
        rows, rows_totals = check_rows(spec, seed, start, on_batch)
        report(rows_totals)
        if totals.run_errors:  # a row's call that stopped stops the check
            parts = []
    agreement = _agreement(spec, seed, parts, used, start) if on_batch else None
    every = entry_every(known, exhaustive, bounded_product, unknown) if entry_state and parts else 0
    work = (((batch_chunk, (spec, seed, block, first, every, used, start)) for block, first in _blocks(parts))
            if on_batch else
            ((machine_chunk, (spec, seed, chunk, start, first, every)) for chunk, first in _chunks(parts)))
    _run_work(work, only(jobs, unknown or known >= PARALLEL_CALLS[used]), report, lambda: totals.run_errors)
    searched = _search(spec, seed, runner, on_batch, totals, search_budget)
    if searched.found:  # the search's cases, checked like every other case
        found = case_sets.cases_to_columns(routine, searched.found)
        parts.append(case_sets.Part("search", len(searched.found), len(searched.found), lambda: iter([found])))
        if on_batch:
            agreement.merge(_agreement(spec, seed, parts[-1:], "batch", start))
        work = (((batch_chunk, (spec, seed, block, 0, 0, "batch", start))
                 for block in case_sets.batches(parts[-1:], BATCH_LANES))
                if on_batch else ((machine_chunk, (spec, seed, chunk, start)) for chunk, _ in _chunks(parts[-1:])))
        _run_work(work, 1, report, lambda: totals.run_errors)
    require_inside(f"{routine.spec_path}: cases.where", routine.domain, totals.cases, totals.outside,
                   totals.constraint_cases)
    if routine.reference is None:  # rows only: unknown static bounds are said, not an error
        static, rows.static_note = rows_only_static(routine, runner)
    else:
        static = static_bounds(routine, runner)
    probe = chain((row.case for row in routine.rows), *(islice(p.cases, PROBE_CASES) for p in parts))
    check = RoutineCheck(routine, runner.size(runner.blocks_read(probe)), static, totals, bounds_violations(routine, static, totals),
                         budget_violations(routine, static, totals), _part_runs(parts, totals, unknown, rows),
                         start=runner.start, engine=used, agreement=agreement, rows=rows, engine_reason=reason,
                         compile_seconds=compile_seconds, search=searched, engine_note=engine_note, entry_every=every,
                         random_draw=next((p.draw for p in parts if p.name == "random"), None))
    if rows is not None and rows.agreement is not None:
        check.agreement = agreement = merged_agreement(agreement, rows)
    if agreement is not None and agreement.failure is not None and totals.failure is None:
        totals.failure = agreement.failure  # the timing model or the engines disagreed on a call
    if totals.failure is not None:
        check.trace = failure_trace(spec, seed, totals.failure.case, start)
    if used == "compiled":  # the compiled engine counts no coverage: say so rather than show what it did not count
        return _finished(check, began)
    check.code_coverage = completed(totals.code_coverage, runner)
    if totals.max_case is not None and not totals.run_errors:
        check.code_coverage.worst_path = worst_path(runner, totals.max_case)
        check.code_coverage.worst_cycles = totals.cycles_max
    return _finished(check, began)


def _finished(check: RoutineCheck, began: float) -> RoutineCheck:
    check.seconds = time.monotonic() - began
    return check


def _search(spec: str, seed: int, runner, on_batch: bool, totals: Tally, budget: int | None) -> SearchResult:
    """The coverage-guided search from what the planned cases ran (none after a call that stopped,
    nor for a spec of rows only: no answer is known for a case it would find)."""
    routine = runner.routine
    if budget is None:
        budget = routine.search if routine.search is not None else DEFAULT_SEARCH
    if routine.reference is None or totals.run_errors:
        budget = 0
    return search(runner, on_batch=on_batch, seed=seed, budget=budget, covered=totals.code_coverage,
                  slowest=None if totals.max_case is None else (totals.cycles_max, totals.max_case),
                  fastest=None if totals.min_case is None else (totals.cycles_min, totals.min_case))


def run_checks(names: list[str] | None, *, exhaustive: bool = False, seed: int | None = None,
               random_count: int | None = None, jobs: Workers | int | None = None,
               progress: Callable[[str], None] | None = None, start: SceneStart | None = None,
               bounded_product: int = case_sets.BOUNDED_PRODUCT, engine: str = "auto",
               search_budget: int | None = None) -> list[RoutineCheck]:
    """Check the named routines (built-in names or spec paths; all built-ins when none are named);
    every name is loaded and validated before any work starts."""
    specs = select(names)
    workers = as_workers(jobs)
    with session():  # the routines share one cluster, started by the first that needs it
        return [check_routine(spec, exhaustive=exhaustive, seed=seed, random_count=random_count, jobs=workers,
                              progress=progress, start=start, bounded_product=bounded_product, engine=engine,
                              search_budget=search_budget)
                for spec in specs]
