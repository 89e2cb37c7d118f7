"""Calls run on either engine, each giving the same `CallBlock`: `Machine` (the reference, with the
timing model on every call) or the batched core (retro.cpu.batch). The one rule that picks the engine
(`batched`), the runners cached per worker process, and the trace of a failing call."""

from __future__ import annotations

from dataclasses import dataclass
from itertools import islice

import numpy as np

from retro.cpu.batch import LaneError
from retro.analysis.check.coverage import count_steps, from_lanes
from retro.analysis.check.results import describe_outputs
from retro.analysis.coverage_model import CodeCoverage
from retro.errors import InputError, RunError
from retro.fileio import reads_unchanged, recording_reads
from retro.routines import cases as case_sets
from retro.routines.chip_access import NesStart
from retro.routines.outputs import row_of
from retro.routines.runner import RasterStart, RoutineRunner
from retro.routines.spec import Routine, load_spec

ENGINES = ("auto", "scalar", "batch", "compiled")
ARRAY_ENGINES = ("batch", "compiled")  # engines that run a column block at once (never with chips on the bus)
BATCH_LANES = 65_536  # cases the batched core runs at once (memory stays bounded: see LaneMemory)
AUTO_BATCH_CASES = 20_000  # planned cases from which engine="auto" takes the batched core for a check
# (it then also runs AGREEMENT_PER_PART cases of each part on Machine: below this it would not pay)
# "auto" between the batched core and the compiled engine: by the planned calls' work, their 6502 cycles (the
# count times a call's expected cycles: the geometric mean of the static best and worst, `expected_cycles`), the
# CPU the compiled engine saves on them against what it costs a process before its first call (each figure
# measured by `python benchmarks/compiled_speed.py --auto`; docs/compiled.md "What auto picks"):
BATCH_NS_PER_CYCLE = 3.9  # the batched core's CPU per cycle of the calls it runs (median; 1.7-6.6 ns by routine)
COMPILED_NS_PER_CYCLE = 0.35  # the compiled engine's (median; 0.1-0.5 ns)
COMPILED_START_SECONDS = 0.45  # numba's import, its CPU target's start and the load from the cache, per process
AUTO_COMPILED_CYCLES = round(COMPILED_START_SECONDS / (BATCH_NS_PER_CYCLE - COMPILED_NS_PER_CYCLE) * 1e9)
# (a routine's first compile, 0.6-5 s, is not counted: it is paid once per routine and content, its code kept in
# the cache, and a check this big wins it back within a few runs)
AUTO_PROBE_CASES = 32  # without static bounds: cases of each part run on Machine for a call's mean cycles
AGREEMENT_PER_PART = 2_000  # cases of each part also run on Machine when the batched core runs the check
TRACE_SHOWN = 400  # instructions of the first failing case's trace in the report

_RUNNERS: dict[tuple, tuple[set, RoutineRunner]] = {}  # the files a runner was built from (fileio), it
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
    """`--scene S --at-line L --at-cycle C` (a VIC-II scene) or `--at-line L --at-dot D` / `--in-nmi`
    (a NES scene), as plain data that crosses to worker processes."""

    scene: str
    line: int | None = None  # None: the scene's own [cpu] start_line / start_cycle (a NES scene: line 0)
    cycle: int | None = None
    dot: int | None = None  # a NES scene: the dot in that scanline (default 0)
    in_nmi: bool = False  # a NES scene: every call is the NMI handler, from the start of vblank

    def raster_start(self) -> RasterStart | NesStart:
        from retro.scenes import load_scene
        from retro.scenes.vic import VicScene

        scene = load_scene(self.scene)
        if not isinstance(scene, VicScene):
            return nes_start(scene, self.line, self.dot, self.in_nmi, self.cycle)
        if self.dot is not None or self.in_nmi:
            raise InputError(f"{'--in-nmi' if self.in_nmi else '--at-dot'}: needs a NES scene; {self.scene} is a "
                             f"VIC-II scene (--at-line and --at-cycle)")
        line = scene.start_line if self.line is None else self.line
        cycle = scene.start_cycle if self.cycle is None else self.cycle
        video = scene.state.video
        if not 0 <= line < video.lines or not 1 <= cycle <= video.cycles_per_line:
            raise InputError(f"--at-line/--at-cycle: the {video.chip} has lines 0-{video.lines - 1} and cycles "
                             f"1-{video.cycles_per_line}, got line {line} cycle {cycle}")
        return RasterStart(scene, line, cycle)


