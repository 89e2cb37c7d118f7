"""A whole check: the case plan, blocks of calls over worker processes on the engine the one rule
picks, the engine agreement, the totals and the verdicts of bounds and budget."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from functools import cached_property
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
    planned_cycles,
    routine_key,
    routine_of,
    run_on_batched_core,
    run_on_machine,
    runner_for,
)
from retro.analysis.check.coverage import completed, worst_path
from retro.analysis.check.entry_runs import (
    VARIANTS,
    EntryBaseline,
    entry_baseline,
    entry_block_on_machine,
    entry_every,
    name_dependence,
    rerun_engine,
)
from retro.analysis.check.results import PartRun, RoutineCheck
from retro.analysis.check.search import DEFAULT_SEARCH, SearchResult, search
from retro.analysis.check.tally import EXAMPLES_KEPT, Tally, count_array_block, count_block, entry_tally
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
    tally, baseline = array_block(spec, seed, columns, first, every, engine, start)
    if baseline is not None:
        tally.merge(held_entry_tally(spec, seed, start, [baseline]))
    return tally


def array_block(spec: str, seed: int, columns: list, first: int, every: int, engine: str,
                start: SceneStart | None, outside_wanted: int = EXAMPLES_KEPT,
                runner: RoutineRunner | None = None) -> tuple[Tally, EntryBaseline | None]:
    """A column block on an array engine, tallied, and its entry-state rerun cases held for
    `held_entry_tally` (None: `every` is 0), so that a task's blocks rerun theirs together;
    `outside_wanted` as for count_block. `runner`: the spec's runner_for, when the caller holds it (a
    sweep task asks once for all its blocks: the files it was built from are looked at once a task)."""
    runner = runner or runner_for(spec, seed, start)
    block = run_on_batched_core(runner, columns, engine=engine)
    tally, inside = count_array_block(runner.routine, block, columns, runner.memory_values, outside_wanted)
    if not every:
        return tally, None
    return tally, entry_baseline(runner.routine, block.outputs, block.cycles, block.returned, columns, first, every,
                                 inside)


def held_entry_tally(spec: str, seed: int, start: SceneStart | None, held: list[EntryBaseline],
                     engine: str = "batch") -> Tally:
    """The held rerun cases of blocks run with the entry state varied on `engine` (the batched core, or
    the compiled engine: entry_runs.rerun_engine), all at once."""
    return _named(spec, seed, start, entry_tally(_variants(spec, seed, start), held, seed, engine))


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


def agreement_chunk(spec: str, seed: int, columns: list, engine: str = "batch",
                    start: SceneStart | None = None) -> Tally:
    """A column block's cases on both engines: Machine's tally (timing model included), its block
    compared with the array engine's call for call."""
    runner = runner_for(spec, seed, start)
    cases = case_sets.columns_to_cases(columns)
    against = run_on_batched_core(runner, columns, confirm_stop=False, coverage=False, engine=engine)
    return count_block(runner.routine, run_on_machine(runner, cases, coverage=False), columns, cases,
                       runner.memory_values, against)  # (the array engine counts these cases' coverage)


# ---- a sweep's tasks: a description of their cases, made in the worker -------------------------------

@dataclass(frozen=True)
class Sweep:
    """What every task of a check's sweep shares: the plan of its cases (spec, seed, options), the engine
    and the entry-state sample. A task is this plus a range of case indices; the worker makes the cases
    itself (retro.routines.cases), so no case column ever crosses a pipe or the network."""

    spec: str
    seed: int
    exhaustive: bool
    random: int | None
    bounded_product: int
    engine: str  # "scalar" (Machine), "batch" or "compiled"
    every: int = 0  # every how many cases one is rerun with the entry state varied (0: none)
    start: SceneStart | None = None
    rerun_engine: str = "batch"  # the array engine the entry-state reruns run on (entry_runs.rerun_engine)

    def parts(self) -> list[case_sets.Part]:
        """The plan's parts, made once per process (the check's own process registers the ones it made),
        with the counts of those that did not say it (a sweep function's) once this process made them."""
        if self not in _PLANS:
            _PLANS.clear()  # one plan per worker at a time: memory stays bounded
            _PLANS[self] = case_sets.plan(routine_of(self.spec), exhaustive=self.exhaustive, seed=self.seed,
                                          random=self.random, bounded_product=self.bounded_product)
        return _PLANS[self]

    def counted(self, index: int, count: int) -> None:
        """Part `index` made `count` cases: later tasks pass over it by its count (a new list: the check's
        own plan is left as it is)."""
        parts = list(self.parts())
        parts[index] = replace(parts[index], count=count)
        _PLANS[self] = parts

    def task_cases(self, planned: int) -> int:
        """Cases per task: TASK_BLOCKS blocks (COMPILED_TASK_FACTOR times more on the compiled engine, and
        LONG_SWEEP_FACTOR times more again for a sweep of `planned` >= LONG_SWEEP_CALLS cases)."""
        if self.engine != "compiled":
            return TASK_BLOCKS * self.block
        long = LONG_SWEEP_FACTOR if planned >= LONG_SWEEP_CALLS else 1
        return TASK_BLOCKS * self.block * COMPILED_TASK_FACTOR * long

    @cached_property
    def block(self) -> int:
        """Cases per block: the batched core's lanes (fewer for table inputs), a CHUNK on Machine."""
        if self.engine == "scalar":
            return case_sets.CHUNK
        return case_sets.block_size(case_sets.cases_to_columns(routine_of(self.spec), []), BATCH_LANES)


