"""Cross-check a routine (a spec: built-in or the user's) against its reference, results and cycles.

For every case: the routine's outputs must equal the reference's (inside the spec's `where`
domain), and the measured cycle count must equal the independent timing model summed over the
executed path (retro.cpu.timing). Cases outside the domain are run too: their failures are what
shows each condition of the domain is needed, and a failure inside it is a mismatch. Measured
extremes must lie within the static best/worst case (retro.cpu.flow), and both within the spec's
cycle budget (`[cycles] max`) when it has one.

Cases are made lazily (retro.routines.cases) and run in chunks over worker processes (`jobs`);
the first run failure (BRK, JAM, a runaway past `[cycles] limit`) stops the check and is reported
with its inputs.

Two engines run the calls: `Machine` (scalar, the reference, with the timing model on every call)
and the batched core (retro.cpu.batch: 65,536 cases at a time with numpy). `engine="auto"` takes the
batched core from AUTO_BATCH_CASES planned cases on; then the first AGREEMENT_PER_PART cases of every
part also run on `Machine` with the timing model, and the two engines must agree call for call
(outputs and cycles): a disagreement is a mismatch of kind "engine".
"""

from __future__ import annotations

import math
import os
import time
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from contextlib import contextmanager
from dataclasses import dataclass, field
from itertools import islice
from typing import TYPE_CHECKING

import numpy as np

from retro.analysis.raster import format_raster, raster_figures
from retro.cpu.flow import Bounds, analyse
from retro.cpu.timing import model_cycles
from retro.errors import InputError, RunError
from retro.routines import cases as case_sets
from retro.routines.registry import select
from retro.cpu.batch import LaneError
from retro.routines.sandbox import UserCodeError, shown
from retro.routines.runner import (
    NEEDS_A_VIC_SCENE,
    BatchOutcome,
    RasterStart,
    RoutineRunner,
    Size,
    describe_value,
    row_of,
)
from retro.routines.spec import Routine, load_spec
from retro.routines.where import require_inside
from retro.workers import worker_pool

if TYPE_CHECKING:
    from retro.analysis.row_check import RowsCheck

EXAMPLES_KEPT = 5
JSON_EXACT = 1 << 53  # larger whole numbers lose digits in JSON readers that use doubles
ENGINES = ("auto", "scalar", "batch")
DEFAULT_ENGINE = "auto"  # what engine=None means, here and in the study's method runs: see engine_default
BATCH_LANES = 65_536  # cases the batched core runs at once (memory stays bounded: see LaneMemory)
AUTO_BATCH_CASES = 20_000  # planned cases from which engine="auto" takes the batched core
AGREEMENT_PER_PART = 2_000  # cases of each part also run on Machine when the batched core runs the check
TRACE_SHOWN = 400  # instructions of the first failing case's trace in the report
PROGRESS_SECONDS = 1.0  # at most one progress line a second


@dataclass
class Failure:
    """The first failing case of a chunk: what the routine and the reference said."""

    case: tuple
    kind: str  # "result", "cycles" or "run"
    outputs: tuple | None = None
    expected: tuple | None = None
    message: str = ""


@dataclass
class ChunkResult:
    cases: int = 0
    result_mismatches: int = 0
    cycle_mismatches: int = 0
    run_errors: int = 0
    outside: int = 0
    outside_wrong: int = 0
    constraint_cases: dict[str, int] = field(default_factory=dict)
    constraint_wrong: dict[str, int] = field(default_factory=dict)
    cycles_min: int | None = None
    cycles_max: int | None = None
    min_case: tuple | None = None
    max_case: tuple | None = None
    cycles_sum: int = 0
    cycles_count: int = 0
    cpu_min: int | None = None  # cycles the CPU ran (stalls excluded): what the static bounds bound
    cpu_max: int | None = None
    stolen_max: int = 0  # with a scene: the most cycles one call lost to Bad Lines and sprite DMA
    engine_cases: int = 0  # calls run on both engines and compared
    engine_mismatches: int = 0
    examples: list[str] = field(default_factory=list)
    outside_examples: list[str] = field(default_factory=list)
    failure: Failure | None = None

    def merge(self, other: "ChunkResult") -> None:
        self.cases += other.cases
        self.result_mismatches += other.result_mismatches
        self.cycle_mismatches += other.cycle_mismatches
        self.run_errors += other.run_errors
        self.outside += other.outside
        self.outside_wrong += other.outside_wrong
        for target, source in ((self.constraint_cases, other.constraint_cases),
                               (self.constraint_wrong, other.constraint_wrong)):
            for key, value in source.items():
                target[key] = target.get(key, 0) + value
        if other.cycles_count:
            if self.cycles_min is None or other.cycles_min < self.cycles_min:
                self.cycles_min, self.min_case = other.cycles_min, other.min_case
            if self.cycles_max is None or other.cycles_max > self.cycles_max:
                self.cycles_max, self.max_case = other.cycles_max, other.max_case
        self.cycles_sum += other.cycles_sum
        self.cycles_count += other.cycles_count
        if other.cpu_min is not None:
            self.cpu_min = other.cpu_min if self.cpu_min is None else min(self.cpu_min, other.cpu_min)
            self.cpu_max = other.cpu_max if self.cpu_max is None else max(self.cpu_max, other.cpu_max)
        self.stolen_max = max(self.stolen_max, other.stolen_max)
        self.engine_cases += other.engine_cases
        self.engine_mismatches += other.engine_mismatches
        self.examples = (self.examples + other.examples)[:EXAMPLES_KEPT]
        self.outside_examples = (self.outside_examples + other.outside_examples)[:EXAMPLES_KEPT]
        self.failure = self.failure or other.failure


