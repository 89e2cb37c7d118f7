"""Calls run on either engine, each giving the same `CallBlock`: `Machine` (the reference, with the
timing model on every call) or the batched core (retro.cpu.batch). The one rule that picks the engine
(`batched`), the runners cached per worker process, and the trace of a failing call."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.cpu.batch import LaneError
from retro.cpu.timing import model_cycles
from retro.analysis.check.results import describe_outputs
from retro.errors import InputError, RunError
from retro.routines import cases as case_sets
from retro.routines.runner import NEEDS_A_VIC_SCENE, RasterStart, RoutineRunner, row_of
from retro.routines.spec import Routine, load_spec

ENGINES = ("auto", "scalar", "batch")
BATCH_LANES = 65_536  # cases the batched core runs at once (memory stays bounded: see LaneMemory)
AUTO_BATCH_CASES = 20_000  # planned cases from which engine="auto" takes the batched core for a check
# (it then also runs AGREEMENT_PER_PART cases of each part on Machine: below this it would not pay)
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


@dataclass
class CallBlock:
    """What a block of calls did, the same fields on both engines: per output an array ((n,) or
    (n, bytes)), cycles (stalls included), cycles the VIC-II stole, and the timing model's count
    (Machine only). `returned` calls returned; call `returned`, when there is one, did not: `stop` says
    why ("run": the routine broke it on Machine too; "engine": only the batched core stopped it)."""

    outputs: list
    cycles: np.ndarray
    stolen: np.ndarray
    modelled: np.ndarray | None  # the timing model's cycles per call; None on the batched core
    returned: int
    stop: str | None = None  # None, "run" or "engine"
    stop_message: str = ""
    lane_errors: np.ndarray | None = None  # the batched core: per call, the LaneError that stopped it (0: none)

    @property
    def calls(self) -> int:
        """Calls the block stands for: those that returned and the one that stopped it."""
        return self.returned + (self.stop is not None)

    def row(self, i: int) -> tuple:
        return row_of(self.outputs, i)

    def stopped(self, i: int) -> bool:
        if self.lane_errors is not None:
            return bool(self.lane_errors[i])
        return i >= self.returned


def check_engine(engine: str) -> None:
    if engine not in ENGINES:
        raise InputError(f"--engine: {engine!r} is not one of {', '.join(ENGINES)}")


def batched(engine: str, calls: int | None, batchable: bool, threshold: int) -> bool:
    """The one rule choosing the engine: "batch" and "scalar" as said; "auto" takes the batched core
    for `threshold` calls or more (None: an unknown count, a sweep). Never with chips on the bus."""
    check_engine(engine)
    return batchable and (engine == "batch" or (engine == "auto" and (calls is None or calls >= threshold)))


def run_on_machine(runner: RoutineRunner, cases: list[tuple]) -> CallBlock:
    """Calls on Machine, each timed again by the timing model; the first that does not return ends
    the block (the next could run away as well)."""
    read = runner.machine.memory.__getitem__
    answers, cycles, stolen, modelled = [], [], [], []
    stop, message = None, ""
    for case in cases:
        steps: list = []
        try:
            answer, spent = runner.run(case, steps)
        except RunError as exc:
            stop, message = "run", str(exc)
            break
        broken = facts_broken(runner, steps)
        if broken:
            stop, message = "run", broken
            break
        answers.append(answer)
        cycles.append(spent)
        stolen.append(runner.last_stolen)
        modelled.append(model_cycles(read, steps, runner.routine.cpu))
    return CallBlock(_output_arrays(runner.routine, answers), np.asarray(cycles, dtype=np.int64),
                     np.asarray(stolen, dtype=np.int64), np.asarray(modelled, dtype=np.int64), len(answers),
                     stop, message)


def facts_broken(runner: RoutineRunner, steps: list) -> str:
    """The first stated fact (`[facts]`) the recorded call contradicts, as a message ('' when none)."""
    watched = runner.watched_facts
    if not watched:
        return ""
    for pc, x, y, p, _, a in steps:
        fact = watched.get(pc)
        if fact is not None and fact.broken(a, x, y, p, runner.call_image[pc]):
            return f"the call {fact.describe_break()} at ${pc:04X} (A={a}, X={x}, Y={y}, P=${p:02X})"
    return ""


def _output_arrays(routine: Routine, answers: list[tuple]) -> list[np.ndarray]:
    n = len(answers)
    return [np.asarray([a[k] for a in answers], dtype=np.int64).reshape((n, len(port.places)) if port.table else (n,))
            for k, port in enumerate(routine.outputs)]


def run_on_batched_core(runner: RoutineRunner, columns: list, confirm_stop: bool = True) -> CallBlock:
    """Calls on the batched core; the first call it stops is run again on Machine (`confirm_stop`),
    whose error names it (or which returns: then the engines disagree)."""
    outcome = runner.run_batch(columns)
    stopped = np.flatnonzero(outcome.error)
    n = len(outcome.cycles)
    block = CallBlock(outcome.outputs, outcome.cycles, np.zeros(n, dtype=np.int64), None,
                      int(stopped[0]) if len(stopped) else n, lane_errors=outcome.error)
    if len(stopped) and confirm_stop:
        machine = run_on_machine(runner, [case_sets.case_of(columns, block.returned)])
        if machine.stop is not None:
            block.stop, block.stop_message = "run", machine.stop_message
        else:
            block.stop, block.stop_message = "engine", (
                f"the engines disagree: the batched core stopped the call "
                f"({LaneError(int(outcome.error[block.returned])).name}), Machine returned")
    return block


def disagreement(routine: Routine, machine: CallBlock, batch: CallBlock, i: int) -> str | None:
    """Why call i differs between the engines (None: it does not)."""
    stopped = batch.stopped(i)
    if i >= machine.returned:
        return None if stopped else "the engines disagree: Machine stopped the call, the batched core returned"
    answer, cycles = machine.row(i), int(machine.cycles[i])
    if stopped:
        return (f"the engines disagree: the batched core stopped the call "
                f"({LaneError(int(batch.lane_errors[i])).name}), Machine returned")
    if batch.row(i) == answer and int(batch.cycles[i]) == cycles:
        return None
    return (f"the engines disagree: Machine: {describe_outputs(routine, answer)} in {cycles} cycles; batched core: "
            f"{describe_outputs(routine, batch.row(i))} in {int(batch.cycles[i])} cycles")


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

