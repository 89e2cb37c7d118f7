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

import functools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from retro.assembler import requested_tables
from retro.cpu.batch import BatchCpu, LaneCoverage, LaneError
from retro.cpu.lane_memory import LaneMemoryFull
from retro.cpu.machine import (
    DEFAULT_BUDGET,
    ENTRY_S,
    RETURN_TRAP,
    STACK_BASE,
    CallResult,
    interrupt_entry_flags,
    push_interrupt_frame,
    push_return_trap,
    return_s,
)
from retro.chips.vic.constants import IRQ_SOURCES, REG_IRQ_ENABLE
from retro.cpu.mpu import FLAG_B, FLAG_I, FLAG_U
from retro.cpu.variants import VARIANTS
from retro.cpu.timing import TimingError, timing_of, timing_table
from retro.errors import InputError, RunError
from retro.fileio import read_text
from retro.machines import build_machine
from retro.machines.c64 import vic_of
from retro.program import Program
from retro.routines.chip_access import BusStalls, chip_free
from retro.routines.entry import EntryState, variant_memory, variant_stack
from retro.routines.sandbox import bytes_of
from retro.routines.spec import Port, Routine, call_with
from retro.routines.world import NO_WORLD, WORLD_PLACES, BatchWorld, MachineWorld, World, chip_overlaps
from retro.scenes.vic import VicScene
from retro.tables import GENERATORS, STORAGE_TABLES

NEEDS_A_VIC_SCENE = "--at-line needs a VIC-II scene (chip = \"vic-ii\")"
MEMORY_RNG_OFFSET = 1  # memory blocks draw from seed + 1, cases from seed: changing one never moves the other


@dataclass(frozen=True)
class Size:
    code_bytes: int  # from the origin up to the first generated table (the program's length without them)
    table_bytes: int  # lookup tables and the `[memory]` blocks the routine read (storage the caller fills: not)
    storage_bytes: int
    table_blocks: tuple[tuple[str, int], ...] = ()  # (name, bytes) of the `[memory]` blocks among the tables


PROBE_CASES = 2_000  # cases of each part run to see which `[memory]` blocks a routine reads
STORES = frozenset({"STA", "STX", "STY", "STZ", "SAX", "SHA", "SHX", "SHY", "TAS"})  # write, never read
NO_DATA = frozenset({"JMP", "JSR", "BRK", "RTS", "RTI"})


def data_address(read, pc: int, x: int, y: int, pointer: int, cpu: str) -> int | None:
    """The address the instruction at pc reads its operand from (registers before it, `pointer`: the
    word of an (indirect),Y instruction as recorded), or None when it reads none."""
    try:
        op = timing_of(read(pc), cpu)
    except TimingError:
        return None
    if op.mnemonic in STORES or op.mnemonic in NO_DATA:
        return None
    mode, lo = op.mode, read((pc + 1) & 0xFFFF)
    if mode == "zpg":
        return lo
    if mode in ("zpx", "zpy"):
        return (lo + (x if mode == "zpx" else y)) & 0xFF
    if mode in ("abs", "abx", "aby"):
        return ((lo | read((pc + 2) & 0xFFFF) << 8) + (x if mode == "abx" else y if mode == "aby" else 0)) & 0xFFFF
    if mode == "iny":
        return (pointer + y) & 0xFFFF
    if mode in ("inx", "zpi"):  # the pointer as memory holds it after the call (not recorded)
        at = (lo + (x if mode == "inx" else 0)) & 0xFF
        return read(at) | read((at + 1) & 0xFF) << 8
    return None


def routine_code(read, entries: list[int], within: tuple[int, int], cpu: str = "6510",
                 world: World = NO_WORLD) -> dict[int, int]:
    """{address: length} of every instruction reachable from the entries (following branches, JMP and
    JSR into the program), as the static analysis decodes them (an interrupt handler's RTI and the
    world's exits end a path); code it does not follow counts none."""
    from retro.cpu.flow import OPCODE_RTI, OPCODE_RTS, instruction_lengths

    ends = frozenset({OPCODE_RTS, OPCODE_RTI}) if world.enter != "jsr" else frozenset({OPCODE_RTS})
    return instruction_lengths(read, entries, within, cpu, skip_undecodable=True, ends=ends,
                               exits=frozenset(world.exits))