@dataclass(frozen=True)
class PartRun:
    name: str
    cases: int
    total: int  # cases of the space the part stands for (exhaustive: the whole product)


@dataclass
class RoutineCheck:
    routine: Routine
    size: Size
    static: Bounds | None
    totals: ChunkResult
    bounds_violations: list[str]
    budget_violations: list[str] = field(default_factory=list)
    parts: list[PartRun] = field(default_factory=list)
    trace: list[str] = field(default_factory=list)  # the first failing case's instructions
    start: RasterStart | None = None  # with --scene: the beam position every call started at
    engine: str = "scalar"  # which engine ran the cases: "scalar" (Machine) or "batch"
    agreement: ChunkResult | None = None  # with the batched core: the cases also run on Machine
    rows: "RowsCheck | None" = None  # the spec's expected rows (retro.analysis.row_check)
    seconds: float = 0.0  # wall time of the check (JUnit reports)

    @property
    def mismatches(self) -> int:
        t = self.totals
        found = (t.result_mismatches + t.cycle_mismatches + t.run_errors + len(self.bounds_violations)
                 + len(self.budget_violations))
        if self.agreement is not None:  # its result mismatches and run errors are among the batch's own
            found += self.agreement.engine_mismatches + self.agreement.cycle_mismatches
        if self.rows is not None:  # rows whose call returned something else (a stopped call is a run error)
            found += self.rows.wrong
        return found

    @property
    def mean(self) -> float:
        return self.totals.cycles_sum / self.totals.cycles_count if self.totals.cycles_count else 0.0

    @property
    def worst_reached(self) -> bool:
        return self.static is not None and self.totals.cpu_max == self.static.worst

    def domain_report(self) -> list[str]:
        t = self.totals
        lines = [f"inside the domain: {t.cases - t.outside} cases, {t.result_mismatches} wrong"]
        for condition in self.routine.domain:
            violating = t.constraint_cases.get(condition.text, 0)
            wrong = t.constraint_wrong.get(condition.text, 0)
            verdict = "needed" if wrong else "not shown to be needed by these cases"
            lines.append(f"  condition {condition.text}: {violating} cases break it, {wrong} of them wrong: {verdict}")
        return lines


# ---- one case, one chunk -----------------------------------------------------------------------------

def inputs_by_name(routine: Routine, case: tuple) -> dict:
    return {port.name: list(value) if port.table else value for port, value in zip(routine.inputs, case)}


def describe_case(routine: Routine, case: tuple) -> str:
    return ", ".join(f"{port.name}={describe_value(port, value)}" for port, value in zip(routine.inputs, case))


def describe_outputs(routine: Routine, values: tuple) -> str:
    return ", ".join(f"{port.name}={describe_value(port, value)}" for port, value in zip(routine.outputs, values)
                     if value is not None)  # None: an output an expected row does not state


def expected_outputs(routine: Routine, case: tuple, memory: dict) -> tuple:
    """The reference's answer for a case, as a tuple in the outputs' order (a one-line error for a
    reference that raises or answers in the wrong shape)."""
    arguments = dict(zip(routine.input_names, case))
    arguments.update({name: memory[name] for name in routine.reference_memory})
    try:
        value = routine.reference(**arguments)
    except UserCodeError:
        raise
    except Exception as exc:  # the user's reference: whatever it raises is reported in one line
        raise InputError(f"{routine.spec_path}: reference {routine.reference_name} raised {type(exc).__name__}: "
                         f"{str(exc)[:200]} (inputs {describe_case(routine, case)})") from None
    return normalise_outputs(routine, value, case)


def normalise_outputs(routine: Routine, value, case: tuple) -> tuple:
    outputs = routine.outputs
    where = f"{routine.spec_path}: reference {routine.reference_name}"
    if isinstance(value, dict):
        if set(value) != set(routine.output_names):
            raise InputError(f"{where} returned keys {sorted(value)} for the outputs {list(routine.output_names)} "
                             f"(inputs {describe_case(routine, case)})")
        values = [value[name] for name in routine.output_names]
    elif len(outputs) == 1:
        values = [value]
    else:
        raise InputError(f"{where} returned {type(value).__name__}; with {len(outputs)} outputs it must return a "
                         f"dict {{{', '.join(routine.output_names)}}} (inputs {describe_case(routine, case)})")
    out = []
    for port, item in zip(outputs, values):
        out.append(_output_value(port, item, where, routine, case))
    return tuple(out)


