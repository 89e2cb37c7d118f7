"""Coverage of the routine's code over a check's cases, collected on either engine into one
`CodeCoverage` (retro/analysis/coverage_model.py): on Machine from the path each call recorded for
the timing model, on the batched core from its per-group counts (retro.cpu.batch.LaneCoverage).
Both count the same things the same way, so the two engines give equal coverage for equal cases.

Also here: the instructions a check could run (every instruction reachable from the entry, as the
static analysis decodes the code every call starts from), the worst case's path, and the summary
every report shows (instructions and branch directions run, what was not run, with labels)."""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from retro.analysis.coverage_model import CodeCoverage
from retro.cpu.batch import LaneCoverage
from retro.cpu.timing import instruction_cycles, is_conditional_branch, timing_table
from retro.program import Program
from retro.routines.runner import RoutineRunner
from retro.routines.size import routine_code

UNCOVERED_SHOWN = 8  # addresses named in the text line (JSON lists them all)
NO_FEWER = 1 << 62  # above any instruction's cycles


def from_lanes(lanes: LaneCoverage) -> CodeCoverage:
    return CodeCoverage(dict(lanes.executed), dict(lanes.taken), dict(lanes.not_taken), dict(lanes.cycles_min),
                        dict(lanes.cycles_max))


def count_steps(coverage: CodeCoverage, read: Callable[[int], int], steps: Iterable[tuple[int, int, int, int, int]],
                cpu: str) -> int:
    """Add one call's recorded path (Machine's (pc, x, y, p, pointer) per instruction) to `coverage`;
    return the call's cycles by the timing model. A conditional branch was taken when it cost more
    than its base cycles (the taken penalty is at least one cycle)."""
    base = timing_table(cpu)
    branches = _conditional_branches(cpu)
    executed, taken, not_taken = coverage.executed, coverage.taken, coverage.not_taken
    low, high = coverage.cycles_min, coverage.cycles_max
    total = 0
    for pc, x, y, p, pointer, *_ in steps:
        cycles = instruction_cycles(read, pc, x, y, p, pointer, cpu)
        total += cycles
        executed[pc] = executed.get(pc, 0) + 1
        if cycles < low.get(pc, NO_FEWER):
            low[pc] = cycles
        if cycles > high.get(pc, -1):
            high[pc] = cycles
        opcode = read(pc)
        if opcode in branches:
            if cycles > base[opcode].cycles:
                taken[pc] = taken.get(pc, 0) + 1
                not_taken.setdefault(pc, 0)
            else:
                not_taken[pc] = not_taken.get(pc, 0) + 1
                taken.setdefault(pc, 0)
    return total


def directions_of(read: Callable[[int], int], steps: Iterable[tuple[int, int, int, int, int]],
                  cpu: str) -> set[tuple[int, bool]]:
    """The branch directions, (pc, taken), of one call's recorded path (as `count_steps` tells them)."""
    table = timing_table(cpu)
    branches = _conditional_branches(cpu)
    went = set()
    for pc, x, y, p, pointer, *_ in steps:
        opcode = read(pc)
        if opcode in branches:
            went.add((pc, instruction_cycles(read, pc, x, y, p, pointer, cpu) > table[opcode].cycles))
    return went


@functools.cache
def _conditional_branches(cpu: str) -> frozenset[int]:
    return frozenset(opcode for opcode, op in timing_table(cpu).items() if is_conditional_branch(op))


def code_instructions(runner: RoutineRunner) -> dict[int, int]:
    """{address: opcode} of every instruction reachable from the entry in the code every call starts
    from (after `init`), following branches, JMP and JSR within the program."""
    program = runner.program
    read = runner.call_image.__getitem__
    within = (program.origin, program.end)
    return {pc: read(pc) for pc in routine_code(read, [runner.entry], within, runner.routine.cpu)}


