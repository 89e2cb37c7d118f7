"""The verdicts beside the tally: static bounds of a routine (best and worst cycles from its bytes),
measured cycles against them, and both against the spec's budget."""

from __future__ import annotations

from collections.abc import Callable

from retro.analysis.check.results import describe_case
from retro.analysis.check.tally import Tally
from retro.cpu.flow import Bounds, analyse
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_N, FLAG_V, FLAG_Z
from retro.cpu.values import ANY, CLEAR, SET, MemoryModel, State, of_values, single
from retro.errors import InputError
from retro.routines.places import Port
from retro.routines.runner import RoutineRunner
from retro.routines.spec import Routine

FLAG_NAMES = {FLAG_C: "c", FLAG_Z: "z", FLAG_D: "d", FLAG_V: "v", FLAG_N: "n"}  # I: no timing depends on it
IO_AREAS = ((0xD000, 0xDFFF), (0x2000, 0x401F))  # with a scene: the C64's I/O, the NES PPU and APU registers


def static_bounds(routine: Routine, runner: RoutineRunner | None = None) -> Bounds | None:
    """Best and worst cycles from the routine's bytes (as loaded, after init), subroutines included;
    None when the spec turns the analysis off (`[cycles] static = false`)."""
    if not routine.static:
        return None
    runner = runner or RoutineRunner(routine)
    program = runner.program
    memory = bytes(runner.call_image)  # the code as loaded (after init), never memory the cases left behind
    bounds = dict(routine.loop_addresses)
    names = {address: label for label, address in sorted(program.symbols.items(), key=lambda kv: len(kv[0]))[::-1]}

    def describe(address: int) -> str:
        return f"${address:04X}" + (f" ({names[address]})" if address in names else "")
    model = MemoryModel(entry_memory(routine, memory, runner.start is not None, runner.memory_values), (program.origin, program.end))
    try:
        world = routine.world
        found = analyse(memory.__getitem__, runner.entry, bounds, name=routine.name,
                        within=(program.origin, program.end), describe=describe, cpu=routine.cpu,
                        memory=model, entry_state=entry_state(routine), facts={f.address: f.fact for f in routine.facts},
                        mocks=world.mock_costs(), interrupt=world.enter != "jsr", exits=frozenset(world.exits))
        if world.entry_cycles:  # the interrupt sequence before the handler's first instruction
            found = Bounds(found.best + world.entry_cycles, found.worst + world.entry_cycles, found.instructions,
                           found.modified)
        return found
    except InputError as exc:
        raise InputError(f"{routine.spec_path}: static analysis: {exc} ([cycles] static = false skips it)") from None


def _port_byte_sets(port: Port) -> list[int]:
    """Per place of an input, the set of byte values it may hold (retro.cpu.values)."""
    values = port.values
    if port.flag:
        return [(CLEAR if values.lo == 0 else 0) | (SET if values.hi >= 1 else 0)]
    if port.table:
        listed = values.listed if values.listed is not None else range(values.lo, values.hi + 1)
        return [of_values(listed)] * len(port.places)
    sets = []
    for k in range(len(port.places)):
        if values.listed is not None:
            sets.append(of_values(v >> (8 * k) for v in values.listed))
            continue
        lo, hi = values.lo >> (8 * k), values.hi >> (8 * k)  # a range's byte k runs over lo..hi (mod 256)
        sets.append(ANY if hi - lo >= 0xFF else of_values(range(lo, hi + 1)))
    return sets


def entry_state(routine: Routine) -> State:
    """Registers and flags on entry: an input's `values`, anything for what the spec does not name."""
    known: dict[str, int] = {}
    for name, value in routine.entry_state:  # `[entry]`: what the caller guarantees
        name = name.lower()
        if name in ("a", "x", "y"):
            known[name] = single(value)
        elif name in ("c", "z", "n", "v", "d"):
            known[name] = SET if value else CLEAR
    for port in routine.inputs:
        if port.via is not None:
            continue  # placed on the stack, in a slot or behind a pointer: memory, unknown here
        for place, values in zip(port.places, _port_byte_sets(port)):
            if place.kind == "register" and place.register in ("a", "x", "y"):
                known[place.register] = values
            elif place.kind == "flag" and place.bit in FLAG_NAMES:
                known[FLAG_NAMES[place.bit]] = values
    return State(**known)


def entry_memory(routine: Routine, image: bytes, io: bool, generated: dict[str, tuple[int, ...]]) -> Callable[[int], int]:
    """Memory on entry as sets: the image after init, the inputs' `values` where they go, any value in
    blocks made from the seed (another seed makes other bytes) and, with a scene (`io`), in the chips'
    register areas."""
    overrides: dict[int, int] = {}
    for port in routine.inputs:
        for place, values in zip(port.places, _port_byte_sets(port)):
            if place.kind == "memory":
                overrides[place.address] = values
    for block in routine.memory:
        if block.data is None:
            for offset in range(len(generated[block.name])):
                overrides[block.address + offset] = ANY
    for hardware in routine.world.hardware:  # a scripted read gives what the script says: any value here
        overrides[hardware.address] = ANY
    singles = [single(b) for b in image]

    def initial(address: int) -> int:
        if address in overrides:
            return overrides[address]
        if io and any(first <= address <= last for first, last in IO_AREAS):
            return ANY
        return singles[address]
    return initial


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