def _output_value(port, item, where: str, routine: Routine, case: tuple):
    if isinstance(item, np.ndarray) and item.ndim == 0 or isinstance(item, np.generic):
        item = item.item()
    if port.table:
        try:
            values = tuple(int(v) for v in item)
        except (TypeError, ValueError):
            values = None
        if values is None or len(values) != len(port.places) or any(not 0 <= v <= 0xFF for v in values):
            raise InputError(f"{where} returned {shown(item)} for {port.name}: expected {len(port.places)} bytes "
                             f"(inputs {describe_case(routine, case)})")
        return values
    if isinstance(item, bool):
        item = int(item)
    limit = 1 << port.bits
    if not isinstance(item, int) or not 0 <= item < limit:
        raise InputError(f"{where} returned {shown(item)} for {port.name}: expected a whole number 0..{limit - 1} "
                         f"({'a flag: true or false' if port.flag else port.describe()}) "
                         f"(inputs {describe_case(routine, case)})")
    return item


_RUNNERS: dict[tuple[str, int], RoutineRunner] = {}
_BUILT: dict[str, Routine] = {}  # specs built in Python (retro.testing), by a key standing for their path
_BUILT_PREFIX = "<built>:"


def routine_key(spec: str | Routine) -> str:
    """What names a routine across worker processes: its spec path, or a key for one built in Python."""
    if isinstance(spec, Routine):
        key = f"{_BUILT_PREFIX}{spec.spec_path}:{id(spec)}"
        _BUILT[key] = spec
        return key
    return str(spec)


def routine_of(key: str) -> Routine:
    return _BUILT[key] if key.startswith(_BUILT_PREFIX) else load_spec(key)


@dataclass(frozen=True)
class SceneStart:
    """`--scene S --at-line L --at-cycle C`, as plain data that crosses to worker processes."""

    scene: str
    line: int | None = None  # None: the scene's own [cpu] start_line / start_cycle
    cycle: int | None = None

    def raster_start(self) -> RasterStart:
        from retro.scenes import load_scene
        from retro.scenes.vic import VicScene

        scene = load_scene(self.scene)
        if not isinstance(scene, VicScene):
            raise InputError(f"--scene {self.scene}: {NEEDS_A_VIC_SCENE}")
        line = scene.start_line if self.line is None else self.line
        cycle = scene.start_cycle if self.cycle is None else self.cycle
        video = scene.state.video
        if not 0 <= line < video.lines or not 1 <= cycle <= video.cycles_per_line:
            raise InputError(f"--at-line/--at-cycle: the {video.chip} has lines 0-{video.lines - 1} and cycles "
                             f"1-{video.cycles_per_line}, got line {line} cycle {cycle}")
        return RasterStart(scene, line, cycle)


def runner_for(spec: str, seed: int, start: SceneStart | None = None) -> RoutineRunner:
    key = (str(spec), seed, start)
    if key not in _RUNNERS:
        _RUNNERS[key] = RoutineRunner(routine_of(str(spec)), seed, start.raster_start() if start else None)
    return _RUNNERS[key]