def nes_start(scene, line: int | None, dot: int | None, in_nmi: bool, cycle: int | None) -> NesStart:
    """A NES scene's entry, every option checked against the scene's video standard (one-line errors)."""
    from retro.chips.ppu.constants import DOTS_PER_LINE

    if cycle is not None:
        raise InputError(f"--at-cycle: a VIC-II option; {scene.source} is a NES scene: give the scanline's dot "
                         f"(--at-dot 0-{DOTS_PER_LINE - 1})")
    if in_nmi and (line is not None or dot is not None):
        raise InputError("--in-nmi enters at the start of vblank: not with --at-line/--at-dot")
    video = scene.video
    line, dot = line or 0, dot or 0
    if not 0 <= line <= video.pre_render_line or not 0 <= dot < DOTS_PER_LINE:
        raise InputError(f"--at-line/--at-dot: the {video.name.upper()} PPU has scanlines 0-{video.pre_render_line} "
                         f"and dots 0-{DOTS_PER_LINE - 1}, got scanline {line} dot {dot}")
    return NesStart(scene, line, dot, in_nmi)


def runner_for(spec: str, seed: int, start: SceneStart | None = None, fill: str | None = None) -> RoutineRunner:
    """The cached runner of a spec (`fill`: an entry-state variant's, retro.routines.entry), built
    again when a file it was built from changed since (the spec, its program, the scene, the scene's
    sprite files): a file edited between two checks in one process (a notebook, the pytest plugin)
    is never run stale."""
    key = (str(spec), seed, start, fill)
    cached = _RUNNERS.get(key)
    if cached is not None and reads_unchanged(cached[0]):
        return cached[1]
    with recording_reads() as reads:
        runner = RoutineRunner(routine_of(str(spec)), seed, start.raster_start() if start else None, fill)
    _RUNNERS[key] = reads, runner
    return runner


@dataclass
class CallBlock:
    """What a block of calls did, the same fields on both engines: per output an array ((n,) or
    (n, bytes)), cycles (stalls included), cycles the VIC-II stole, and the timing model's count
    (Machine only). `returned` calls returned; call `returned`, when there is one, did not: `stop` says
    why ("run": the routine broke it on Machine too; "engine": only the batched core stopped it)."""

    outputs: list
    cycles: np.ndarray
    stolen: np.ndarray | None  # None: no call lost a cycle (an array engine without a scene)
    modelled: np.ndarray | None  # the timing model's cycles per call; None on the batched core
    returned: int
    stop: str | None = None  # None, "run" or "engine"
    stop_message: str = ""
    lane_errors: np.ndarray | None = None  # the batched core: per call, the LaneError that stopped it (0: none)
    coverage: CodeCoverage | None = None  # what the calls ran of the code (None: not collected)
    mock_calls: list | None = None  # per call, the mocks' calls the reference takes (retro.routines.world)
    fallbacks: dict | None = None  # the compiled engine: calls it left to the batched core, by reason

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
    """The one rule choosing between Machine and an array engine: "batch", "compiled" and "scalar" as
    said; "auto" takes an array engine for `threshold` calls or more (None: an unknown count, a sweep).
    Never with chips on the bus."""
    check_engine(engine)
    return batchable and (engine in ARRAY_ENGINES or (engine == "auto" and (calls is None or calls >= threshold)))


def compiled_pays(cycles: int) -> bool:
    """The rule "auto" takes the compiled engine by for a check of known size: its `cycles` of planned calls
    cost more on the batched core than on the compiled engine by at least what the compiled engine costs
    a process before its first call."""
    return cycles >= AUTO_COMPILED_CYCLES


