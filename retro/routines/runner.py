"""Run one routine (a validated spec) on cases: a loaded machine, its memory set, the fast call path.

`RoutineRunner(routine, seed).run(case)` puts the case's values where the spec says (registers,
flags, memory; numbers little-endian, tables as bytes), calls the routine with `Machine.call_fast`
and returns (outputs, cycles): the outputs as a tuple in the spec's order. With `record`, the
executed path is appended for the independent timing model (retro.cpu.timing).

`run_batch(columns)` runs many cases at once on the batched core, `run_compiled` on the compiled engine
(retro.routines.batch_runs): every lane starts from the memory as it stood after `init`, with its
inputs in place. Where inputs go is the runner's `InputPlan` (retro.routines.input_plan), outputs are
read back by retro.routines.outputs, and `size` counts bytes with retro.routines.size.

Memory on the scalar path persists between calls: every input is written before each call, and so
are the output places in memory (restored to their value after `init`, so an output a routine writes
only on some paths reads the same on both engines), and so is the routine's own code as it stood after
`init` (self-modifying code: each call starts from the same instructions, as each lane does); the
`[memory]` blocks once after loading (then `init` runs). A routine must not depend on anything else
it wrote in an earlier call.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from retro.chips.vic.constants import IRQ_SOURCES, REG_IRQ_ENABLE
from retro.cpu.machine import DEFAULT_BUDGET, ENTRY_S, CallResult
from retro.cpu.mpu import FLAG_I
from retro.cpu.timing import model_cycles, timing_table
from retro.errors import InputError, RunError
from retro.fileio import read_text
from retro.machines import build_machine
from retro.machines.c64 import vic_of
from retro.routines import batch_runs
from retro.routines.batch_runs import BatchOutcome
from retro.routines.chip_access import BusStalls, NesCalls, NesStart, chip_free
from retro.routines.entry import EntryState, variant_memory, variant_stack
from retro.routines.input_plan import InputPlan, case_byte
from retro.routines.outputs import port_values
from retro.routines.sandbox import bytes_of
from retro.routines.size import Size, data_address, program_size, routine_code
from retro.routines.spec import Routine, call_with
from retro.routines.world_machine import MachineWorld, chip_overlaps
from retro.scenes.vic import VicScene

NEEDS_A_VIC_SCENE = "--at-line needs a VIC-II scene (chip = \"vic-ii\")"
MEMORY_RNG_OFFSET = 1  # memory blocks draw from seed + 1, cases from seed: changing one never moves the other

PROBE_CASES = 2_000  # cases of each part run to see which `[memory]` blocks a routine reads


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
class RasterStart:
    """Run every call with a VIC-II scene on the bus and the beam at this line and cycle (the CPU
    then stalls on Bad Lines and sprite DMA as on a real C64), the frame drawn so far in the
    collision latches and $D019 (unread, unacknowledged)."""

    scene: VicScene
    line: int
    cycle: int = 1


def _machine_for(routine: Routine, start: RasterStart | NesStart | None):
    """(the machine a routine runs on, its VIC-II or None, the PPU's side of every call or None): a bare
    CPU, the scene's C64 or the scene's NES."""
    if start is None:
        return build_machine(cpu=routine.cpu), None, None
    if start.scene.cpu_variant != routine.cpu:
        raise InputError(f"--scene: a {start.scene.cpu_variant} scene cannot run the {routine.cpu} routine "
                         f"{routine.name}")
    if isinstance(start, NesStart):
        machine = build_machine(start.scene)
        return machine, None, NesCalls(machine, start, routine.world.enter)
    if not isinstance(start.scene, VicScene):
        raise InputError(NEEDS_A_VIC_SCENE)
    machine = build_machine(start.scene)
    return machine, vic_of(machine), None


def _pointer_pcs(routine: Routine) -> frozenset[int]:
    """(indirect),Y instructions: the timing model needs their pointer (and the 65C02's BBR/BBS the
    zero-page byte they test). Every byte of the program that could be such an opcode is listed; a
    data byte in the set only costs a lookup."""
    indirect_y = {opcode for opcode, op in timing_table(routine.cpu).items() if op.mode in ("iny", "zpr")}
    program = routine.program
    return frozenset(program.origin + i for i, b in enumerate(program.code) if b in indirect_y)


def _code_span(routine: Routine, image: bytes) -> tuple[int, int]:
    """[start, end) of the instructions reachable from the entry and init (what a store into the
    routine's own code patches); (0, 0) when none is decoded."""
    program = routine.program
    entries = [routine.entry_address] + ([routine.init_address] if routine.init is not None else [])
    code = routine_code(image.__getitem__, entries, (program.origin, program.end), routine.cpu, routine.world)
    if not code:
        return 0, 0
    return min(code), max(pc + length for pc, length in code.items())


def _written_kept(routine: Routine) -> dict[str, int]:
    """Per hardware entry, how many of the values written the outputs show."""
    kept: dict[str, int] = {}
    for port in routine.outputs:
        for place in port.places:
            if place.kind == "written":
                kept[place.register] = max(kept.get(place.register, 0), place.bit + 1)
    return kept


class RoutineRunner:
    def __init__(self, routine: Routine, seed: int = 0, start: RasterStart | NesStart | None = None,
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
        self.machine, self.vic, self.nes = _machine_for(routine, start)
        if fill is not None:  # before anything is loaded: what stays untouched keeps the variant's bytes
            memory = np.asarray(self.machine.memory, dtype=np.uint8)
            self.machine.memory[:] = np.where(memory == 0, variant_memory(fill, seed), memory).tolist()
            self.machine.stack_top = variant_stack(fill, seed)
        self.machine.load(self.program)
        if start is not None:  # before the world's own devices join the bus
            chip_overlaps(routine, self.machine.bus.devices, str(start.scene.source))
        self.world = None if routine.world.empty else MachineWorld(routine.world, self.machine, str(routine.spec_path))
        self.last_stolen = 0  # cycles of the last call in which the VIC-II held the CPU
        self.entry = routine.entry_address
        self.memory_values = memory_values(routine, seed)
        for block in routine.memory:
            data = self.memory_values[block.name]
            self.machine.memory[block.address:block.address + len(data)] = list(data)
        self.code_image = bytes(self.machine.memory)  # before init and the cases patch anything
        if self.world is not None:
            self.world.place_traps()  # mocks and exits (init may call a mock too)
        if routine.init is not None:
            self.machine.call_fast(routine.init_address, budget=self.limit)
        self.call_image = bytearray(self.machine.memory)  # what every call starts from (the batch's image)
        self._code_span = _code_span(routine, self.call_image)
        self._code_as_called = self._code_bytes_of(self.call_image)
        self.pointer_pcs = _pointer_pcs(routine)
        self.plan = InputPlan.of(routine, self.call_image, seed)
        self._dirty: list[int] = []  # addresses the last call's ports placed by the case took (restored)
        self.watched_facts = {fact.address: fact for fact in routine.facts}  # held against every call
        self.written_kept = _written_kept(routine)
        self.fallbacks: dict[int, int] = {}  # compiled engine: calls it left to the batched core, by status
        self._compiled = None  # compiled engine: (the routine, its code bytes, its image): batch_runs.compiled_routine
        self._compiled_free: dict = {}  # ... an entry-state run's, by its free registers and P bits
        self._entered_image = None  # compiled engine: (S, the call image, it with the return trap): batch_runs
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
        registers, p = self.plan.place(case, case_byte, lambda address, byte: writes.append((address, byte)), entry,
                                       write_table=lambda addresses, value: writes.extend(zip(addresses, value)))
        if self._machine_s:
            registers["s"] = self.machine.entry_s  # the machine's stack top (the entry-state runs vary it)
        return writes, registers, p

    def reset_memory(self, image: bytes) -> None:
        """Start the following calls from this memory image (entry-state runs, naming a dependence)."""
        self.machine.memory[:] = list(image)
        self.call_image = bytearray(image)
        self._code_as_called = self._code_bytes_of(self.call_image)

    def _code_bytes_of(self, image) -> list[int]:
        start, end = self._code_span
        return list(image[start:end])

    def _restore_code(self) -> None:
        """Put back the code a previous call patched (self-modifying code): each call starts from the
        code as every lane of the array engines does, whatever case ran before it."""
        start, end = self._code_span
        memory = self.machine.memory
        if memory[start:end] != self._code_as_called:
            memory[start:end] = self._code_as_called

    def run(self, case: Sequence, record: list | None = None, entry: tuple[dict, int, int] | None = None,
            timed: bool = False) -> tuple[tuple, int]:
        """(outputs in the spec's order, cycles) of one call; `entry` as in `inputs_for_call`. With a
        world, `record` leaves out the traps (mocks, exits) and `last_extra_cycles` says what the timing
        model must add for them and for an interrupt entry; `last_calls` holds the recorded mocks' calls.
        `timed`: the independent timing model (retro.cpu.timing) counts the call too, into
        `last_modelled` (a world's traps and interrupt entry added)."""
        writes, registers, p = self.inputs_for_call(case, entry)
        self._restore_code()
        if self.start is not None:
            self.restart_beam()
            stolen = self.machine.mpu.stolen
        located = self.plan.vias.outputs(case) if self.plan.vias is not None else None
        world = self.world
        if world is None:
            cycles, a, x, y, p = self.machine.call_fast(self.entry, writes, **registers, p=p, budget=self.limit,
                                                        record=record, pointer_pcs=self.pointer_pcs, timed=timed)
        else:
            if timed and record is None:
                record = []  # the model times the path less the traps
            world.reset(self.machine.cycle)
            cycles, a, x, y, p = self.machine.call_fast(self.entry, writes, **registers, p=self._entry_p(p),
                                                        budget=self.limit, record=record, pointer_pcs=self.pointer_pcs,
                                                        enter=self.routine.world.enter)
        if self.start is not None:  # the VIC-II's stalls, or OAM DMA's (the PPU's `stall`, not counted in mpu.stolen)
            self.last_stolen = self.machine.mpu.stolen - stolen if self.nes is None else self.nes.dma_cycles
        if world is not None:
            if record is not None:
                traps = world.actions
                record[:] = [step for step in record if step[0] not in traps]
            self.last_extra_cycles = world.trap_cycles + self.routine.world.entry_cycles
            self.last_calls = world.recorded_calls()
        if timed:
            self.last_modelled = self.last_extra_cycles + (
                self.machine.last_modelled if world is None else
                model_cycles(self.machine.memory.__getitem__, record, self.routine.cpu))
        return self.outputs(a, x, y, p, located), cycles

    last_extra_cycles = 0
    last_modelled = 0
    last_calls: dict | None = None

    def _entry_p(self, p):
        """P at entry; an IRQ handler's pushed P has I clear (the CPU takes an IRQ only then)."""
        return p & ~FLAG_I if self.routine.world.enter == "irq" else p

    def restart_beam(self) -> None:
        """The scene's chip as every call finds it: the beam at the start, the frame drawn so far."""
        if self.nes is not None:
            self.nes.restart()
            return
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
        return None if self.start is None else self.chip_verdict[1]

    @functools.cached_property
    def bus_stalls(self) -> BusStalls:
        """The VIC-II's stalls per lane from the start line and cycle (the scene's BA schedule)."""
        video = self.vic.video
        start = self.start.line * video.cycles_per_line + self.start.cycle - 1
        return BusStalls(self.vic.bus.wait, start, self.machine.mpu.write_masks)

    @functools.cached_property
    def chip_verdict(self) -> tuple[bool, str]:
        memory = self.machine.memory
        if self.nes is not None:
            return self.nes.verdict(memory.__getitem__, self.entry, (self.program.origin, self.program.end),
                                    self.routine.cpu, self.limit)
        if self.vic is None:
            return True, ""
        pages = frozenset(page for page, device in enumerate(self.machine.bus.page_devices) if device is not None)
        interrupts = bool(self.vic.registers[REG_IRQ_ENABLE] & IRQ_SOURCES)
        if interrupts and (not self.plan.base_flags & FLAG_I or any(bit == FLAG_I for _, bit in self.plan.flags)):
            return False, "the scene enables VIC-II interrupts and I may be clear on entry"
        return chip_free(memory.__getitem__, self.entry, (self.program.origin, self.program.end), pages,
                         self.routine.cpu, interrupts, self.routine.world.enter != "jsr")

    @property
    def batch_refusal(self) -> str | None:
        """Why the batched core cannot run this routine's world (None: it can; a scene aside)."""
        return self.routine.world.batch_refusal()

    @property
    def fixed_entry_s(self) -> int:
        """S at entry when no input sets it: the spec's, or the machine's stack top."""
        return self.machine.entry_s if self.routine.entry_s == ENTRY_S else self.routine.entry_s

    def run_batch(self, columns: list, coverage: bool = False, first_lanes: bool = False,
                  entry: tuple[dict, np.ndarray, int] | None = None) -> BatchOutcome:
        """Run every case of a column block (one array per input) on the batched core (`coverage`:
        count what the lanes ran; `first_lanes`: also which lane first went each way at each branch;
        `entry`: an entry-state run's free registers and P bits per lane, InputPlan.place)."""
        return batch_runs.run_batch(self, columns, coverage, first_lanes, entry)

    def compiled(self):
        """The routine compiled (retro.routines.batch_runs.compiled_routine)."""
        return batch_runs.compiled_routine(self)

    def run_compiled(self, columns: list, entry: tuple[dict, np.ndarray, int] | None = None) -> BatchOutcome:
        """Run every case of a column block on the compiled engine (the calls it leaves on the batched core);
        `entry` as for run_batch."""
        return batch_runs.run_compiled(self, columns, entry)

    def outputs(self, a: int, x: int, y: int, p: int, located: dict | None = None) -> tuple:
        read = self.machine.memory.__getitem__
        return tuple(port_values(self.routine.outputs, {"a": a, "x": x, "y": y}, p, read, widen=int, table=tuple,
                                 world=None if self.world is None else self.world.value, located=located,
                                 read_at=read))

    def traced(self, case: Sequence) -> CallResult:
        """The same call with the instruction trace (for the report of a failing case)."""
        writes, registers, p = self.inputs_for_call(case)
        if self.start is not None:
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