def check_chunk(spec: str, seed: int, chunk: list[tuple], start: SceneStart | None = None,
                against: BatchOutcome | None = None) -> ChunkResult:
    """Run cases of one routine; a pure function of its arguments (used in worker processes). With
    `against` (the batched core's outcome for the same cases), every call is also compared with it."""
    runner = runner_for(spec, seed, start)
    routine = runner.routine
    name = routine.name
    read = runner.machine.memory.__getitem__
    out = ChunkResult()
    columns = case_sets.cases_to_columns(routine, chunk)
    holds = [condition.over(columns, chunk) for condition in routine.domain]  # per condition, per case
    answers = None
    for i, case in enumerate(chunk):
        steps: list = []
        try:
            answer, cycles = runner.run(case, steps)
        except RunError as exc:
            out.cases += 1
            out.run_errors += 1
            out.examples.append(f"{name}({describe_case(routine, case)}): {exc}")
            out.failure = out.failure or Failure(case, "run", message=str(exc))
            if against is not None:
                _compare_engines(out, routine, case, against, i, None, None)
            break  # a broken routine stops the check: the next case could run away as well
        if against is not None:
            _compare_engines(out, routine, case, against, i, answer, cycles)
        broken = [c.text for c, held in zip(routine.domain, holds) if not held[i]]
        try:
            if routine.reference_arrays:  # the whole chunk in one call, as the batched core asks it
                if answers is None:
                    inside = np.logical_and.reduce(holds) if holds else np.ones(len(chunk), dtype=bool)
                    answers, answered = expected_columns(routine, columns, chunk, runner.memory_values, inside)
                if not answered[i]:
                    raise InputError("outside the domain, the reference gave no answer")
                expected = row_of(answers, i)
            else:
                expected = expected_outputs(routine, case, runner.memory_values)
        except UserCodeError:  # a hang, an exit: never a refusal
            raise
        except InputError:
            if not broken:
                raise
            expected = None  # a reference may refuse inputs outside the domain: no answer to compare
        out.cases += 1
        cpu_cycles = cycles - runner.last_stolen  # the timing model and the static bounds know no stalls
        modelled = model_cycles(read, steps, routine.cpu)
        if modelled != cpu_cycles:
            out.cycle_mismatches += 1
            out.failure = out.failure or Failure(case, "cycles", answer, expected,
                                                 f"measured {cpu_cycles} cycles, the timing model says {modelled}")
            if len(out.examples) < EXAMPLES_KEPT:
                out.examples.append(f"{name}({describe_case(routine, case)}): measured {cpu_cycles} cycles, "
                                    f"the timing model says {modelled}")
        for text in broken:
            out.constraint_cases[text] = out.constraint_cases.get(text, 0) + 1
        if broken:
            out.outside += 1
            if expected is not None and answer != expected:
                out.outside_wrong += 1
                for text in broken:
                    out.constraint_wrong[text] = out.constraint_wrong.get(text, 0) + 1
                if len(out.outside_examples) < EXAMPLES_KEPT:
                    out.outside_examples.append(
                        f"{name}({describe_case(routine, case)}): returned {describe_outputs(routine, answer)}, "
                        f"reference {describe_outputs(routine, expected)} (outside: {', '.join(broken)})")
            continue
        if answer != expected:
            out.result_mismatches += 1
            out.failure = out.failure or Failure(case, "result", answer, expected)
            if len(out.examples) < EXAMPLES_KEPT:
                out.examples.append(f"{name}({describe_case(routine, case)}): returned "
                                    f"{describe_outputs(routine, answer)}, reference {describe_outputs(routine, expected)}")
        if out.cycles_min is None or cycles < out.cycles_min:
            out.cycles_min, out.min_case = cycles, case
        if out.cycles_max is None or cycles > out.cycles_max:
            out.cycles_max, out.max_case = cycles, case
        out.cycles_sum += cycles
        out.cycles_count += 1
        out.cpu_min = cpu_cycles if out.cpu_min is None else min(out.cpu_min, cpu_cycles)
        out.cpu_max = cpu_cycles if out.cpu_max is None else max(out.cpu_max, cpu_cycles)
        out.stolen_max = max(out.stolen_max, runner.last_stolen)
    return out


def _compare_engines(out: ChunkResult, routine: Routine, case: tuple, batch: BatchOutcome, i: int,
                     answer: tuple | None, cycles: int | None) -> None:
    """Count one call run on both engines; a difference is an engine mismatch (answer None: Machine
    stopped the call with a run error)."""
    out.engine_cases += 1
    stopped = bool(batch.error[i])
    if answer is None and stopped:
        return
    if answer is not None and not stopped and batch.case_outputs(i) == answer and int(batch.cycles[i]) == cycles:
        return
    out.engine_mismatches += 1
    if answer is None:
        text = "Machine stopped the call, the batched core returned"
    elif stopped:
        text = f"the batched core stopped the call ({LaneError(int(batch.error[i])).name}), Machine returned"
    else:
        text = (f"Machine: {describe_outputs(routine, answer)} in {cycles} cycles; batched core: "
                f"{describe_outputs(routine, batch.case_outputs(i))} in {int(batch.cycles[i])} cycles")
    message = f"the engines disagree: {text}"
    out.failure = out.failure or Failure(case, "engine", answer, None, message)
    if len(out.examples) < EXAMPLES_KEPT:
        out.examples.append(f"{routine.name}({describe_case(routine, case)}): {message}")


def agreement_chunk(spec: str, seed: int, chunk: list[tuple]) -> ChunkResult:
    """Cases run on both engines: Machine's full check (timing model included) and the comparison."""
    runner = runner_for(spec, seed, None)
    outcome = runner.run_batch(case_sets.cases_to_columns(runner.routine, chunk))
    return check_chunk(spec, seed, chunk, None, outcome)


