"""Static bounds of a routine (best and worst cycles from its bytes)."""

from __future__ import annotations

from retro.cpu.flow import Bounds, analyse
from retro.errors import InputError
from retro.routines.runner import RoutineRunner
from retro.routines.spec import Routine

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
                       within=(program.origin, program.end), describe=describe)
    except InputError as exc:
        raise InputError(f"{routine.spec_path}: static analysis: {exc} ([cycles] static = false skips it)") from None