TASK_BLOCKS = 4  # blocks per task: a few seconds of work at most, many tasks for an even spread
COMPILED_TASK_FACTOR = 8  # ... times this on the compiled engine, whose block is ~10 ms of work: a task costs
# about 5 ms of the parent's CPU (the scheduler, the client) and a worker's, measured on aabb8's sweep
LONG_SWEEP_CALLS = 1 << 28  # from this many planned cases (seconds of work on each worker) ...
LONG_SWEEP_FACTOR = 4  # ... tasks this many times larger again: aabb8's full sweep in 1,536 tasks of 8 M cases, not
# 6,144 (measured on its 1/16 slice, 2 workers: 29.5-32.6 CPU s against 36.8-38.7, the parent 3.5 s against 5.2-5.7;
# still 32 tasks from LONG_SWEEP_CALLS on, for an even spread over the workers)
_PLANS: dict[Sweep, list] = {}
_CURSORS: dict[Sweep, tuple[int, Iterator]] = {}  # where this process's last task of a sweep stopped


def sweep_task(sweep: Sweep, first: int, count: int) -> Tally:
    """Cases first..first+count-1 of the sweep (fewer at its end: none past it), tallied block by
    block; stops after a block with a run error. On an array engine the blocks' entry-state reruns
    are held and run together at the end (retro.analysis.check.entry_runs.EntryBaseline)."""
    totals = Tally()
    held: list = []
    blocks = _blocks_from(sweep, first)
    runner = runner_for(sweep.spec, sweep.seed, sweep.start) if sweep.engine != "scalar" else None
    position = first
    while position < first + count:
        block = next(blocks, None)
        if block is None:
            break
        tally, baseline = _block_tally(sweep, block, position, EXAMPLES_KEPT - len(totals.outside_examples), runner)
        totals.merge(tally)
        if baseline is not None:
            held.append(baseline)
        position += len(block[0])
        if totals.run_errors:
            break
    if held:
        totals.merge(held_entry_tally(sweep.spec, sweep.seed, sweep.start, held, sweep.rerun_engine))
    _CURSORS.clear()
    _CURSORS[sweep] = (position, blocks)
    return totals