def expected_columns(routine: Routine, columns: list, cases: list[tuple] | None, memory: dict,
                     inside: np.ndarray | None = None) -> tuple[list[np.ndarray], np.ndarray]:
    """The reference's answers for a block of cases, one array per output (a table: (n, bytes)), and
    which cases it answered: outside the domain (`inside` False) it may refuse a case or answer out of
    range; inside, that is a one-line error."""
    n = len(columns[0])
    inside = np.ones(n, dtype=bool) if inside is None else inside
    answerable = np.ones(n, dtype=bool)
    if routine.reference_arrays:
        arguments = dict(zip(routine.input_names, columns))
        arguments.update({name: memory[name] for name in routine.reference_memory})
        where = f"{routine.spec_path}: reference {routine.reference_name} (arrays = true)"
        try:
            with np.errstate(all="ignore"):
                value = routine.reference(**arguments)
        except UserCodeError:
            raise
        except Exception as exc:  # the user's reference: whatever it raises is reported in one line
            raise InputError(f"{where} raised {type(exc).__name__}: {str(exc)[:200]}") from None
        if isinstance(value, dict):
            if set(value) != set(routine.output_names):
                raise InputError(f"{where} returned keys {sorted(value)} for the outputs {list(routine.output_names)}")
            values = [value[name] for name in routine.output_names]
        elif len(routine.outputs) == 1:
            values = [value]
        else:
            values = list(value) if isinstance(value, (tuple, list)) else []
            if len(values) != len(routine.outputs):
                raise InputError(f"{where}: with {len(routine.outputs)} outputs it must return a dict or a tuple of "
                                 f"{len(routine.outputs)} arrays")
        out, fitting = [], []
        for port, item in zip(routine.outputs, values):
            array = np.asarray(item)
            if array.dtype == bool:
                array = array.astype(np.int64)
            shape = (n, len(port.places)) if port.table else (n,)
            if array.shape != shape and array.ndim == 0:
                array = np.broadcast_to(array, shape)
            if array.shape != shape or not np.issubdtype(array.dtype, np.integer):
                raise InputError(f"{where} returned {array.dtype} of shape {array.shape} for {port.name}: expected "
                                 f"whole numbers of shape {shape}")
            limit = 1 << port.bits
            fits = (array >= 0) & (array < limit)
            if port.table:
                fits = fits.all(axis=1)
            answerable &= fits
            fitting.append(fits)
            out.append(array.astype(np.int64))
        bad = np.flatnonzero(~answerable & inside)
        if len(bad):
            i = int(bad[0])
            k = next(k for k, fits in enumerate(fitting) if not fits[i])
            port = routine.outputs[k]
            raise InputError(f"{where} returned {out[k][i].tolist()} for {port.name}: outside 0..{(1 << port.bits) - 1} "
                             f"(inputs {describe_case(routine, case_sets.case_of(columns, i))})")
        return out, answerable
    cases = cases if cases is not None else case_sets.columns_to_cases(columns)
    answers = []
    blank = tuple(tuple(-1 for _ in p.places) if p.table else -1 for p in routine.outputs)
    for i, case in enumerate(cases):
        try:
            answers.append(expected_outputs(routine, case, memory))
        except UserCodeError:
            raise
        except InputError:
            if inside[i]:
                raise
            answers.append(blank)  # a reference may refuse inputs outside the domain: nothing to compare
            answerable[i] = False
    return [np.asarray([a[k] for a in answers], dtype=np.int64).reshape((n, len(port.places)) if port.table else (n,))
            for k, port in enumerate(routine.outputs)], answerable


def check_batch(spec: str, seed: int, columns: list) -> ChunkResult:
    """`check_chunk` for a column block on the batched core (used in worker processes)."""
    runner = runner_for(spec, seed, None)
    routine = runner.routine
    name = routine.name
    out = ChunkResult()
    outcome = runner.run_batch(columns)
    stopped = np.flatnonzero(outcome.error)
    n = len(columns[0]) if not len(stopped) else int(stopped[0])
    full = columns
    columns = [c[:n] for c in columns]
    case_by_case = not routine.reference_arrays or any(c.test_columns is None for c in routine.domain)
    cases = case_sets.columns_to_cases(columns) if case_by_case else None
    inside = np.ones(n, dtype=bool)
    broken_by: list[np.ndarray] = []
    for condition in routine.domain:
        broken = ~condition.over(columns, cases)
        broken_by.append(broken)
        inside &= ~broken
        out.constraint_cases[condition.text] = int(broken.sum())
    if n:
        expected, answerable = expected_columns(routine, columns, cases, runner.memory_values, inside)
        got = [o[:n] for o in outcome.outputs]
        equal = np.ones(n, dtype=bool)
        for g, e in zip(got, expected):
            equal &= (g == e).all(axis=1) if g.ndim == 2 else g == e
        wrong_inside = np.flatnonzero(inside & ~equal)
        wrong_outside = ~inside & ~equal & answerable
        out.cases = n
        out.result_mismatches = len(wrong_inside)
        out.outside = int((~inside).sum())
        out.outside_wrong = int(wrong_outside.sum())
        for condition, broken in zip(routine.domain, broken_by):
            out.constraint_wrong[condition.text] = int((broken & wrong_outside).sum())
        case_at = (lambda i: cases[i]) if cases is not None else (
            lambda i: case_sets.case_of(columns, i))

        for i in wrong_inside[:EXAMPLES_KEPT].tolist():
            out.examples.append(f"{name}({describe_case(routine, case_at(i))}): returned "
                                f"{describe_outputs(routine, row_of(got, i))}, reference "
                                f"{describe_outputs(routine, row_of(expected, i))}")
        if len(wrong_inside):
            first = int(wrong_inside[0])
            out.failure = Failure(case_at(first), "result", row_of(got, first), row_of(expected, first))
        for i in np.flatnonzero(wrong_outside)[:EXAMPLES_KEPT].tolist():
            broken = [c.text for c, b in zip(routine.domain, broken_by) if b[i]]
            out.outside_examples.append(
                f"{name}({describe_case(routine, case_at(i))}): returned {describe_outputs(routine, row_of(got, i))}, "
                f"reference {describe_outputs(routine, row_of(expected, i))} (outside: {', '.join(broken)})")
        cycles = outcome.cycles[:n][inside]
        if len(cycles):
            positions = np.flatnonzero(inside)
            low, high = int(np.argmin(cycles)), int(np.argmax(cycles))
            out.cycles_min, out.min_case = int(cycles[low]), case_at(int(positions[low]))
            out.cycles_max, out.max_case = int(cycles[high]), case_at(int(positions[high]))
            out.cycles_sum = int(cycles.sum())
            out.cycles_count = len(cycles)
            out.cpu_min, out.cpu_max = out.cycles_min, out.cycles_max
    if len(stopped):  # the first call that did not return stops the check, as on Machine
        case = case_sets.case_of(full, n)
        out.cases += 1
        out.run_errors += 1
        try:
            runner.run(case)
            message = (f"the engines disagree: the batched core stopped the call "
                       f"({LaneError(int(outcome.error[n])).name}), Machine returned")
            kind = "engine"
            out.engine_cases += 1
            out.engine_mismatches += 1
        except RunError as exc:
            message, kind = str(exc), "run"
        out.examples.append(f"{name}({describe_case(routine, case)}): {message}")
        out.failure = out.failure or Failure(case, kind, message=message)
    return out


