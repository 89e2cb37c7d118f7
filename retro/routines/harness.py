"""Run one registered routine on cases: a loaded machine, the world in memory, the fast call path.

`RoutineRunner(routine, world).run(case)` writes the case's bytes to the routine's zero-page inputs
and registers (inputs named A, X, Y, or C for the carry flag, set when the case's value is non-zero),
calls it with `Machine.call_fast` and returns (answer, cycles, steps) where steps is the executed
path that the independent timing model (retro.cpu.timing) needs.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from retro.assembler import assemble_file, requested_tables
from retro.cpu.machine import DEFAULT_FLAGS, Machine
from retro.cpu.timing import OPCODES
from retro.program import Program
from retro.routines.registry import Routine, World
from retro.routines.screen import SCREEN_BASE
from retro.tables import GENERATORS, STORAGE_TABLES

FLAG_C = 0x01
REGISTER_INPUTS = ("A", "X", "Y", "C")  # input names that are registers (C: the carry flag), not zero page
_INSTRUCTION_LINE = re.compile(r"^\s*(?P<address>[0-9A-Fa-f]{4})  (?P<bytes>(?:[0-9A-Fa-f]{2} ){1,3})\s*[A-Z]{3}\b")


@dataclass(frozen=True)
class Size:
    code_bytes: int  # from the origin up to the first generated table
    table_bytes: int  # lookup tables (storage the caller fills is not counted)
    storage_bytes: int


def program_size(program: Program, source_text: str) -> Size:
    names = requested_tables(source_text)
    starts = [program.symbols[n] for n in names if n in program.symbols]
    tables_start = min(starts) if starts else program.end
    code_end = program.origin
    for line in program.listing.splitlines():  # instructions, not the page-alignment padding
        match = _INSTRUCTION_LINE.match(line)
        if match and int(match.group("address"), 16) < tables_start:
            code_end = max(code_end, int(match.group("address"), 16) + len(match.group("bytes").split()))
    lookup = sum(len(GENERATORS[n]()) for n in names if n not in STORAGE_TABLES)
    storage = sum(len(GENERATORS[n]()) for n in names if n in STORAGE_TABLES)
    return Size(code_bytes=code_end - program.origin, table_bytes=lookup, storage_bytes=storage)


class RoutineRunner:
    def __init__(self, routine: Routine, world: World) -> None:
        self.routine = routine
        self.world = world
        self.program = assemble_file(routine.source)
        self.machine = Machine()
        self.machine.load(self.program)
        symbols = self.program.symbols
        self.entry = symbols[routine.name]
        zero_page = [(i, name) for i, name in enumerate(routine.inputs) if name not in REGISTER_INPUTS]
        self.addresses = [symbols[name] for _, name in zero_page]
        self.zero_page_slots = [i for i, _ in zero_page]
        self.register_slots = {name: i for i, name in enumerate(routine.inputs) if name in REGISTER_INPUTS}
        memory = self.machine.memory
        self.pointer_pcs = self._indirect_y_pcs()
        if routine.init:
            self.machine.call_fast(symbols[routine.init])
        if world.screen:
            memory[SCREEN_BASE:SCREEN_BASE + len(world.screen)] = list(world.screen)
        if world.props:
            start = symbols["tile_props"]
            memory[start:start + len(world.props)] = list(world.props)
        self.current_pair = -1

    def size(self) -> Size:
        """Bytes of code, lookup tables and caller-filled storage of the routine's program."""
        return program_size(self.program, self.routine.source.read_text())

    def _indirect_y_pcs(self) -> frozenset[int]:
        """PCs of the (indirect),Y instructions reachable in the listing (the model needs their pointer)."""
        pcs = set()
        for line in self.program.listing.splitlines():
            parts = line.split()
            if len(parts) >= 2 and len(parts[0]) == 4:
                try:
                    pc, opcode = int(parts[0], 16), int(parts[1], 16)
                except ValueError:
                    continue
                op = OPCODES.get(opcode)
                if op and op.mode == "iny":
                    pcs.add(pc)
        return frozenset(pcs)

    def _set_masks(self, pair: int) -> None:
        if pair != self.current_pair:
            memory = self.machine.memory
            for label, data in zip(("pixel_mask_a", "pixel_mask_b"), self.world.masks[pair]):
                start = self.program.symbols[label]
                memory[start:start + len(data)] = list(data)
            self.current_pair = pair

    def run(self, case: tuple, record: list | None = None) -> tuple[int, int]:
        """(answer, cycles) of one call; with `record`, the executed path is appended to it."""
        if self.routine.name == "pixel":
            self._set_masks(case[2])
        writes = [(address, case[i]) for address, i in zip(self.addresses, self.zero_page_slots)]
        registers = {name.lower(): case[i] for name, i in self.register_slots.items() if name != "C"}
        carry = "C" in self.register_slots and case[self.register_slots["C"]] != 0
        cycles, a, x, _, p = self.machine.call_fast(self.entry, writes, **registers, p=DEFAULT_FLAGS | (FLAG_C if carry else 0),
                                                    record=record, pointer_pcs=self.pointer_pcs)
        output = self.routine.output
        if output == "carry":
            return p & FLAG_C, cycles
        if output == "product":
            return x | a << 8, cycles
        return a, cycles