def program_size(program: Program, source_text: str | None, entries: list[int], read, cpu: str = "6510",
                 world: World = NO_WORLD, blocks: Sequence[tuple[str, int, int]] = ()) -> Size:
    """The routine's bytes: its reachable instructions (the entry's and init's, with their subroutines)
    and the generated tables they name (by address, or by `#>table` for pointers set up at init)."""
    within = (program.origin, program.end)
    code = routine_code(read, entries, within, cpu, world)
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
    counted = [spans[n] for n in used]  # a `[memory]` block inside a generated table is that table
    read_blocks = [(name, start, size) for name, start, size in blocks
                   if not any(first <= start < end for first, end in counted)]
    return Size(code_bytes=sum(code.values()), table_bytes=lookup + sum(size for _, _, size in read_blocks),
                storage_bytes=storage, table_blocks=tuple((name, size) for name, _, size in read_blocks))


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
    retro.cpu.batch.LaneError that stopped it (0: returned); `coverage`: what the lanes ran, when asked."""

    outputs: list
    cycles: np.ndarray
    error: np.ndarray
    stolen: np.ndarray | None = None  # per case, the cycles a scene's chip held the CPU (None: no chip)
    coverage: LaneCoverage | None = None
    mock_calls: list | None = None  # per case, the calls of the mocks the reference takes (retro.routines.world)


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
    base_registers: tuple[tuple[str, int], ...] = (("a", 0), ("x", 0), ("y", 0))  # before the inputs ([entry])
    vias: "ViaPlan | None" = None  # inputs and outputs placed by the case (stack, table slot, pointer)
    entry_s: int = ENTRY_S  # S at entry when no input sets it

    def __post_init__(self) -> None:  # what every call starts from, worked out once (a call is microseconds)
        object.__setattr__(self, "_start", {**dict(self.base_registers), "s": self.entry_s})
        object.__setattr__(self, "_s_varies", any(register == "s" for _, register, _ in self.registers))

    @property
    def s_varies(self) -> bool:
        """An input sets S (each call, or each lane, has its own)."""
        return self._s_varies

    @classmethod
    def of(cls, routine: Routine, image: Sequence[int] | None = None, salt: int = 0) -> "InputPlan":
        registers, flags, places, tables = [], [], [], []
        for index, port in enumerate(routine.inputs):
            if port.via is not None:
                continue  # placed by ViaPlan
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
        vias = ViaPlan.of(routine, image, salt) if any(p.via for p in routine.inputs + routine.outputs) else None
        entry = EntryState.of(routine.entry_state, routine.inputs)
        return cls(tuple(registers), tuple(flags), tuple(places), tuple(tables),
                   (entry.flags | FLAG_U) & ~forced, tuple(outputs),
                   tuple(entry.registers.items()), vias, routine.entry_s)

    def place(self, values: Sequence, table_byte: Callable, write: Callable,
              entry: tuple[dict, object, int] | None = None, scatter: Callable | None = None,
              select: Callable | None = None) -> tuple[dict[str, object], object]:
        """Put `values` (one per input: numbers, or arrays of lanes) in place: `write(address, byte)`
        for every memory byte as it is made (a block's arrays are consumed while in cache), and
        (register values, P) returned; `table_byte(value, k)` is byte k of a table input's value.
        `entry`: (free registers by name, free P bits, the free bits' mask) of an entry-state run
        (retro.routines.entry), replacing the baseline's values of the registers and flags no input
        or `[entry]` sets. Inputs placed by the case go through `scatter(address, byte)` (the
        address: a number, or one per lane) and `select(condition, a, b)` (a where b otherwise)."""
        for index, address, shift in self.bytes:
            write(address, (values[index] >> shift) & 0xFF)
        for index, addresses in self.tables:
            for k, address in enumerate(addresses):
                write(address, table_byte(values[index], k))
        if self.vias is not None:
            self.vias.place(values, table_byte, scatter or write, select or _case_select)
        registers = dict(self._start)
        p = self.base_flags
        if entry is not None:
            free, bits, mask = entry
            registers.update(free)
            p = (p & ~mask) | bits
        for index, register, shift in self.registers:
            if register == "s":
                registers["s"] = values[index]
                continue
            registers[register] |= (values[index] >> shift) & 0xFF
        for index, bit in self.flags:
            p |= (values[index] != 0) * bit
        return registers, p


def _slots(routine: Routine, port: Port) -> dict[int, list[tuple[int, int]]]:
    """A table slot port: every address its index may pick -> the (slot, byte) pairs placed there."""
    via = port.via
    wrap = 0xFF if via.base < 0x100 else 0xFFFF
    index = routine.inputs[via.index_input].values
    at: dict[int, list[tuple[int, int]]] = {}
    for slot in (index.listed if index.listed is not None else range(index.lo, index.hi + 1)):
        for i in range(len(port.places)):
            at.setdefault((via.base + slot + i) & wrap, []).append((slot, i))
    return at


def _case_select(condition, a, b):
    return a if condition else b


def _byte(port: Port, value, i: int, table_byte: Callable):
    """Byte i of an input's value: of a table, or of a little-endian number."""
    return table_byte(value, i) if port.table else (value >> (8 * i)) & 0xFF


FILLER_MIX = (0x2D, 0x65, 0x1F, 0x9D)  # small odd multipliers: every term stays far below 2^63 (ints and int64 alike)


@dataclass(frozen=True)
class ViaPlan:
    """Where the inputs and outputs placed by the case go (retro.routines.places.Via), worked out once:
    the same arithmetic places one case (ints) or a column block (arrays: one address per lane). An
    input in a slot of a table fills every other slot its index may pick with a value other than its
    own (from the case and the seed), so that a routine reading the wrong slot reads a wrong value."""

    routine: Routine
    pointers: dict  # the address of a pointer no input sets -> its value in memory after `init`
    salt: int
    slot_maps: dict  # (section, port index) of a table slot port -> {address: [(slot, byte), ...]}

    @classmethod
    def of(cls, routine: Routine, image: Sequence[int] | None, salt: int) -> "ViaPlan":
        pointers = {}
        for port in routine.inputs + routine.outputs:
            via = port.via
            if via is not None and via.mode == "pointer" and via.pointer_input < 0:
                high = (via.base + 1) & (0xFF if via.base < 0x100 else 0xFFFF)
                pointers[via.base] = (image[via.base] | image[high] << 8) if image is not None else 0
        slot_maps = {(section, k): _slots(routine, port) for section, ports in (("in", routine.inputs),
                                                                                ("out", routine.outputs))
                     for k, port in enumerate(ports) if port.via is not None and port.via.mode == "indexed"}
        return cls(routine, pointers, salt & 0xFFFF, slot_maps)

    def address(self, via, values: Sequence, i: int):
        """The address of byte i of a port placed by `via`, for a case (or per lane of a block)."""
        if via.mode == "stack":
            s = values[via.s_input] if via.s_input >= 0 else self.routine.entry_s
            return STACK_BASE | ((s + via.base + i) & 0xFF)
        index = values[via.index_input] if via.index_input >= 0 else 0
        if via.mode == "indexed":
            return (via.base + index + i) & (0xFF if via.base < 0x100 else 0xFFFF)
        pointer = values[via.pointer_input] if via.pointer_input >= 0 else self.pointers[via.base]
        return (pointer + via.offset + index + i) & 0xFFFF

    def place(self, values: Sequence, table_byte: Callable, scatter: Callable, select: Callable) -> None:
        for k, port in enumerate(self.routine.inputs):
            via = port.via
            if via is None:
                continue
            value = values[k]
            if via.mode != "indexed":
                for i in range(len(port.places)):
                    scatter(self.address(via, values, i), _byte(port, value, i, table_byte))
                continue
            index = values[via.index_input]
            for address, placed in self.slot_maps["in", k].items():
                slot, i = placed[0]
                byte = _byte(port, value, i, table_byte)
                mixed = (byte * FILLER_MIX[0] + slot * FILLER_MIX[1] + i * FILLER_MIX[2] + (index & 0xFF) * FILLER_MIX[3]
                         + (value & 0xFFFF if not port.table else 0) + self.salt + k)
                chosen = byte ^ (1 + (mixed ^ (mixed >> 5)) % 255)  # never the slot's own byte
                for slot, i in placed:
                    chosen = select(index == slot, _byte(port, value, i, table_byte), chosen)
                scatter(address, chosen)

    def touched(self, values: Sequence) -> list[int]:
        """Every address the case's ports placed by the case take (a table slot port: every slot):
        what Machine restores before the next call, so that each call starts as a batch lane does."""
        found = []
        for section, ports in (("in", self.routine.inputs), ("out", self.routine.outputs)):
            for k, port in enumerate(ports):
                if port.via is not None:
                    found += (list(self.slot_maps[section, k]) if port.via.mode == "indexed" else
                              [self.address(port.via, values, i) for i in range(len(port.places))])
        return found

    def outputs(self, values: Sequence) -> dict[int, list]:
        """Output index -> the addresses of its bytes for this case (or per lane)."""
        return {k: [self.address(port.via, values, i) for i in range(len(port.places))]
                for k, port in enumerate(self.routine.outputs) if port.via is not None}


@dataclass(frozen=True)
class RasterStart:
    """Run every call with a VIC-II scene on the bus and the beam at this line and cycle (the CPU
    then stalls on Bad Lines and sprite DMA as on a real C64), the frame drawn so far in the
    collision latches and $D019 (unread, unacknowledged)."""

    scene: VicScene
    line: int
    cycle: int = 1


class RoutineRunner:
    def __init__(self, routine: Routine, seed: int = 0, start: RasterStart | None = None,
                 fill: str | None = None) -> None:
        """`fill`: an entry-state variant ("ones", "random": retro.routines.entry) whose bytes every
        address holds that the machine, the program, the `[memory]` blocks and `init` leave alone;
        None: zeros (power-on RAM), the baseline."""
        self.routine = routine
        self.seed = seed
        self.start = start
        self.fill = fill
        self.entry_state = EntryState.of(routine.entry_state, routine.inputs, vary_interrupt=start is None)
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
        if fill is not None:  # before anything is loaded: what stays untouched keeps the variant's bytes
            memory = np.asarray(self.machine.memory, dtype=np.uint8)
            self.machine.memory[:] = np.where(memory == 0, variant_memory(fill, seed), memory).tolist()
        if fill is not None:
            self.machine.stack_top = variant_stack(fill, seed)
        self.machine.load(self.program)
        if start is not None:  # before the world's own devices join the bus
            chip_overlaps(routine, self.machine.bus.devices, str(start.scene.source))
        self.world = None if routine.world.empty else MachineWorld(routine.world, self.machine, str(routine.spec_path))
        self.last_stolen = 0  # cycles of the last call in which the VIC-II held the CPU
        self.entry = routine.entry_address
        self.memory_values = memory_values(routine, seed)
        memory = self.machine.memory
        for block in routine.memory:
            data = self.memory_values[block.name]
            memory[block.address:block.address + len(data)] = list(data)
        self.code_image = bytes(self.machine.memory)  # before init and the cases patch anything
        if self.world is not None:
            self.world.place_traps()  # mocks and exits (init may call a mock too)
        if routine.init is not None:
            self.machine.call_fast(routine.init_address, budget=self.limit)
        self.call_image = bytearray(self.machine.memory)  # what every call starts from (the batch's image)
        # (indirect),Y instructions: the timing model needs their pointer (and the 65C02's BBR/BBS the
        # zero-page byte they test). Every byte of the program that could be such an opcode is listed;
        # a data byte in the set only costs a lookup.
        indirect_y = {opcode for opcode, op in timing_table(routine.cpu).items() if op.mode in ("iny", "zpr")}
        self.pointer_pcs = frozenset(self.program.origin + i for i, b in enumerate(self.program.code) if b in indirect_y)
        self.plan = InputPlan.of(routine, self.call_image, seed)
        self._dirty: list[int] = []  # addresses the last call's ports placed by the case took (restored)
        self.watched_facts = {fact.address: fact for fact in routine.facts}  # held against every call
        self.written_kept: dict[str, int] = {}  # per hardware entry, the values written that outputs show
        for port in routine.outputs:
            for place in port.places:
                if place.kind == "written":
                    self.written_kept[place.register] = max(self.written_kept.get(place.register, 0), place.bit + 1)
        self.fallbacks: dict[int, int] = {}  # compiled engine: calls it left to the batched core, by status
        self._machine_s = not self.plan.s_varies and routine.entry_s == ENTRY_S  # S from the machine's stack top

    @property
    def limit(self) -> int:
        return self.routine.limit or DEFAULT_BUDGET

    def inputs_for_call(self, case: Sequence, entry: tuple[dict, int, int] | None = None
                        ) -> tuple[list[tuple[int, int]], dict[str, int], int]:
        """(memory writes, register values, P) that put the case where the spec says; the output
        places in memory are restored first (see the module's docstring). `entry`: an entry-state
        run's free registers and P bits (InputPlan.place)."""
        image = self.call_image
        writes = [(address, image[address]) for address in self.plan.output_addresses]
        if self.plan.vias is not None:
            touched = self.plan.vias.touched(case)
            writes += [(address, image[address]) for address in self._dirty + touched]
            self._dirty = touched
        registers, p = self.plan.place(case, _case_byte, lambda address, byte: writes.append((address, byte)), entry)
        if self._machine_s:
            registers["s"] = self.machine.entry_s  # the machine's stack top (the entry-state runs vary it)
        return writes, registers, p

    def reset_memory(self, image: bytes) -> None:
        """Start the following calls from this memory image (entry-state runs, naming a dependence)."""
        self.machine.memory[:] = list(image)
        self.call_image = bytearray(image)

    def run(self, case: Sequence, record: list | None = None, entry: tuple[dict, int, int] | None = None
            ) -> tuple[tuple, int]:
        """(outputs in the spec's order, cycles) of one call; `entry` as in `inputs_for_call`. With a
        world, `record` leaves out the traps (mocks, exits) and `last_extra_cycles` says what the timing
        model must add for them and for an interrupt entry; `last_calls` holds the recorded mocks' calls."""
        writes, registers, p = self.inputs_for_call(case, entry)
        if self.vic is not None:
            self.restart_beam()
            stolen = self.machine.mpu.stolen
        located = self.plan.vias.outputs(case) if self.plan.vias is not None else None
        world = self.world
        if world is None:
            cycles, a, x, y, p = self.machine.call_fast(self.entry, writes, **registers, p=p, budget=self.limit,
                                                        record=record, pointer_pcs=self.pointer_pcs)
        else:
            world.reset(self.machine.cycle)
            cycles, a, x, y, p = self.machine.call_fast(self.entry, writes, **registers, p=self._entry_p(p),
                                                        budget=self.limit, record=record, pointer_pcs=self.pointer_pcs,
                                                        enter=self.routine.world.enter)
        if self.vic is not None:
            self.last_stolen = self.machine.mpu.stolen - stolen
        if world is not None:
            if record is not None:
                traps = world.actions
                record[:] = [step for step in record if step[0] not in traps]
            self.last_extra_cycles = world.trap_cycles + self.routine.world.entry_cycles
            self.last_calls = world.recorded_calls()
        return self.outputs(a, x, y, p, located), cycles

    last_extra_cycles = 0
    last_calls: dict | None = None

    def _entry_p(self, p):
        """P at entry; an IRQ handler's pushed P has I clear (the CPU takes an IRQ only then)."""
        return p & ~FLAG_I if self.routine.world.enter == "irq" else p

    def restart_beam(self) -> None:
        self.vic.restart(self.machine.cycle, self.start.line, self.start.cycle, drawn=True)
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
        """Whether the batched core can run this routine: without a scene, or with one when no call
        can touch a chip register or be interrupted (`engine_reason` says why or why not)."""
        return self.chip_verdict[0] and self.batch_refusal is None

    @property
    def engine_reason(self) -> str | None:
        """Why the batched core may or may not run the calls with the scene (None without a scene)."""
        return None if self.vic is None else self.chip_verdict[1]

    @functools.cached_property
    def bus_stalls(self) -> BusStalls:
        """The VIC-II's stalls per lane from the start line and cycle (the scene's BA schedule)."""
        video = self.vic.video
        start = self.start.line * video.cycles_per_line + self.start.cycle - 1
        return BusStalls(self.vic.bus.wait, start, self.machine.mpu.write_masks)

    @functools.cached_property
    def chip_verdict(self) -> tuple[bool, str]:
        if self.vic is None:
            return True, ""
        memory = self.machine.memory
        pages = frozenset(page for page, device in enumerate(self.machine.bus.page_devices) if device is not None)
        interrupts = bool(self.vic.registers[REG_IRQ_ENABLE] & IRQ_SOURCES)
        if interrupts and (not self.plan.base_flags & FLAG_I or any(bit == FLAG_I for _, bit in self.plan.flags)):
            return False, "the scene enables VIC-II interrupts and I may be clear on entry"
        return chip_free(memory.__getitem__, self.entry, (self.program.origin, self.program.end), pages,
                         self.routine.cpu, interrupts)

    @property
    def batch_refusal(self) -> str | None:
        """Why the batched core cannot run this routine's world (None: it can; a scene aside)."""
        return self.routine.world.batch_refusal()

    def run_batch(self, columns: list, coverage: bool = False, first_lanes: bool = False,
                  entry: tuple[dict, np.ndarray, int] | None = None) -> "BatchOutcome":
        """Run every case of a column block (one array per input) on the batched core (`coverage`:
        count what the lanes ran; `first_lanes`: also which lane first went each way at each branch;
        `entry`: an entry-state run's free registers and P bits per lane, InputPlan.place)."""
        n = len(columns[0])
        try:
            return self._run_lanes(columns, n, coverage, first_lanes, entry)
        except LaneMemoryFull:
            if n <= 1:
                raise
            half = n // 2
            halves = [None, None] if entry is None else [
                ({k: v[:half] for k, v in entry[0].items()}, entry[1][:half], entry[2]),
                ({k: v[half:] for k, v in entry[0].items()}, entry[1][half:], entry[2])]
            first = self.run_batch([c[:half] for c in columns], coverage, first_lanes, halves[0])
            second = self.run_batch([c[half:] for c in columns], coverage, first_lanes, halves[1])
            if first.coverage is not None:
                first.coverage.merge(second.coverage, lane_offset=half)
            return BatchOutcome([np.concatenate(pair) for pair in zip(first.outputs, second.outputs)],
                                np.concatenate([first.cycles, second.cycles]),
                                np.concatenate([first.error, second.error]),
                                None if first.stolen is None else np.concatenate([first.stolen, second.stolen]),
                                coverage=first.coverage,
                                mock_calls=None if first.mock_calls is None else first.mock_calls + second.mock_calls)

    def compiled(self):
        """The routine compiled (`retro.cpu.compiled`), made on first use and again when the code bytes
        changed (set_memory); Untranslatable when the compiled engine does not take it."""
        from retro.cpu.compiled import SET_FLAG, SET_REGISTERS, compile_routine

        image = bytes(self.call_image)
        held = getattr(self, "_compiled", None)
        if held is not None and (held[2] == image or all(image[a] == b for a, b in held[1])):
            return held[0]
        inputs_at = [address for _, address, _ in self.plan.bytes] + [a for _, addresses in self.plan.tables
                                                                      for a in addresses]
        trapped = bytearray(image)
        push_return_trap(trapped)
        plan = self.plan
        places = ()  # memory inputs go through lane_bytes (numpy casts them to bytes in one pass)
        sets = tuple([(index, shift, SET_REGISTERS.index(register)) for index, register, shift in plan.registers]
                     + [(index, bit, SET_FLAG) for index, bit in plan.flags])
        routine = compile_routine(bytes(trapped), self.entry, self.routine.cpu, RETURN_TRAP, inputs_at,
                                  len(self.routine.inputs), places, sets)
        self._compiled = (routine, [(a, image[a]) for a in sorted(routine.translation.code_bytes)], image)
        return routine

    def run_compiled(self, columns: list) -> "BatchOutcome":
        """Run every case of a column block on the compiled engine; calls it leaves (`fallbacks`, by
        reason) run on the batched core."""
        from retro.cpu import compiled as engine

        compiled = self.compiled()
        n = len(columns[0])
        plan = self.plan
        tables: list[tuple[int, np.ndarray]] = [(address, columns[index] >> shift if shift else columns[index])
                                                for index, address, shift in plan.bytes]
        for index, addresses in plan.tables:
            tables += [(address, columns[index][:, k]) for k, address in enumerate(addresses)]
        lane_addr = np.asarray([address for address, _ in tables], dtype=np.int64)
        lane_bytes = np.empty((len(tables), n), dtype=np.uint8)
        for k, (_, lanes) in enumerate(tables):
            lane_bytes[k] = lanes
        flat = tuple(np.ascontiguousarray(c if c.ndim == 1 else c[:, 0], dtype=np.int64) for c in columns)
        start = dict(plan.base_registers)
        base = np.asarray([start["a"], start["x"], start["y"], plan.base_flags], dtype=np.int64)
        image = bytearray(self.call_image)
        s = self.machine.entry_s if self.routine.entry_s == ENTRY_S else self.routine.entry_s
        stack_pointer = push_return_trap(image, s)
        out_addr = np.asarray(sorted({place.address for port in self.routine.outputs for place in port.places
                                      if place.kind == "memory"}), dtype=np.int64)
        done = compiled.run(bytes(image), flat, base, stack_pointer, self.limit, RETURN_TRAP, return_s(s), out_addr,
                            lane_addr, lane_bytes)
        column_of = {int(address): k for k, address in enumerate(out_addr)}
        out_bytes = done["bytes"]
        outputs = port_values(self.routine.outputs, {"a": done["a"], "x": done["x"], "y": done["y"]}, done["p"],
                              lambda address: out_bytes[column_of[address]].astype(np.int64),
                              widen=lambda values: np.asarray(values, dtype=np.int64),
                              table=lambda columns: np.stack(columns, axis=1).astype(np.int64))
        status = done["status"]
        error = np.where(status == LaneError.BUDGET, LaneError.BUDGET, 0).astype(np.int8)
        cycles = done["cycles"]
        left = np.flatnonzero(status >= engine.FALLBACK) if n and status.max() >= engine.FALLBACK else ()
        if len(left):
            for code, count in zip(*np.unique(status[left], return_counts=True)):
                self.fallbacks[int(code)] = self.fallbacks.get(int(code), 0) + int(count)
            batch = self.run_batch([c[left] for c in columns])
            for output, redone in zip(outputs, batch.outputs):
                output[left] = redone
            cycles[left] = batch.cycles
            error[left] = batch.error
        return BatchOutcome(outputs, cycles, error)

    def _run_lanes(self, columns: list, n: int, coverage: bool = False, first_lanes: bool = False,
                   entry: tuple[dict, np.ndarray, int] | None = None) -> "BatchOutcome":
        image = bytearray(self.call_image)
        enter = self.routine.world.enter
        fixed_s = None
        if not self.plan.s_varies:
            fixed_s = self.machine.entry_s if self.routine.entry_s == ENTRY_S else self.routine.entry_s
            stack_pointer = (push_return_trap(image, fixed_s) if enter == "jsr"
                             else push_interrupt_frame(image, 0, return_s(fixed_s)))
        cpu = BatchCpu(self.routine.cpu, image, n, coverage=coverage, first_lanes=first_lanes)
        memory = cpu.memory
        world = None if self.routine.world.empty else BatchWorld(self.routine.world, cpu, self.written_kept,
                                                                  str(self.routine.spec_path))
        registers, p = self.plan.place(columns, _column_byte, memory.fill, entry,
                                       scatter=lambda address, byte: memory.write(slice(None), address, byte),
                                       select=np.where)
        s = registers.pop("s")
        for name, value in registers.items():
            lanes = getattr(cpu, name)
            lanes |= np.asarray(value).astype(lanes.dtype)
        cpu.p[:] = (self._entry_p(p) | FLAG_U) & ~FLAG_B  # as Machine sets P
        if fixed_s is None:  # each lane's return address where its own JSR put it, as Machine does
            cpu.sp[:] = s
            push_return_trap(_LaneStores(memory), cpu.sp.copy())
            stop = return_s(cpu.sp.copy())
        else:
            if enter != "jsr":  # the interrupt sequence: P pushed (per lane), I set, its 7 cycles counted
                memory.fill(STACK_BASE | (stack_pointer + 1), cpu.p.copy())
                cpu.p[:] = interrupt_entry_flags(VARIANTS[self.routine.cpu], cpu.p)
                cpu.cycles[:] = self.routine.world.entry_cycles
            cpu.sp[:] = stack_pointer
            stop = return_s(fixed_s)
        if world is not None:
            world.stack_top = stop  # where an exit ends the call
        if self.vic is not None:  # the scene's timeline: each lane stalls as Machine would from the start
            cpu.bus_stall = self.bus_stalls
        image = self.call_image
        cpu.watch = {pc: (lambda lanes, fact=fact, opcode=image[pc]: fact.broken(lanes.a, lanes.x, lanes.y, lanes.p,
                                                                                 opcode))
                     for pc, fact in self.watched_facts.items()}
        cpu.call(self.entry, self.limit, RETURN_TRAP, stop)
        if world is not None:
            world.finish()
        located = self.plan.vias.outputs(columns) if self.plan.vias is not None else None
        outputs = port_values(self.routine.outputs, {"a": cpu.a, "x": cpu.x, "y": cpu.y}, cpu.p, cpu.read,
                              widen=lambda lanes: np.asarray(lanes, dtype=np.int64),
                              table=lambda columns: np.stack(columns, axis=1).astype(np.int64),
                              world=None if world is None else world.value, located=located,
                              read_at=lambda address: _every_lane(memory.read(slice(None), address), n))
        calls = world.recorded_calls() if world is not None and self.routine.world.recorded else None
        return BatchOutcome(outputs, cpu.cycles, cpu.error, cpu.stolen if self.vic is not None else None,
                            coverage=cpu.coverage, mock_calls=calls)

    def outputs(self, a: int, x: int, y: int, p: int, located: dict | None = None) -> tuple:
        read = self.machine.memory.__getitem__
        return tuple(port_values(self.routine.outputs, {"a": a, "x": x, "y": y}, p, read, widen=int, table=tuple,
                                 world=None if self.world is None else self.world.value, located=located,
                                 read_at=read))

    def traced(self, case: Sequence) -> CallResult:
        """The same call with the instruction trace (for the report of a failing case)."""
        writes, registers, p = self.inputs_for_call(case)
        if self.vic is not None:
            self.restart_beam()
        if self.world is not None:
            self.world.reset(self.machine.cycle)
        return self.machine.call(self.entry, **registers, p=self._entry_p(p),
                                 memory={address: [v] for address, v in writes}, budget=self.limit, trace=True,
                                 enter=self.routine.world.enter)

    def disassemble_at(self, address: int) -> str:
        """The instruction at address as a trace shows it (a world's trap by what it stands for)."""
        if self.world is not None and address in self.world.actions:
            return self.world.describe_trap(address)
        return self.machine.disassemble_at(address)

    def size(self, read_blocks: Sequence[str] = ()) -> Size:
        """Bytes of code, lookup tables and caller-filled storage of the routine's program; the
        `[memory]` blocks named in `read_blocks` (those the routine read: `blocks_read`) count as tables."""
        source = self.routine.program_file
        text = read_text(source, "source file") if source.suffix.lower() in (".s", ".asm", ".oph") else None
        entries = [self.entry] + ([self.routine.init_address] if self.routine.init is not None else [])
        blocks = [(b.name, b.address, len(self.memory_values[b.name])) for b in self.routine.memory
                  if b.name in read_blocks]
        return program_size(self.program, text, entries, self.code_image.__getitem__, self.routine.cpu,
                            self.routine.world, blocks)

    def blocks_read(self, cases: Iterable[tuple]) -> tuple[str, ...]:
        """The `[memory]` blocks the routine reads on these cases (run on Machine, each instruction's
        operand address from the recorded path), in the spec's order; it stops once every block was
        read, or at the first call that does not return."""
        spans = [(b.address, b.address + len(self.memory_values[b.name]), b.name) for b in self.routine.memory]
        found: set[str] = set()
        read = self.machine.memory.__getitem__
        for case in cases:
            if len(found) == len(spans):
                break
            steps: list = []
            try:
                self.run(case, steps)
            except RunError:
                break
            for pc, x, y, _, pointer, *_ in steps:
                address = data_address(read, pc, x, y, pointer, self.routine.cpu)
                if address is not None:
                    found.update(name for start, end, name in spans if start <= address < end)
        return tuple(b.name for b in self.routine.memory if b.name in found)


def port_values(ports: Sequence[Port], registers: dict, p, read: Callable, widen: Callable, table: Callable,
                world: Callable | None = None, located: dict | None = None, read_at: Callable | None = None) -> list:
    """The outputs of a call, one value per port in the spec's order, read from the registers, P and
    memory (`read(address)`): the same code for one call (ints) and for lanes of the batched core
    (arrays), which differ only in `widen` (a byte or a flag as the output's number type) and
    `table` (bytes of a table output together). An output placed by the case is read from the
    addresses `located` gives it (output index -> addresses of its bytes) with `read_at`; `world(place)`:
    a world output's byte (retro.routines.world)."""
    values = []
    for k, port in enumerate(ports):
        read_place = world if port.places[0].kind in WORLD_PLACES else None
        if port.via is not None:
            data = [read_at(address) for address in located[k]]
            values.append(table(data) if port.table else
                          sum((widen(byte) << (8 * i) for i, byte in enumerate(data)), widen(0)))
        elif port.flag:
            values.append(widen((p & port.places[0].bit) != 0))
        elif port.table:
            values.append(table([read(place.address) if read_place is None else read_place(place)
                                 for place in port.places]))
        else:
            value = widen(0)
            for shift, place in enumerate(port.places):
                byte = (read_place(place) if read_place is not None else
                        registers[place.register] if place.kind == "register" else read(place.address))
                value = value | widen(byte) << (8 * shift)
            values.append(value)
    return values


def describe_value(port: Port, value) -> str:
    if port.table:
        return "[" + " ".join(f"{v:02x}" for v in value) + "]"
    if port.address:  # a pointer or S: an address, as a 6502 programmer writes it
        return f"${value:0{2 if port.bits == 8 else 4}X}"
    return str(value)


class _LaneStores:
    """`memory[address] = byte` on every lane of a batch (an address per lane): push_return_trap's view."""

    def __init__(self, memory) -> None:
        self.memory = memory

    def __setitem__(self, address, byte) -> None:
        self.memory.write(slice(None), address, byte)


def _every_lane(value, lanes: int) -> np.ndarray:
    return np.full(lanes, value, dtype=np.int64) if isinstance(value, (int, np.integer)) else value