def _blocks_from(sweep: Sweep, first: int) -> Iterator:
    """The sweep's blocks from case `first`: this process's cursor moved on when its cases cannot be
    reached without making those before (a sweep function), else a fresh stream that passes over them."""
    position, blocks = _CURSORS.pop(sweep, (None, None))
    parts = sweep.parts()
    if blocks is None or position > first or case_sets.reachable(parts, first):
        return case_sets.stream(parts, sweep.block, first, sweep.counted)
    for _ in range((first - position) // sweep.block):  # another worker's tasks: made and dropped
        next(blocks, None)
    return blocks


def _block_tally(sweep: Sweep, block: list, first: int, outside_wanted: int,
                 runner: RoutineRunner | None) -> tuple[Tally, EntryBaseline | None]:
    """A block tallied, and on an array engine its entry-state rerun cases held (None: none)."""
    if sweep.engine == "scalar":
        return machine_chunk(sweep.spec, sweep.seed, case_sets.columns_to_cases(block), sweep.start, first,
                             sweep.every), None
    return array_block(sweep.spec, sweep.seed, block, first, sweep.every, sweep.engine, sweep.start, outside_wanted,
                       runner)


def _tasks(sweep: Sweep, known: int, unknown: bool, ended: Callable[[], bool]) -> Iterator[tuple]:
    """(sweep, first, count) in case order: up to the planned count, or, with a sweep function whose count
    is unknown, until a task comes back short."""
    size = sweep.task_cases(known)
    first = 0
    while (first < known) if not unknown else not ended():
        yield sweep, first, size
        first += size


def _run_sweep(sweep: Sweep, plan: "_Plan", workers: Workers | int, totals: Tally,
               report: Callable[[Tally], None]) -> None:
    """The planned cases as tasks on `workers` (this process when the check is small), merged in order;
    stops at the first run error."""
    size = sweep.task_cases(plan.known)
    ended = False

    def merged(result: Tally) -> bool:
        nonlocal ended
        ended = ended or result.cases < size
        if result.cases:
            report(result)
        return bool(totals.run_errors)
    needed = plan.unknown or plan.known >= PARALLEL_CALLS[sweep.engine]
    _PLANS[sweep] = plan.parts  # this process's tasks use the parts it made
    try:
        run_in_order(sweep_task, _tasks(sweep, plan.known, plan.unknown, lambda: ended), only(workers, needed), merged)
    finally:
        _PLANS.pop(sweep, None)
        _CURSORS.pop(sweep, None)


# ---- a whole check: a pipeline of steps ----------------------------------------------------------------

@dataclass
class _Plan:
    """A check's routine and the plan of its cases."""

    spec: str
    routine: Routine
    seed: int
    random: int | None
    parts: list[case_sets.Part]

    @property
    def known(self) -> int:
        return sum(p.count for p in self.parts if p.count is not None)

    @property
    def unknown(self) -> bool:
        return any(p.count is None for p in self.parts)

    @property
    def calls(self) -> int | None:
        return None if self.unknown else self.known


@dataclass(frozen=True)
class _Engine:
    """The engine a check runs on, and what the report says of it."""

    on_batch: bool  # an array engine runs the calls (Machine agrees on the first of each part)
    used: str  # "scalar", "batch" or "compiled"
    reason: str
    note: str = ""  # why Machine ran calls an array engine was asked for or would have run
    compile_seconds: float | None = None
    static: tuple | None = None  # (the static bounds,) when the choice needed them (the record uses them too)


def _planned(spec: str | Routine, exhaustive: bool, seed: int | None, random_count: int | None,
             bounded_product: int) -> _Plan:
    key = routine_key(spec)
    routine = routine_of(key)
    seed = routine.seed if seed is None else seed
    if routine.reference is None:  # rows only: no answer is known for a generated case, whatever --random says
        random_count = 0
    parts = case_sets.plan(routine, exhaustive=exhaustive, seed=seed, random=random_count,
                           bounded_product=bounded_product)
    return _Plan(key, routine, seed, random_count, parts)


def _engine_choice(plan: _Plan, runner: RoutineRunner, engine: str, start: SceneStart | None) -> _Engine:
    """The one rule (engines.batched) applied to the plan, and why; an array engine asked for a check
    only Machine can run is an input error."""
    on_batch = batched(engine, plan.calls, runner.batchable, AUTO_BATCH_CASES)
    refusal = runner.batch_refusal if runner.vic is None else None
    note = ""
    if refusal is not None and batched(engine, plan.calls, True, AUTO_BATCH_CASES):
        note = f"Machine ran the calls: {refusal}"  # the batched core would have: say why not
    elif engine in ("batch", "compiled") and not on_batch:
        raise InputError(f"--engine {engine}: with --scene the calls of {plan.routine.name} run on Machine "
                         f"({runner.engine_reason}); use --engine scalar or auto")
    if not on_batch:
        reason = (runner.engine_reason if start is not None else
                  note or (f"{engine}: {plan.known:,} planned calls" if engine == "auto" else f"--engine {engine}"))
        return _Engine(False, "scalar", reason, note)
    static = cycles = None
    if engine == "auto" and plan.calls is not None:  # by the planned calls' work (engines.planned_cycles)
        try:
            static = (_static(plan, runner),)
        except InputError:  # (the record raises it, after the checks that come before it)
            pass
        cycles = planned_cycles(runner, plan.parts, None if static is None else static[0])
    used, reason = array_engine(engine, plan.calls, cycles)
    if start is not None:
        reason = runner.engine_reason
    if used != "compiled":
        return _Engine(True, used, reason, note, static=static)
    refused = compiled_or_why(runner)
    if refused is not None:
        return _Engine(True, "batch", f"the compiled engine does not take it: {refused}", note, static=static)
    return _Engine(True, used, reason, note, runner.compiled().compile_seconds, static)


def _static(plan: _Plan, runner: RoutineRunner):
    """The routine's static bounds (verdicts.static_bounds), or for a spec of rows only, what is known of them."""
    if plan.routine.reference is None:
        return rows_only_static(plan.routine, runner)[0]
    return static_bounds(plan.routine, runner)


def _rows_first(plan: _Plan, start: SceneStart | None, choice: _Engine, totals: Tally,
                report: Callable[[Tally], None]) -> RowsCheck | None:
    """The spec's expected rows, in this process, before the cases (retro.analysis.row_check); a row's
    call that stops stops the check (no planned case runs)."""
    if not plan.routine.rows:
        return None
    rows, rows_totals = check_rows(plan.spec, plan.seed, start, choice.on_batch)
    report(rows_totals)
    if totals.run_errors:
        plan.parts = []
    return rows


def _agreement(spec: str, seed: int, parts: list[case_sets.Part], engine: str,
               start: SceneStart | None = None) -> Tally:
    """Machine first: the reference engine's verdict on a prefix of every part, both engines compared."""
    agreement = Tally()
    for part in parts:
        columns = part.head(AGREEMENT_PER_PART)
        if columns is not None:
            agreement.merge(agreement_chunk(spec, seed, columns, engine, start))
    return agreement


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
            beyond = "the sweep" if unknown else "the search" if done > known else None  # the search's finds
            progress(f"check {routine.name}: {done:,} cases ({known:,} planned, plus {beyond})" if beyond else
                     f"check {routine.name}: {done:,}/{known:,} cases")
    return report


def _search(plan: _Plan, runner: RoutineRunner, on_batch: bool, totals: Tally, budget: int | None) -> SearchResult:
    """The coverage-guided search from what the planned cases ran (none after a call that stopped,
    nor for a spec of rows only: no answer is known for a case it would find)."""
    routine = runner.routine
    if budget is None:
        budget = routine.search if routine.search is not None else DEFAULT_SEARCH
    if routine.reference is None or totals.run_errors:
        budget = 0
    return search(runner, on_batch=on_batch, seed=plan.seed, budget=budget, covered=totals.code_coverage,
                  slowest=None if totals.max_case is None else (totals.cycles_max, totals.max_case),
                  fastest=None if totals.min_case is None else (totals.cycles_min, totals.min_case))


def _run_found(plan: _Plan, searched: SearchResult, on_batch: bool, agreement: Tally | None,
               start: SceneStart | None, totals: Tally, report: Callable[[Tally], None]) -> None:
    """The search's cases, checked like every other case, as a part of their own ("search"), in this
    process on the batched core (or Machine)."""
    if not searched.found:
        return
    found = case_sets.cases_to_columns(plan.routine, searched.found)
    part = case_sets.Part("search", len(searched.found), len(searched.found), lambda: iter([found]))
    plan.parts.append(part)
    if on_batch:
        agreement.merge(_agreement(plan.spec, plan.seed, [part], "batch", start))
    for block in (case_sets.batches([part], BATCH_LANES) if on_batch else
                  case_sets.rechunked(part.blocks(), case_sets.CHUNK)):
        report(batch_chunk(plan.spec, plan.seed, block, 0, 0, "batch", start) if on_batch else
               machine_chunk(plan.spec, plan.seed, case_sets.columns_to_cases(block), start))
        if totals.run_errors:
            return


def _part_runs(parts: list[case_sets.Part], totals: Tally, unknown: bool, rows: RowsCheck | None) -> list[PartRun]:
    part_runs = [PartRun(p.name, p.count if p.count is not None else 0, p.total, p.inside) for p in parts]
    if rows is not None:  # the rows ran first, as a part of their own
        part_runs.insert(0, PartRun("rows", sum(o.checked for o in rows.outcomes), len(rows.outcomes)))
    if unknown:  # the sweep's count is whatever was left after the counted parts
        counted = sum(p.cases for p in part_runs if p.name != "sweep")
        part_runs = [PartRun(p.name, max(totals.cases - counted, 0), max(totals.cases - counted, 0))
                     if p.name == "sweep" else p for p in part_runs]
    return part_runs


def _assembled(plan: _Plan, runner: RoutineRunner, choice: _Engine, totals: Tally, agreement: Tally | None,
               rows: RowsCheck | None, searched: SearchResult, every: int, unknown: bool) -> RoutineCheck:
    """The check's record: static bounds and the verdicts against the totals, the parts, the engine."""
    routine = plan.routine
    require_inside(f"{routine.spec_path}: cases.where", routine.domain, totals.cases, totals.outside,
                   totals.constraint_cases)
    if routine.reference is None:  # rows only: unknown static bounds are said, not an error
        static, rows.static_note = rows_only_static(routine, runner)
    else:
        static = choice.static[0] if choice.static is not None else static_bounds(routine, runner)
    probe = chain((row.case for row in routine.rows), *(islice(p.cases, PROBE_CASES) for p in plan.parts))
    return RoutineCheck(routine, runner.size(runner.blocks_read(probe)), static, totals,
                        bounds_violations(routine, static, totals), budget_violations(routine, static, totals),
                        _part_runs(plan.parts, totals, unknown, rows), start=runner.start, engine=choice.used,
                        agreement=agreement, rows=rows, engine_reason=choice.reason,
                        compile_seconds=choice.compile_seconds, search=searched, engine_note=choice.note,
                        entry_every=every, random_draw=next((p.draw for p in plan.parts if p.name == "random"), None))


def _failure_and_coverage(check: RoutineCheck, plan: _Plan, runner: RoutineRunner, start: SceneStart | None) -> None:
    """The first failure (the timing model's or the engines' disagreement too) with its trace, and the
    code coverage (not on the compiled engine, which counts none: say so rather than show what it did not)."""
    totals, agreement = check.totals, check.agreement
    if check.rows is not None and check.rows.agreement is not None:
        check.agreement = agreement = merged_agreement(agreement, check.rows)
    if agreement is not None and agreement.failure is not None and totals.failure is None:
        totals.failure = agreement.failure  # the timing model or the engines disagreed on a call
    if totals.failure is not None:
        check.trace = failure_trace(plan.spec, plan.seed, totals.failure.case, start)
    if check.engine == "compiled":
        return
    check.code_coverage = completed(totals.code_coverage, runner)
    if totals.max_case is not None and not totals.run_errors:
        check.code_coverage.worst_path = worst_path(runner, totals.max_case)
        check.code_coverage.worst_cycles = totals.cycles_max


def check_routine(spec: str | Routine, *, exhaustive: bool = False, seed: int | None = None,
                  random_count: int | None = None, jobs: Workers | int = 1, progress: Callable[[str], None] | None = None,
                  start: SceneStart | None = None, bounded_product: int = case_sets.BOUNDED_PRODUCT,
                  engine: str = "auto", search_budget: int | None = None, entry_state: bool = True) -> RoutineCheck:
    """Check one routine: a spec path, or a Routine built in Python (then in this process only).
    `engine`: "scalar" (Machine), "batch" (the batched core, checked against Machine on the first
    AGREEMENT_PER_PART cases of each part) or "auto" (batch from AUTO_BATCH_CASES planned cases).
    `jobs`: where a large check's tasks run (retro.workers). `search_budget`: candidates the
    coverage-guided search may run after the planned cases (None: the spec's `[cases] search`, else
    DEFAULT_SEARCH; 0: no search). `entry_state`: also run a sample of the cases with the entry state
    the spec leaves arbitrary varied (retro.analysis.check.entry_runs)."""
    began = time.monotonic()
    check_engine(engine)
    workers = Workers(1) if isinstance(spec, Routine) else jobs
    plan = _planned(spec, exhaustive, seed, random_count, bounded_product)
    known, unknown = plan.known, plan.unknown
    runner = runner_for(plan.spec, plan.seed, start)  # loads and validates in this process before any worker starts
    choice = _engine_choice(plan, runner, engine, start)
    totals = Tally()
    report = _reporter(plan.routine, totals, known, unknown, progress)
    rows = _rows_first(plan, start, choice, totals, report)
    agreement = _agreement(plan.spec, plan.seed, plan.parts, choice.used, start) if choice.on_batch else None
    every = entry_every(known, exhaustive, bounded_product, unknown) if entry_state and plan.parts else 0
    if plan.parts:
        sweep = Sweep(plan.spec, plan.seed, exhaustive, plan.random, bounded_product, choice.used, every, start,
                      rerun_engine(choice.used, known, unknown, every))
        _run_sweep(sweep, plan, workers, totals, report)
    searched = _search(plan, runner, choice.on_batch, totals, search_budget)
    _run_found(plan, searched, choice.on_batch, agreement, start, totals, report)
    check = _assembled(plan, runner, choice, totals, agreement, rows, searched, every, unknown)
    _failure_and_coverage(check, plan, runner, start)
    check.seconds = time.monotonic() - began
    return check


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
