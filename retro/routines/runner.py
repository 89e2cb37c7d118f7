"""Run one routine (a validated spec) on cases: a loaded machine, its memory set, the fast call path.

`RoutineRunner(routine, seed).run(case)` puts the case's values where the spec says (registers,
flags, memory; numbers little-endian, tables as bytes), calls the routine with `Machine.call_fast`
and returns (outputs, cycles): the outputs as a tuple in the spec's order. With `record`, the
executed path is appended for the independent timing model (retro.cpu.timing).

`run_batch(columns)` runs many cases at once on the batched core (retro.cpu.batch): every lane starts
from the memory as it stood after `init`, with its inputs in place.

Memory on the scalar path persists between calls: every input is written before each call, and so
are the output places in memory (restored to their value after `init`, so an output a routine writes
only on some paths reads the same on both engines); the `[memory]` blocks once after loading (then
`init` runs). A routine must not depend on anything else it wrote in an earlier call.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from retro.assembler import requested_tables
from retro.cpu.batch import BatchCpu
from retro.cpu.lane_memory import LaneMemoryFull
from retro.cpu.machine import (
    CALL_STACK_TOP,
    DEFAULT_BUDGET,
    DEFAULT_FLAGS,
    RETURN_TRAP,
    CallResult,
    push_return_trap,
)
from retro.cpu.mpu import FLAG_B, FLAG_U
from retro.cpu.timing import timing_table
from retro.errors import InputError
from retro.fileio import read_text
from retro.machines import build_machine
from retro.machines.c64 import vic_of
from retro.program import Program
from retro.routines.sandbox import bytes_of
from retro.routines.spec import Port, Routine, call_with
from retro.scenes.vic import VicScene
from retro.tables import GENERATORS, STORAGE_TABLES

NEEDS_A_VIC_SCENE = "--at-line needs a VIC-II scene (chip = \"vic-ii\")"
MEMORY_RNG_OFFSET = 1  # memory blocks draw from seed + 1, cases from seed: changing one never moves the other


@dataclass(frozen=True)
class Size:
    code_bytes: int  # from the origin up to the first generated table (the program's length without them)
    table_bytes: int  # lookup tables (storage the caller fills is not counted)
    storage_bytes: int


def routine_code(read, entries: list[int], within: tuple[int, int], cpu: str = "6510") -> dict[int, int]:
    """{address: length} of every instruction reachable from the entries (following branches, JMP and
    JSR into the program), as the static analysis decodes them; code it does not follow counts none."""
    from retro.cpu.flow import instruction_lengths

    return instruction_lengths(read, entries, within, cpu, skip_undecodable=True)


def program_size(program: Program, source_text: str | None, entries: list[int], read, cpu: str = "6510") -> Size:
    """The routine's bytes: its reachable instructions (the entry's and init's, with their subroutines)
    and the generated tables they name (by address, or by `#>table` for pointers set up at init)."""
    within = (program.origin, program.end)
    code = routine_code(read, entries, within, cpu)
    names = requested_tables(source_text) if source_text else []
    spans = {n: (program.symbols[n], program.symbols[n] + len(GENERATORS[n]())) for n in names if n in program.symbols}
    used = set()
    for pc, length in code.items():
        operand = read((pc + 1) & 0xFFFF) | (read((pc + 2) & 0xFFFF) << 8 if length == 3 else 0)
        for name, (first, end) in spans.items():
            if length == 3 and first <= operand < end:
                used.add(name)
            elif length == 2 and read(pc) == IMMEDIATE_LOAD_A and operand == first >> 8:
                used.add(name)  # lda #>table: a pointer's high byte, as set up by an init routine
    lookup = sum(len(GENERATORS[n]()) for n in used if n not in STORAGE_TABLES)
    storage = sum(len(GENERATORS[n]()) for n in used if n in STORAGE_TABLES)
    return Size(code_bytes=sum(code.values()), table_bytes=lookup, storage_bytes=storage)


IMMEDIATE_LOAD_A = 0xA9


def memory_values(routine: Routine, seed: int) -> dict[str, tuple[int, ...]]:
    """The bytes of every `[memory]` block for this seed (generators share one numpy Generator,
    called in the spec's order)."""
    rng = np.random.default_rng(seed + MEMORY_RNG_OFFSET)
    out = {}
    for block in routine.memory:
        if block.data is not None:
            out[block.name] = block.data
            continue
        try:
            made = call_with(block.make, {"rng": rng, "seed": seed})
            data = bytes_of(made, f"{routine.spec_path}: memory.{block.name}: the generator", 0x10000 - block.address)
        except InputError:
            raise
        except Exception as exc:
            raise InputError(f"{routine.spec_path}: memory.{block.name}: the generator raised "
                             f"{type(exc).__name__}: {exc}") from None
        if not data or any(not 0 <= v <= 0xFF for v in data) or block.address + len(data) > 0x10000:
            raise InputError(f"{routine.spec_path}: memory.{block.name}: the generator must return 1 or more "
                             f"bytes (0..255) that fit below $10000")
        out[block.name] = data
    return out


@dataclass(frozen=True)
class BatchOutcome:
    """What a batch of calls did: per output an array (n,) or (n, bytes), cycles, and per case the
    retro.cpu.batch.LaneError that stopped it (0: returned)."""

    outputs: list
    cycles: np.ndarray
    error: np.ndarray


def row_of(arrays: list, i: int) -> tuple:
    """Case i of per-output arrays ((n,) numbers or (n, bytes) tables) as the tuple a scalar run gives."""
    return tuple(tuple(a[i].tolist()) if a.ndim == 2 else int(a[i]) for a in arrays)


def _case_byte(value: Sequence[int], k: int) -> int:
    return value[k]


def _column_byte(value: np.ndarray, k: int) -> np.ndarray:
    return value[:, k]


@dataclass(frozen=True)
class InputPlan:
    """Where each input goes, worked out once per routine so a call does no lookups by name; the
    same plan puts one case (numbers) or a column block (arrays, one element per lane) in place."""

    registers: tuple[tuple[int, str, int], ...]  # (input index, register, byte shift)
    flags: tuple[tuple[int, int], ...]  # (input index, P bit)
    bytes: tuple[tuple[int, int, int], ...]  # (input index, address, byte shift)
    tables: tuple[tuple[int, tuple[int, ...]], ...]  # (input index, addresses)
    base_flags: int  # P before the flag inputs: the default flags without those the inputs set
    output_addresses: tuple[int, ...]  # output places in memory (restored before each Machine call)

    @classmethod
    def of(cls, routine: Routine) -> "InputPlan":
        registers, flags, places, tables = [], [], [], []
        for index, port in enumerate(routine.inputs):
            if port.flag:
                flags.append((index, port.places[0].bit))
            elif port.table:
                tables.append((index, tuple(p.address for p in port.places)))
            else:
                for byte, place in enumerate(port.places):
                    if place.kind == "register":
                        registers.append((index, place.register, 8 * byte))
                    else:
                        places.append((index, place.address, 8 * byte))
        forced = 0
        for _, bit in flags:
            forced |= bit
        outputs = sorted({place.address for port in routine.outputs for place in port.places if place.kind == "memory"})
        return cls(tuple(registers), tuple(flags), tuple(places), tuple(tables), DEFAULT_FLAGS & ~forced,
                   tuple(outputs))

    def place(self, values: Sequence, table_byte: Callable, write: Callable) -> tuple[dict[str, object], object]:
        """Put `values` (one per input: numbers, or arrays of lanes) in place: `write(address, byte)`
        for every memory byte as it is made (a block's arrays are consumed while in cache), and
        (register values, P) returned; `table_byte(value, k)` is byte k of a table input's value."""
        for index, address, shift in self.bytes:
            write(address, (values[index] >> shift) & 0xFF)
        for index, addresses in self.tables:
            for k, address in enumerate(addresses):
                write(address, table_byte(values[index], k))
        registers = {"a": 0, "x": 0, "y": 0}
        for index, register, shift in self.registers:
            registers[register] |= (values[index] >> shift) & 0xFF
        p = self.base_flags
        for index, bit in self.flags:
            p |= (values[index] != 0) * bit
        return registers, p


@dataclass(frozen=True)
class RasterStart:
    """Run every call with a VIC-II scene on the bus and the beam at this line and cycle (the CPU
    then stalls on Bad Lines and sprite DMA as on a real C64)."""

    scene: VicScene
    line: int
    cycle: int = 1


class RoutineRunner:
    def __init__(self, routine: Routine, seed: int = 0, start: RasterStart | None = None) -> None:
        self.routine = routine
        self.seed = seed
        self.start = start
        self.program = routine.program  # read once, by the spec
        self.vic = None
        if start is None:
            self.machine = build_machine(cpu=routine.cpu)
        else:
            if start.scene.cpu_variant != routine.cpu:
                raise InputError(f"--scene: a {start.scene.cpu_variant} scene cannot run the {routine.cpu} routine "
                                 f"{routine.name}")
            if not isinstance(start.scene, VicScene):
                raise InputError(NEEDS_A_VIC_SCENE)
            self.machine = build_machine(start.scene)
            self.vic = vic_of(self.machine)
        self.machine.load(self.program)
        self.last_stolen = 0  # cycles of the last call in which the VIC-II held the CPU
        self.entry = routine.entry_address
        self.memory_values = memory_values(routine, seed)
        memory = self.machine.memory
        for block in routine.memory:
            data = self.memory_values[block.name]
            memory[block.address:block.address + len(data)] = list(data)
        self.code_image = bytes(self.machine.memory)  # before init and the cases patch anything
        if routine.init is not None:
            self.machine.call_fast(routine.init_address, budget=self.limit)
        self.call_image = bytearray(self.machine.memory)  # what every call starts from (the batch's image)
        # (indirect),Y instructions: the timing model needs their pointer (and the 65C02's BBR/BBS the
        # zero-page byte they test). Every byte of the program that could be such an opcode is listed;
        # a data byte in the set only costs a lookup.
        indirect_y = {opcode for opcode, op in timing_table(routine.cpu).items() if op.mode in ("iny", "zpr")}
        self.pointer_pcs = frozenset(self.program.origin + i for i, b in enumerate(self.program.code) if b in indirect_y)
        self.plan = InputPlan.of(routine)
        self.watched_facts = {fact.address: fact for fact in routine.facts}  # held against every call

    @property
    def limit(self) -> int:
        return self.routine.limit or DEFAULT_BUDGET

    def inputs_for_call(self, case: Sequence) -> tuple[list[tuple[int, int]], dict[str, int], int]:
        """(memory writes, register values, P) that put the case where the spec says; the output
        places in memory are restored first (see the module's docstring)."""
        image = self.call_image
        writes = [(address, image[address]) for address in self.plan.output_addresses]
        registers, p = self.plan.place(case, _case_byte, lambda address, byte: writes.append((address, byte)))
        return writes, registers, p

    def run(self, case: Sequence, record: list | None = None) -> tuple[tuple, int]:
        """(outputs in the spec's order, cycles) of one call."""
        writes, registers, p = self.inputs_for_call(case)
        if self.vic is not None:
            self._restart_beam()
            stolen = self.machine.mpu.stolen
        cycles, a, x, y, p = self.machine.call_fast(self.entry, writes, **registers, p=p, budget=self.limit,
                                                    record=record, pointer_pcs=self.pointer_pcs)
        if self.vic is not None:
            self.last_stolen = self.machine.mpu.stolen - stolen
        return self.outputs(a, x, y, p), cycles

    def _restart_beam(self) -> None:
        self.vic.restart(self.machine.cycle, self.start.line, self.start.cycle)
        self.machine.mpu.ba_high_until = -1  # the CPU's note of how long BA stays high was for the old beam

    def answer(self, case: Sequence) -> int:
        """The first output of one call (the hit flag or value of a single-output routine)."""
        return self.run(case)[0][0]

    def set_memory(self, name: str, values: Sequence[int]) -> None:
        """Replace a `[memory]` block's bytes (what the reference is given too)."""
        block = next((b for b in self.routine.memory if b.name == name), None)
        if block is None:
            raise InputError(f"{self.routine.spec_path}: no memory block {name!r}")
        data = tuple(int(v) for v in values)
        self.machine.memory[block.address:block.address + len(data)] = list(data)
        self.call_image[block.address:block.address + len(data)] = bytes(data)
        self.memory_values[name] = data

    @property
    def batchable(self) -> bool:
        """Whether the batched core can run this routine (it has no chips: not with a scene)."""
        return self.vic is None

    def run_batch(self, columns: list) -> "BatchOutcome":
        """Run every case of a column block (one array per input) on the batched core."""
        n = len(columns[0])
        try:
            return self._run_lanes(columns, n)
        except LaneMemoryFull:
            if n <= 1:
                raise
            half = n // 2
            first = self.run_batch([c[:half] for c in columns])
            second = self.run_batch([c[half:] for c in columns])
            return BatchOutcome([np.concatenate(pair) for pair in zip(first.outputs, second.outputs)],
                                np.concatenate([first.cycles, second.cycles]),
                                np.concatenate([first.error, second.error]))

    def _run_lanes(self, columns: list, n: int) -> "BatchOutcome":
        image = bytearray(self.call_image)
        stack_pointer = push_return_trap(image)
        cpu = BatchCpu(self.routine.cpu, image, n)
        registers, p = self.plan.place(columns, _column_byte, cpu.memory.fill)
        for name, value in registers.items():
            lanes = getattr(cpu, name)
            lanes |= np.asarray(value).astype(lanes.dtype)
        cpu.p[:] = (p | FLAG_U) & ~FLAG_B  # as Machine sets P
        cpu.sp[:] = stack_pointer
        image = self.call_image
        cpu.watch = {pc: (lambda lanes, fact=fact, opcode=image[pc]: fact.broken(lanes.a, lanes.x, lanes.y, lanes.p,
                                                                                 opcode))
                     for pc, fact in self.watched_facts.items()}
        cpu.call(self.entry, self.limit, RETURN_TRAP, CALL_STACK_TOP)
        outputs = port_values(self.routine.outputs, {"a": cpu.a, "x": cpu.x, "y": cpu.y}, cpu.p, cpu.read,
                              widen=lambda lanes: np.asarray(lanes, dtype=np.int64),
                              table=lambda columns: np.stack(columns, axis=1).astype(np.int64))
        return BatchOutcome(outputs, cpu.cycles, cpu.error)

    def outputs(self, a: int, x: int, y: int, p: int) -> tuple:
        return tuple(port_values(self.routine.outputs, {"a": a, "x": x, "y": y}, p, self.machine.memory.__getitem__,
                                 widen=int, table=tuple))

    def traced(self, case: Sequence) -> CallResult:
        """The same call with the instruction trace (for the report of a failing case)."""
        writes, registers, p = self.inputs_for_call(case)
        if self.vic is not None:
            self._restart_beam()
        return self.machine.call(self.entry, **registers, p=p, memory={address: [v] for address, v in writes},
                                 budget=self.limit, trace=True)

    def size(self) -> Size:
        """Bytes of code, lookup tables and caller-filled storage of the routine's program."""
        source = self.routine.program_file
        text = read_text(source, "source file") if source.suffix.lower() in (".s", ".asm", ".oph") else None
        entries = [self.entry] + ([self.routine.init_address] if self.routine.init is not None else [])
        return program_size(self.program, text, entries, self.code_image.__getitem__, self.routine.cpu)


def port_values(ports: Sequence[Port], registers: dict, p, read: Callable, widen: Callable, table: Callable) -> list:
    """The outputs of a call, one value per port in the spec's order, read from the registers, P and
    memory (`read(address)`): the same code for one call (ints) and for lanes of the batched core
    (arrays), which differ only in `widen` (a byte or a flag as the output's number type) and
    `table` (bytes of a table output together)."""
    values = []
    for port in ports:
        if port.flag:
            values.append(widen((p & port.places[0].bit) != 0))
        elif port.table:
            values.append(table([read(place.address) for place in port.places]))
        else:
            value = widen(0)
            for shift, place in enumerate(port.places):
                byte = registers[place.register] if place.kind == "register" else read(place.address)
                value = value | widen(byte) << (8 * shift)
            values.append(value)
    return values


def describe_value(port: Port, value) -> str:
    if port.table:
        return "[" + " ".join(f"{v:02x}" for v in value) + "]"
    return str(value)
