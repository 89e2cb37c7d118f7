"""The verdicts beside the tally: static bounds of a routine (best and worst cycles from its bytes),
measured cycles against them, and both against the spec's budget."""

from __future__ import annotations

from retro.analysis.check.results import describe_case
from retro.analysis.check.tally import Tally
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
    bounds = dict(routine.loop_addresses)
    names = {address: label for label, address in sorted(program.symbols.items(), key=lambda kv: len(kv[0]))[::-1]}

    def describe(address: int) -> str:
        return f"${address:04X}" + (f" ({names[address]})" if address in names else "")
    try:
        world = routine.world
        found = analyse(memory.__getitem__, runner.entry, bounds, name=routine.name,
                        within=(program.origin, program.end), describe=describe, cpu=routine.cpu,
                        mocks=world.mock_costs(), interrupt=world.enter != "jsr", exits=frozenset(world.exits))
        if world.entry_cycles:  # the interrupt sequence before the handler's first instruction
            found = Bounds(found.best + world.entry_cycles, found.worst + world.entry_cycles, found.instructions)
        return found
    except InputError as exc:
        raise InputError(f"{routine.spec_path}: static analysis: {exc} ([cycles] static = false skips it)") from None


def bounds_violations(routine: Routine, static: Bounds | None, t: Tally) -> list[str]:
    """Measured CPU cycles (stalls excluded) outside the static best/worst case."""
    if static is None or not t.cycles_count:
        return []
    out = []
    if t.cpu_min < static.best:
        out.append(f"{routine.name}: measured minimum {t.cpu_min} is below the static best case {static.best}")
    if t.cpu_max > static.worst:
        out.append(f"{routine.name}: measured maximum {t.cpu_max} is above the static worst case {static.worst}")
    return out


def budget_violations(routine: Routine, static: Bounds | None, t: Tally) -> list[str]:
    """The measured maximum and the static worst case against `[cycles] max`."""
    if routine.budget is None:
        return []
    out = []
    if t.cycles_count and t.cycles_max > routine.budget:
        out.append(f"{routine.name}: measured maximum {t.cycles_max} cycles is over the budget of "
                   f"{routine.budget} (inputs {describe_case(routine, t.max_case)})")
    if static is not None and static.worst > routine.budget:
        out.append(f"{routine.name}: the static worst case {static.worst} cycles is over the budget "
                   f"of {routine.budget}")
    return out