# ---- static bounds -------------------------------------------------------------------------------------

def static_bounds(routine: Routine, runner: RoutineRunner | None = None) -> Bounds | None:
    """Best and worst cycles from the routine's bytes (as loaded, after init), subroutines included;
    None when the spec turns the analysis off (`[cycles] static = false`)."""
    if not routine.static:
        return None
    runner = runner or RoutineRunner(routine)
    machine = runner.machine
    program = runner.program
    memory = list(machine.memory)
    bounds = {machine.resolve(label, f"cycles.loops.{label}"): count for label, count in routine.loop_bounds.items()}
    names = {address: label for label, address in sorted(program.symbols.items(), key=lambda kv: len(kv[0]))[::-1]}

    def describe(address: int) -> str:
        return f"${address:04X}" + (f" ({names[address]})" if address in names else "")
    try:
        return analyse(memory.__getitem__, runner.entry, bounds, name=routine.name,
                       within=(program.origin, program.end), describe=describe, cpu=routine.cpu)
    except InputError as exc:
        raise InputError(f"{routine.spec_path}: static analysis: {exc} ([cycles] static = false skips it)") from None


# ---- a whole check -----------------------------------------------------------------------------------

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


@contextmanager
def engine_default(engine: str) -> Iterator[None]:
    """Make `engine` what engine=None means while the block runs: the study's commands reach routine
    runs through many layers, and workers forked inside the block inherit the setting."""
    global DEFAULT_ENGINE
    if engine not in ENGINES:
        raise InputError(f"--engine: {engine!r} is not one of {', '.join(ENGINES)}")
    before, DEFAULT_ENGINE = DEFAULT_ENGINE, engine
    try:
        yield
    finally:
        DEFAULT_ENGINE = before


def check_routine(spec: str | Routine, *, exhaustive: bool = False, seed: int | None = None,
                  random_count: int | None = None, jobs: int = 1, progress: Callable[[str], None] | None = None,
                  start: SceneStart | None = None, bounded_product: int = case_sets.BOUNDED_PRODUCT,
                  engine: str | None = None) -> RoutineCheck:
    """Check one routine: a spec path, or a Routine built in Python (then in this process only).
    `engine`: "scalar" (Machine), "batch" (the batched core, checked against Machine on the first
    AGREEMENT_PER_PART cases of each part) or "auto" (batch from AUTO_BATCH_CASES planned cases)."""
    began = time.monotonic()
    engine = DEFAULT_ENGINE if engine is None else engine
    if engine not in ENGINES:
        raise InputError(f"--engine: {engine!r} is not one of {', '.join(ENGINES)}")
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

    rows = None
    if routine.rows:  # the spec's expected rows run first, in this process (retro.analysis.row_check)
        from retro.analysis.row_check import check_rows

        rows, rows_totals = check_rows(spec, seed, start, batched)
        report(rows_totals)
        if totals.run_errors:  # a row's call that stopped stops the check
            parts = []
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
    require_inside(f"{routine.spec_path}: cases.where", routine.domain, totals.cases, totals.outside,
                   totals.constraint_cases)
    part_runs = [PartRun(p.name, p.count if p.count is not None else 0, p.total) for p in parts]
    if rows is not None:
        part_runs.insert(0, PartRun("rows", sum(o.checked for o in rows.outcomes), len(rows.outcomes)))
    if unknown:  # the sweep's count is whatever was left after the counted parts
        counted = sum(p.cases for p in part_runs if p.name != "sweep")
        part_runs = [PartRun(p.name, max(totals.cases - counted, 0), max(totals.cases - counted, 0))
                     if p.name == "sweep" else p for p in part_runs]
    if routine.reference is None:  # rows only: unknown static bounds are said, not an error
        from retro.analysis.row_check import rows_only_static

        static, rows.static_note = rows_only_static(routine, runner)
    else:
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
                         start=runner.start, engine="batch" if batched else "scalar", agreement=agreement, rows=rows)
    if rows is not None and rows.agreement is not None:
        from retro.analysis.row_check import merged_agreement

        check.agreement = agreement = merged_agreement(agreement, rows)
    if agreement is not None and agreement.failure is not None and totals.failure is None:
        totals.failure = agreement.failure  # the timing model or the engines disagreed on a call
    if totals.failure is not None:
        check.trace = failure_trace(spec, seed, totals.failure.case, start)
    check.seconds = time.monotonic() - began
    return check