def expected_cycles(best: int, worst: int) -> float:
    """A call's expected cycles from the static bounds: their geometric mean (a loop's worst case is far above
    its typical call: tile_box's bounds 52 and 26,800 give 1,180 for a measured mean of 504)."""
    return (max(best, 1) * max(worst, 1)) ** 0.5


def planned_cycles(runner: RoutineRunner, parts: list, bounds) -> int | None:
    """The planned calls' 6502 cycles, estimated: their count times `expected_cycles` of the static `bounds`,
    or without them (None: the spec turns the analysis off) each part's count times the mean cycles of its
    first AUTO_PROBE_CASES cases on Machine; None when a part's count is unknown (a sweep function's)."""
    if any(part.count is None for part in parts):
        return None
    if bounds is not None:
        return round(sum(part.count for part in parts) * expected_cycles(bounds.best, bounds.worst))
    total = 0.0
    for part in parts:
        spent = []
        for case in islice(part.cases, min(part.count, AUTO_PROBE_CASES)):
            try:
                spent.append(runner.run(case)[1])
            except RunError:  # (the check finds it again and reports it)
                break
        total += part.count * (sum(spent) / len(spent) if spent else 0)
    return round(total)


def array_engine(engine: str, calls: int | None, cycles: int | None = None) -> tuple[str, str]:
    """Which array engine runs a check that `batched` sent to one, and why: ("compiled" or "batch",
    the reason the report gives). "auto" takes the compiled engine for a sweep, and for `calls` whose
    `cycles` (planned_cycles) pay for it (compiled_pays), when numba can be imported; its routine may
    still be refused (`compiled_or_why`)."""
    if engine == "batch":
        return "batch", "--engine batch"
    why = "auto: a sweep"
    if engine == "auto" and calls is not None:
        cycles = cycles or 0
        why = f"auto: {calls:,} planned calls, about {cycles / 1e6:,.0f} M cycles"
        if not compiled_pays(cycles):
            return "batch", f"{why} (the compiled engine from {AUTO_COMPILED_CYCLES / 1e6:,.0f} M)"
    from retro.cpu.compiled import numba_problem  # (numba's import, 0.2 s: only when the compiled engine may run)

    problem = numba_problem()
    if problem is not None:
        _say_once(f"the compiled engine is off: {problem}; the batched core runs instead")
        return "batch", problem
    return "compiled", "--engine compiled" if engine == "compiled" else why


_SAID: set[str] = set()


def _say_once(message: str) -> None:
    import sys

    if message not in _SAID:
        _SAID.add(message)
        print(f"retro: {message}", file=sys.stderr)


def compiled_or_why(runner: RoutineRunner) -> str | None:
    """None when the compiled engine takes the runner's routine (compiling it, or loading it from the
    cache, in this process), else why not (the report's reason)."""
    from retro.cpu.compiled import Untranslatable

    if not runner.routine.world.empty:  # traps, scripted reads and interrupt entry live in the other engines
        return "the routine has a world ([mocks], [hardware], an interrupt entry or an exit), which it does not model"
    if runner.vic is not None:
        return "a scene: the VIC-II's stalls are modelled on Machine and the batched core only"
    if runner.plan.vias is not None or runner.plan.s_varies:
        return "inputs placed by the case (on the stack, in a table slot or behind a pointer), which it does not place"
    if runner.watched_facts:  # Machine and the batched core stop a call that contradicts one
        return "the spec states facts ([facts]), which it does not hold against the calls"
    try:
        runner.compiled()
    except Untranslatable as exc:
        return str(exc)
    return None