def completed(coverage: CodeCoverage, runner: RoutineRunner) -> CodeCoverage:
    """The coverage with every reachable instruction listed (0 when no case ran it) and both
    directions of every conditional branch among them."""
    table = timing_table(runner.routine.cpu)
    out = CodeCoverage(dict(coverage.executed), dict(coverage.taken), dict(coverage.not_taken),
                       dict(coverage.cycles_min), dict(coverage.cycles_max), coverage.worst_path,
                       coverage.worst_cycles)
    for pc, opcode in code_instructions(runner).items():
        out.executed.setdefault(pc, 0)
        op = table.get(opcode)
        if op is not None and is_conditional_branch(op):
            out.taken.setdefault(pc, 0)
            out.not_taken.setdefault(pc, 0)
    return out


def worst_path(runner: RoutineRunner, case: tuple) -> tuple[int, ...]:
    """The instruction addresses one call runs, in order (the worst case's path)."""
    steps: list = []
    runner.run(case, steps)
    return tuple(step[0] for step in steps)


def address_label(symbols: dict[str, int], program: Program, address: int) -> str | None:
    """The nearest label at or below an address of the program ("loop", "miss+2"), None without one."""
    candidates = [(value, name) for name, value in symbols.items() if program.origin <= value <= address < program.end]
    if not candidates:
        return None
    nearest = max(value for value, _ in candidates)
    best = (nearest, min(name for value, name in candidates if value == nearest))
    offset = address - best[0]
    return best[1] if offset == 0 else f"{best[1]}+{offset}"


@dataclass(frozen=True)
class CoverageSummary:
    """What a report says of the coverage: counts, and what was not run (address, label, direction)."""

    instructions: int
    instructions_run: int
    directions: int
    directions_run: int
    not_run: tuple[tuple[int, str | None], ...]
    directions_not_run: tuple[tuple[int, str | None, str], ...]  # (address, label, "taken" or "not taken")


def summary(coverage: CodeCoverage, program: Program) -> CoverageSummary:
    label = lambda pc: address_label(program.symbols, program, pc)  # noqa: E731
    not_run = tuple((pc, label(pc)) for pc in sorted(coverage.executed) if not coverage.executed[pc])
    branches = sorted(coverage.taken.keys() | coverage.not_taken.keys())
    missing = tuple((pc, label(pc), way) for pc in branches
                    for way, counts in (("taken", coverage.taken), ("not taken", coverage.not_taken))
                    if not counts.get(pc, 0))
    return CoverageSummary(len(coverage.executed), len(coverage.executed) - len(not_run), 2 * len(branches),
                           2 * len(branches) - len(missing), not_run, missing)


def _named(pc: int, label: str | None) -> str:
    return f"${pc:04X}" + (f" ({label})" if label else "")


def coverage_line(s: CoverageSummary) -> str:
    """One line: "code: 41/43 instructions, 9/10 branch directions; not run: $C012 (miss+2) ..."."""
    line = f"code: {s.instructions_run}/{s.instructions} instructions, {s.directions_run}/{s.directions} branch directions"
    gaps = [_named(pc, label) for pc, label in s.not_run]
    gaps += [f"{_named(pc, label)} {way}" for pc, label, way in s.directions_not_run
             if (pc, label) not in s.not_run]
    if gaps:
        shown = ", ".join(gaps[:UNCOVERED_SHOWN])
        line += f"; not run: {shown}" + (f" and {len(gaps) - UNCOVERED_SHOWN} more" if len(gaps) > UNCOVERED_SHOWN else "")
    return line


def coverage_record(s: CoverageSummary) -> dict:
    """The JSON of the summary: counts, and what was not run as "$hex" addresses with labels."""
    return {"instructions": s.instructions, "instructions_run": s.instructions_run,
            "branch_directions": s.directions, "branch_directions_run": s.directions_run,
            "not_run": [{"address": f"${pc:04X}", "label": label} for pc, label in s.not_run],
            "branch_directions_not_run": [{"address": f"${pc:04X}", "label": label, "direction": way}
                                          for pc, label, way in s.directions_not_run]}
