"""Cases run on either engine: `Machine` (the reference, with the timing model on every call) or the
batched core; the runners cached per worker process; the engine default of the study's commands."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from retro.analysis.check.reference import expected_columns, expected_outputs
from retro.analysis.check.results import EXAMPLES_KEPT, ChunkResult, Failure, describe_case, describe_outputs
from retro.cpu.batch import LaneError
from retro.cpu.timing import model_cycles
from retro.errors import InputError, RunError
from retro.routines import cases as case_sets
from retro.routines.runner import NEEDS_A_VIC_SCENE, BatchOutcome, RasterStart, RoutineRunner, row_of
from retro.routines.spec import Routine, load_spec

ENGINES = ("auto", "scalar", "batch")
DEFAULT_ENGINE = "auto"  # what engine=None means, here and in the study's method runs: see engine_default
BATCH_LANES = 65_536  # cases the batched core runs at once (memory stays bounded: see LaneMemory)
AUTO_BATCH_CASES = 20_000  # planned cases from which engine="auto" takes the batched core
AGREEMENT_PER_PART = 2_000  # cases of each part also run on Machine when the batched core runs the check
TRACE_SHOWN = 400  # instructions of the first failing case's trace in the report

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
        except InputError:
            if not broken:
                raise
            expected = None  # a reference may refuse inputs outside the domain: no answer to compare
        out.cases += 1
        cpu_cycles = cycles - runner.last_stolen  # the timing model and the static bounds know no stalls
        modelled = model_cycles(read, steps)
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