def failure_trace(spec: str, seed: int, case: tuple, start: SceneStart | None = None) -> list[str]:
    """The instructions of one case, run again on a fresh machine with the trace on."""
    runner = RoutineRunner(routine_of(spec), seed, start.raster_start() if start else None)
    try:
        result = runner.traced(case)
    except RunError as exc:
        return [f"(the traced run failed too: {exc})"]
    lines = []
    total = 0
    for entry in result.trace[:TRACE_SHOWN]:
        total += entry.cycles
        notes = " ".join(n for n, on in (("taken", entry.branch_taken), ("page+1", entry.page_crossed)) if on)
        lines.append(f"${entry.address:04X}  {runner.machine.disassemble_at(entry.address):<14} "
                     f"{entry.cycles}  {total:>6}  {notes}".rstrip())
    if len(result.trace) > TRACE_SHOWN:
        lines.append(f"... {len(result.trace) - TRACE_SHOWN} more instructions")
    return lines


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


# ---- reports -------------------------------------------------------------------------------------------

def coverage(check: RoutineCheck) -> list[dict]:
    out = []
    for part in check.parts:
        item = {"part": part.name, "cases": part.cases}
        if part.name == "exhaustive":
            item["space"] = part.total
            item["inputs"] = list(check.routine.exhaustive)
            item["complete"] = part.cases == part.total
        out.append(item)
    return out


def cycle_figures(check: RoutineCheck) -> dict:
    """The cycle fields shared by `retro check --json` and `retro cycles --json`."""
    t = check.totals
    routine = check.routine
    return {"min": t.cycles_min, "mean": round(check.mean, 2), "max": t.cycles_max,
            "static_min": check.static.best if check.static else None,
            "static_max": check.static.worst if check.static else None,
            "min_inputs": inputs_by_name(routine, t.min_case) if t.min_case is not None else None,
            "max_inputs": inputs_by_name(routine, t.max_case) if t.max_case is not None else None,
            "budget": routine.budget,
            "raster": {**raster_figures(routine.machine, t.cycles_min, check.mean if t.cycles_count else None,
                                        t.cycles_max), **scene_raster(check)}}


def scene_raster(check: RoutineCheck) -> dict:
    """With --scene: the calls on the scene's timeline from the start line ({"scene": {...}}), stalls
    included: lines taken, the most cycles stolen, and where the slowest call ended."""
    start = check.start
    t = check.totals
    if start is None or not t.cycles_count:
        return {}
    video = start.scene.state.video
    per_line = video.cycles_per_line
    last = start.line * per_line + start.cycle - 1 + t.cycles_max - 1
    frames, within = divmod(last, video.frame_cycles)
    end_line, end_cycle = divmod(within, per_line)
    return {"scene": {"chip": video.chip, "start_line": start.line, "start_cycle": start.cycle,
                      "min_lines": round(t.cycles_min / per_line, 3), "mean_lines": round(check.mean / per_line, 3),
                      "max_lines": round(t.cycles_max / per_line, 3), "stolen_max": t.stolen_max,
                      "slowest_end_line": end_line, "slowest_end_cycle": end_cycle + 1, "frames_crossed": frames}}


def check_record(check: RoutineCheck) -> dict:
    """One routine's check as plain data (what `retro check --json` prints)."""
    t = check.totals
    record = {"routine": check.routine.name, "spec": str(check.routine.spec_path), "cpu": check.routine.cpu,
              "machine": check.routine.machine, "cases": t.cases, "mismatches": check.mismatches,
              "result_mismatches": t.result_mismatches,
              "cycle_mismatches": t.cycle_mismatches + (check.agreement.cycle_mismatches if check.agreement else 0),
              "run_errors": t.run_errors, "bounds_violations": check.bounds_violations,
              "budget_violations": check.budget_violations,
              "outside_domain": t.outside, "outside_domain_wrong": t.outside_wrong,
              "domain": [{"condition": c.text, "cases": t.constraint_cases.get(c.text, 0),
                          "wrong": t.constraint_wrong.get(c.text, 0)} for c in check.routine.domain],
              **cycle_figures(check), "worst_reached": check.worst_reached, "coverage": coverage(check),
              "input_space": space if (space := check.routine.input_space()) < JSON_EXACT else None,
              "input_space_log2": round(math.log2(space), 3), "coverage_argument": check.routine.coverage or None,
              "examples": t.examples, "outside_examples": t.outside_examples, "engine": check.engine,
              "engine_agreement": None if check.agreement is None else {
                  "cases": check.agreement.engine_cases, "mismatches": check.agreement.engine_mismatches,
                  "timing_model_mismatches": check.agreement.cycle_mismatches},
               "notes": list(check.routine.notes), "first_failure": None, "rows": None}
    failure = t.failure
    if failure is not None:
        routine = check.routine
        record["first_failure"] = {
            "kind": failure.kind, "inputs": inputs_by_name(routine, failure.case),
            "outputs": None if failure.outputs is None else dict(zip(routine.output_names, _plain(failure.outputs))),
            "expected": None if failure.expected is None else {  # None: an output an expected row does not state
                name: value for name, value in zip(routine.output_names, _plain(failure.expected))
                if value is not None},
            "message": failure.message, "trace": check.trace}
    if check.rows is not None:
        from retro.analysis.row_check import rows_record

        record["rows"] = rows_record(check.routine, check.rows)
    return record