def run_on_machine(runner: RoutineRunner, cases: list[tuple], coverage: bool = True) -> CallBlock:
    """Calls on Machine, each timed again by the timing model; the first that does not return ends
    the block (the next could run away as well). `coverage`: collect it (from the same recorded path)."""
    read = runner.machine.memory.__getitem__
    answers, cycles, stolen, modelled = [], [], [], []
    calls = [] if runner.routine.world.recorded else None
    stop, message = None, ""
    covered = CodeCoverage() if coverage else None
    keep_steps = coverage or bool(runner.watched_facts)  # else the timing model counts as the call runs
    for case in cases:
        steps: list | None = [] if keep_steps else None
        try:
            answer, spent = runner.run(case, steps, timed=not coverage)
        except RunError as exc:
            stop, message = "run", str(exc)
            break
        broken = facts_broken(runner, steps) if steps is not None else ""
        if broken:
            stop, message = "run", broken
            break
        answers.append(answer)
        cycles.append(spent)
        stolen.append(runner.last_stolen)
        # the timing model times the routine's instructions; a world's traps and interrupt entry are added
        modelled.append(count_steps(covered, read, steps, runner.routine.cpu) + runner.last_extra_cycles
                        if coverage else runner.last_modelled)
        if calls is not None:
            calls.append(runner.last_calls)
    return CallBlock(_output_arrays(runner.routine, answers), np.asarray(cycles, dtype=np.int64),
                     np.asarray(stolen, dtype=np.int64), np.asarray(modelled, dtype=np.int64), len(answers),
                     stop, message, coverage=covered, mock_calls=calls)


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


def run_on_batched_core(runner: RoutineRunner, columns: list, confirm_stop: bool = True,
                        coverage: bool = True, engine: str = "batch") -> CallBlock:
    """Calls on an array engine (the batched core, or the compiled engine with the calls it leaves run
    on the batched core); the first call it stops is run again on Machine (`confirm_stop`), whose error
    names it (or which returns: then the engines disagree). `coverage`: collect it (the batched core
    only: the compiled engine counts none)."""
    fallbacks = None
    if engine == "compiled":
        before = dict(runner.fallbacks)
        outcome = runner.run_compiled(columns)
        fallbacks = {code: count - before.get(code, 0) for code, count in runner.fallbacks.items()
                     if count != before.get(code, 0)}
        coverage = False
    else:
        outcome = runner.run_batch(columns, coverage)
    stopped = np.flatnonzero(outcome.error)
    n = len(outcome.cycles)
    block = CallBlock(outcome.outputs, outcome.cycles, outcome.stolen, None,
                      int(stopped[0]) if len(stopped) else n, lane_errors=outcome.error,
                      coverage=from_lanes(outcome.coverage) if coverage else None, mock_calls=outcome.mock_calls,
                      fallbacks=fallbacks)
    if coverage and len(stopped):  # coverage counts the calls before the first that stopped, as on Machine
        block.coverage = (from_lanes(runner.run_batch([c[:block.returned] for c in columns], True).coverage)
                          if block.returned else CodeCoverage())
    if len(stopped) and confirm_stop:
        machine = run_on_machine(runner, [case_sets.case_of(columns, block.returned)])
        if machine.stop is not None:
            block.stop, block.stop_message = "run", machine.stop_message
        else:
            block.stop, block.stop_message = "engine", (
                f"the engines disagree: the batched core stopped the call "
                f"({LaneError(int(outcome.error[block.returned])).name}), Machine returned")
    return block


def disagreements(routine: Routine, machine: CallBlock, batch: CallBlock) -> dict[int, str]:
    """`disagreement` of each call of Machine's block that has one, by call, in call order; the calls
    both engines returned with the same outputs and cycles (compared as arrays) are passed over."""
    n, r = machine.calls, machine.returned
    stopped = (batch.lane_errors[:r] != 0 if batch.lane_errors is not None
               else np.arange(r) >= batch.returned)
    same = ~stopped & (machine.cycles[:r] == batch.cycles[:r])
    for ours, theirs in zip(machine.outputs, batch.outputs):
        equal = ours[:r] == theirs[:r]
        same &= equal.all(axis=1) if equal.ndim == 2 else equal
    found = {}
    for i in np.flatnonzero(~same).tolist() + list(range(r, n)):
        message = disagreement(routine, machine, batch, i)
        if message is not None:
            found[i] = message
    return found


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
        lines.append(f"${entry.address:04X}  {runner.disassemble_at(entry.address):<14} "
                     f"{entry.cycles}  {total:>6}  {notes}".rstrip())
    if len(result.trace) > TRACE_SHOWN:
        lines.append(f"... {len(result.trace) - TRACE_SHOWN} more instructions")
    return lines