def _plain(values: tuple) -> list:
    return [list(v) if isinstance(v, tuple) else v for v in values]


def format_space(space: int) -> str:
    return f"{space:,}" if space < JSON_EXACT else f"2^{math.log2(space):.1f}"


def format_coverage(check: RoutineCheck) -> str:
    parts = []
    for part in check.parts:
        if part.name == "exhaustive":
            scope = ", ".join(check.routine.exhaustive)
            parts.append(f"exhaustive over {scope}: {part.cases:,} of {part.total:,}"
                         + ("" if part.cases == part.total else " (sampled; --exhaustive runs all)"))
        else:
            parts.append(f"{part.name} {part.cases:,}")
    return "; ".join(parts)


def format_check(check: RoutineCheck) -> list[str]:
    t = check.totals
    routine = check.routine
    verdict = "OK" if not check.mismatches else f"{check.mismatches} MISMATCH(ES)"
    static = (f"static {check.static.best}-{check.static.worst}, worst case "
              f"{'reached' if check.worst_reached else 'not reached'}" if check.static else
              "static bounds unknown" if check.rows is not None and check.rows.static_note else "static analysis off")
    cost = (f"cycles {t.cycles_min}-{t.cycles_max} (mean {check.mean:.2f})" if t.cycles_count
            else "no case inside the domain")
    if check.agreement is None:
        checked = f"timing model equal on {t.cases - t.cycle_mismatches - t.run_errors} of {t.cases} calls"
    else:
        a = check.agreement
        checked = (f"batched core; on {a.engine_cases} of the calls Machine agrees on "
                   f"{a.engine_cases - a.engine_mismatches} and the timing model on "
                   f"{a.cases - a.cycle_mismatches - a.run_errors}")
    lines = [f"{routine.name}: {t.cases} cases, {verdict}; {cost}, {static}; {checked}"]
    lines += [f"  note: {note}" for note in routine.notes]
    if check.parts:
        lines.append(f"  cases: {format_coverage(check)}; input space {format_space(check.routine.input_space())}")
    if routine.coverage:
        lines.append(f"  coverage: {routine.coverage}")
    if t.cycles_count:
        lines.append(f"  fastest: {describe_case(routine, t.min_case)}")
        lines.append(f"  slowest: {describe_case(routine, t.max_case)}")
        raster = format_raster(routine.machine, raster_figures(routine.machine, t.cycles_min, check.mean, t.cycles_max))
        if raster:
            lines.append(f"  raster (CPU never stalled): {raster}")
        scene = scene_raster(check).get("scene")
        if scene:
            lines.append(f"  on the scene from line {scene['start_line']} cycle {scene['start_cycle']} ({scene['chip']}): "
                         f"{scene['min_lines']:.2f}-{scene['max_lines']:.2f} lines, up to {scene['stolen_max']} cycles "
                         f"stolen; the slowest ends at line {scene['slowest_end_line']} cycle {scene['slowest_end_cycle']}"
                         + (f" {scene['frames_crossed']} frame(s) later" if scene["frames_crossed"] else ""))
    if routine.budget is not None:
        lines.append(f"  budget: {routine.budget} cycles: {'broken' if check.budget_violations else 'kept'}")
    lines += [f"  {line}" for line in check.domain_report()[1:]] if routine.domain else []
    if t.outside:
        lines.append(f"  outside the stated domain: {t.outside} cases, {t.outside_wrong} wrong"
                     + (f", e.g. {t.outside_examples[0]}" if t.outside_examples else ""))
    if check.rows is not None:
        from retro.analysis.row_check import rows_lines

        lines += rows_lines(routine, check.rows)
    lines += [f"  MISMATCH {example}" for example in t.examples]
    lines += [f"  MISMATCH {violation}" for violation in check.bounds_violations]
    lines += [f"  BUDGET {violation}" for violation in check.budget_violations]
    if t.failure is not None:
        lines.append(f"  first failing case: {describe_case(routine, t.failure.case)}")
        if t.failure.outputs is not None:
            lines.append(f"    routine:   {describe_outputs(routine, t.failure.outputs)}")
        if t.failure.expected is not None:
            stated = "the row:  " if t.failure.kind == "row" else "reference:"
            lines.append(f"    {stated} {describe_outputs(routine, t.failure.expected)}")
        if t.failure.message:
            lines.append(f"    {t.failure.message}")
        lines.append("    trace (address, instruction, cycles, running total):")
        lines += [f"    {line}" for line in check.trace]
    return lines
