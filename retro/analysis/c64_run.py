"""Run a C64 program as the machine would after `RUN`: from its BASIC `SYS` line or a given entry.

`run_c64` puts the program on a C64 (`retro.machines.c64.build_c64`: the 6510 and the VIC-II with
its Bad Lines, sprite DMA and raster/collision interrupts as the model has them; docs/vic.md) and
runs it for a number of frames, or less when a stop condition holds first (checked after every
instruction, as for a cartridge: `retro.analysis.console_run`):
- the PC reaches an address (`until`), a byte of memory has a value (`until_value`);
- the program has halted: an instruction jumped or branched to itself (`JMP *`) while no interrupt
  can come (I set, or no VIC-II interrupt source enabled that can still latch);
- the program returned: the RTS that leaves the SYS'd code (BASIC would go on; here the run ends).

The machine is a C64 after `RUN` as far as the CPU sees it [Mapping the Commodore 64]: the 6510's
port at $00/$01 holds $2F/$37 (BASIC, KERNAL and I/O mapped in); A, X, Y and P come from
$030C-$030F as SYS loads them (all 0 after power-on, so I is clear); the RAM vectors at $0314-$0319
hold the KERNAL's $EA31, $FE66, $FE47. Without a scene the VIC-II holds the registers the KERNAL's
initialisation writes (table TVIC at $ECB9: $D011 = $9B, display on, so Bad Lines happen).

There is no BASIC or KERNAL ROM (and no SID or disk; of CIA 1 only its timers). The KERNAL code
present is its IRQ entry and exit ($FF48-$FF5A, $EA81-$EA86; `retro.machines.c64.install_kernal_irq_entry`),
so that a program hooking $0314 runs as on the machine, and the stubs of the few ROM routines test
programs call (retro.machines.c64_stubs: STROUT, LINPRT, IOINIT, with CIA 1's timers). Any other
instruction fetched from a ROM that the port
at $01 maps in ($A000-$BFFF with LORAM and HIRAM set, $E000-$FFFF with HIRAM set) ends the run with
a RunError naming the address and the instruction that got there (`JSR $FFD2`, `JMP $EA31`, or a
BRK through the KERNAL's $FE66).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

from retro.analysis.console_run import FRAMES_DONE, HALTED, MAX_FRAMES, REACHED, REPORTED, VALUE_SEEN, \
    StopRun, Verdict, run_frames
from retro.chips.vic.constants import CHAR_ROM_BYTES, PAL, REG_SPRITE_ENABLE, REGISTER_COUNT, SPRITE_BYTES, SPRITE_COUNT, \
    VIC_BASE
from retro.chips.vic.device import VicDevice
from retro.chips.vic.fetch import CHARGEN_ENV, ROM_MISSING_HINT, memory_parts
from retro.chips.vic.graphics import VicMemory
from retro.chips.vic.model import VicState
from retro.cpu.bus import NEVER
from retro.cpu.machine import CALL_STACK_TOP, RETURN_TRAP, Machine, push_return_trap
from retro.cpu.mpu import FLAG_I, FLAG_U
from retro.errors import InputError, RunError
from retro.fileio import read_bytes
from retro.machines.c64 import (
    KERNAL_IRQ_ENTRY,
    KERNAL_IRQ_ENTRY_CODE,
    KERNAL_IRQ_EXIT,
    KERNAL_IRQ_EXIT_CODE,
    KERNAL_IRQ_HANDLER,
    KERNAL_IRQ_HANDLER_STUB,
    KERNAL_NMI_EXIT,
    build_c64,
    install_kernal_irq_entry,
    install_kernal_irq_handler_stub,
    vic_of,
)
from retro.machines.c64_stubs import ROM_STUB_NAMES, C64Stubs, install_c64_stubs
from retro.program import Program
from retro.scenes.vic import VicScene

RETURNED = "returned"  # why a run stopped, besides console_run's reasons
DEFAULT_C64_FRAMES = 50  # one second of PAL time

# The KERNAL's VIC-II initialisation (TVIC, $ECB9-$ECE7, written to $D000-$D02E at reset) [Mapping
# the Commodore 64, $ECB9]: sprites at 0, $D011 $9B, $D012 $37 (compare line 311), $D016 $08,
# $D018 $14, $D019 $0F (acknowledge), border light blue, background blue, sprite colours 1-7 and $4C.
KERNAL_VIC_REGISTERS = bytes([0x00] * 16 + [0x00, 0x9B, 0x37, 0x00, 0x00, 0x00, 0x08, 0x00, 0x14, 0x0F, 0x00,
                                            0x00, 0x00, 0x00, 0x00, 0x00, 0x0E, 0x06, 0x01, 0x02, 0x03, 0x04,
                                            0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x4C])
assert len(KERNAL_VIC_REGISTERS) == REGISTER_COUNT

PORT_DIRECTION, PORT_DATA = 0x00, 0x01
POWER_ON_PORT = (0x2F, 0x37)  # $00, $01 after the KERNAL's reset: BASIC, KERNAL and I/O in
LORAM, HIRAM = 0x01, 0x02
BASIC_ROM = (0xA000, 0xBFFF)
KERNAL_ROM = (0xE000, 0xFFFF)
RAM_VECTORS = 0x0314  # IRQ, BRK, NMI: the KERNAL's handlers after reset
KERNAL_VECTORS = (0xEA31, 0xFE66, 0xFE47)
SYS_REGISTERS = 0x030C  # A, X, Y, P that SYS loads (0 after power-on)
# Entry points a program may call, named in the error [C64 Programmer's Reference Guide, KERNAL
# jump table; Mapping the Commodore 64]
KERNAL_NAMES = {0xFFD2: "CHROUT", 0xFFE4: "GETIN", 0xFFCF: "CHRIN", 0xFFF0: "PLOT", 0xFF9F: "SCNKEY",
                0xFFE1: "STOP", 0xFFBA: "SETLFS", 0xFFBD: "SETNAM", 0xFFD5: "LOAD", 0xFFD8: "SAVE",
                0xFFC0: "OPEN", 0xFFC3: "CLOSE", 0xFFCC: "CLRCHN", 0xFF81: "CINT", 0xFF84: "IOINIT",
                0xE544: "clear screen",
                0xEA7E: "the KERNAL's IRQ handler (after the keyboard scan)",
                0xFE66: "the KERNAL's BRK handler (BASIC warm start)", 0xFE47: "the KERNAL's NMI handler"}
STUB_RANGES = ((KERNAL_IRQ_ENTRY, KERNAL_IRQ_ENTRY + len(KERNAL_IRQ_ENTRY_CODE)),
               (KERNAL_IRQ_EXIT, KERNAL_IRQ_EXIT + len(KERNAL_IRQ_EXIT_CODE)),
               (KERNAL_IRQ_HANDLER, KERNAL_IRQ_HANDLER + len(KERNAL_IRQ_HANDLER_STUB)),
               (KERNAL_NMI_EXIT, KERNAL_NMI_EXIT + len(KERNAL_IRQ_EXIT_CODE))) + tuple(
                   (address, address + 1) for address in ROM_STUB_NAMES)
MAX_C64_FRAMES = MAX_FRAMES


def kernal_vic_state() -> VicState:
    """A PAL VIC-II as the KERNAL leaves it: its registers, no sprite data, blank memory."""
    return VicState(PAL, KERNAL_VIC_REGISTERS, (bytes(SPRITE_BYTES),) * SPRITE_COUNT, VicMemory.blank())


@dataclass
class C64Run:
    machine: Machine
    entry: int
    frames_asked: int
    cycles: int
    instructions: int
    stopped: str  # FRAMES_DONE, REACHED, VALUE_SEEN, HALTED, RETURNED or INTERRUPTED
    halt_pc: int | None = None
    sys_line: int | None = None  # the BASIC line the SYS was on
    notes: tuple[str, ...] = ()
    peeks: dict[str, list[int]] = field(default_factory=dict)  # filled by the command
    tracer: object = None  # a retro.analysis.trace.Tracer that observed the run (--trace, --watch)
    verdict: Verdict | None = None  # with result_at: the test program's result (debug_cart_verdict)
    printed: list[str] = field(default_factory=list)  # what the ROM stubs printed, a line per RETURN

    @property
    def vic(self) -> VicDevice:
        return vic_of(self.machine)

    @property
    def frames_run(self) -> float:
        return self.cycles / self.vic.video.frame_cycles


def rom_at(memory, pc: int) -> bool:
    """Whether the port at $01 maps a ROM (BASIC or KERNAL) at pc, outside retro's KERNAL and ROM stubs."""
    if pc < BASIC_ROM[0] or any(lo <= pc < hi for lo, hi in STUB_RANGES):
        return False
    port = memory[PORT_DATA]
    if pc <= BASIC_ROM[1]:
        return port & (LORAM | HIRAM) == LORAM | HIRAM
    return pc >= KERNAL_ROM[0] and bool(port & HIRAM)


def rom_error(machine: Machine, pc: int, came_from: int | None) -> RunError:
    name = KERNAL_NAMES.get(pc)
    what = "BASIC" if pc <= BASIC_ROM[1] else "KERNAL"
    origin = (f" (from ${came_from:04X} {machine.disassemble_at(came_from)})" if came_from is not None else "")
    return RunError(f"the program went into the {what} ROM at ${pc:04X}{f' ({name})' if name else ''}{origin}: "
                    f"this C64 has no BASIC or KERNAL ROM (docs/vic.md \"Running a C64 program\")")


# VICE's testbench (testbench/*-hooks.sh of the VICE test programs; x64sc's -debugcart): a test
# program ends by writing its result to $D7FF, $00 passed and $FF failed; the first write ends the run.
DEBUG_CART = 0xD7FF
DEBUG_CART_PASSED, DEBUG_CART_FAILED = 0x00, 0xFF


class ResultPort:
    """RAM at a test program's result address that remembers the first value written there."""

    def __init__(self, memory: list[int]) -> None:
        self.memory = memory
        self.written: int | None = None

    def read(self, address: int, cycle: int) -> int:
        return self.memory[address]

    def write(self, address: int, value: int, cycle: int) -> None:
        self.memory[address] = value
        if self.written is None:
            self.written = value

    def peek(self, address: int) -> int:
        return self.memory[address]


def debug_cart_verdict(address: int, written: int | None, frames_out: int | None = None) -> Verdict:
    """The verdict of VICE's testbench protocol from the first byte written at `address` (None: none);
    `frames_out`: the frame count, when the run ended because it ran out."""
    protocol = f"result byte ${address:04X} (VICE testbench: $00 passed, $FF failed)"
    if written is None:
        return Verdict(protocol, None, None, "nothing written there yet" if frames_out is None
                       else f"nothing written there in {frames_out:,} frames: more --frames?")
    if written == DEBUG_CART_PASSED:
        return Verdict(protocol, written, True, "passed")
    return Verdict(protocol, written, False, "failed" if written == DEBUG_CART_FAILED
                   else f"${written:02X} written: the protocol knows $00 and $FF only")


class _C64Watch:
    """Observer of the run loop: the stop conditions (module docstring) and the ROM check."""

    def __init__(self, machine: Machine, until: int | None, until_value: tuple[int, int] | None,
                 result: ResultPort | None = None) -> None:
        self.machine = machine
        self.result = result
        self.memory = machine.bus.memory
        self.peek = machine.bus.peek
        self.vic = vic_of(machine)
        self.until = until
        self.until_value = until_value
        self.pc = -1
        self.last: int | None = None  # the address of the last instruction run
        self.halt_pc: int | None = None

    def before(self, mpu) -> None:
        if mpu.pending_interrupt is not None:
            self.pc = -1
            return
        pc = self.pc = mpu.pc
        if pc >= BASIC_ROM[0] and rom_at(self.memory, pc):
            raise rom_error(self.machine, pc, self.last)

    def after(self, mpu) -> None:
        pc = mpu.pc
        if self.pc >= 0:
            self.last = self.pc
        if self.result is not None and self.result.written is not None:
            raise StopRun(REPORTED)
        if pc == self.pc and (mpu.p & FLAG_I or self.vic.irq_next >= NEVER):
            self.halt_pc = pc
            raise StopRun(HALTED)
        if pc == RETURN_TRAP and mpu.sp == CALL_STACK_TOP:
            raise StopRun(RETURNED)
        if pc == self.until:
            raise StopRun(REACHED)
        if self.until_value is not None and self.peek(self.until_value[0]) == self.until_value[1]:
            raise StopRun(VALUE_SEEN)


def char_rom_image() -> bytes | None:
    """The character ROM image the user names in $RETRO_C64_CHARGEN (4096 bytes), or None."""
    path = os.environ.get(CHARGEN_ENV)
    if not path:
        return None
    image = read_bytes(path, "character ROM image", CHAR_ROM_BYTES)
    if len(image) != CHAR_ROM_BYTES:
        raise InputError(f"{path} (${CHARGEN_ENV}): a character ROM image is {CHAR_ROM_BYTES} bytes, not {len(image)}")
    return image


def c64_for(program: Program, scene: VicScene | None) -> Machine:
    """A C64 as after RUN (module docstring) with `program` loaded and the scene's VIC-II (else the
    KERNAL's), its beam where the scene says (else line 0, cycle 1). The VIC-II reads its memory
    (retro.chips.vic.fetch); a scene's screen, colour RAM, character set, bitmap and sprite data are
    put where it fetches them (fetch.memory_parts), and the program may not load over them."""
    return _c64_with_stubs(program, scene)[0]


def _c64_with_stubs(program: Program, scene: VicScene | None) -> tuple[Machine, C64Stubs]:
    """`c64_for`'s machine and its stubs (CIA 1, the ROM routines: retro.machines.c64_stubs)."""
    char_rom = char_rom_image()
    if scene is None:
        machine = build_c64(kernal_vic_state(), reads_memory=True, char_rom=char_rom)
    else:
        machine = build_c64(scene.state, start_line=scene.start_line, start_cycle=scene.start_cycle,
                            reads_memory=True, char_rom=char_rom)
        _fill_scene_memory(machine, scene, program)
    install_kernal_irq_handler_stub(machine)  # a handler hooked at $0314 may end with JMP $EA31
    install_kernal_irq_entry(machine)  # the KERNAL is mapped in: its vector at $FFFE is the hardware's
    stubs = install_c64_stubs(machine, vic_of(machine).fetcher.bank_port)
    memory = machine.bus.memory
    memory[PORT_DIRECTION], memory[PORT_DATA] = POWER_ON_PORT
    for i, vector in enumerate(KERNAL_VECTORS):
        memory[RAM_VECTORS + 2 * i], memory[RAM_VECTORS + 2 * i + 1] = vector & 0xFF, vector >> 8
    machine.load(program)
    machine.mpu.stop_on_brk = False  # BRK goes through the vector, as on the machine
    return machine, stubs


def _fill_scene_memory(machine: Machine, scene: VicScene, program: Program) -> None:
    port = vic_of(machine).fetcher.bank_port
    if scene.bank:
        port.set_bank(scene.bank)
    try:
        parts = memory_parts(scene.state, port.bank)
    except InputError as exc:
        raise InputError(f"{scene.source}: {exc}") from None
    loaded = (program.origin, program.origin + len(program.code))
    for name, at, values in parts:
        if at < loaded[1] and loaded[0] < at + len(values):
            raise InputError(f"{scene.source}: the scene's {name} (${at:04X}-${at + len(values) - 1:04X}, where the "
                             f"VIC-II reads it) overlaps the program (${loaded[0]:04X}-${loaded[1] - 1:04X})")
        machine.bus.load(at, bytes(values))


def run_c64(program: Program, entry: int, *, frames: int, scene: VicScene | None = None,
            until: int | None = None, until_value: tuple[int, int] | None = None,
            sys_line: int | None = None, notes: tuple[str, ...] = (), wrap=None,
            result_at: int | None = None) -> C64Run:
    """Run `program` on a C64 from `entry` (module docstring) for up to `frames` frames. `wrap(machine,
    watch)`, if given, returns the observer to run with instead of the stop conditions' own (a
    profiler that tells them in turn). `result_at`: a test program's result address (DEBUG_CART):
    the run stops at the first write there and carries the verdict."""
    if not 1 <= frames <= MAX_C64_FRAMES:
        raise InputError(f"--frames: {frames:,} is not a frame count in 1..{MAX_C64_FRAMES:,}")
    machine, stubs = _c64_with_stubs(program, scene)
    mpu = machine.mpu
    memory = machine.bus.memory
    mpu.a, mpu.x, mpu.y = (memory[SYS_REGISTERS + i] for i in range(3))
    mpu.p = memory[SYS_REGISTERS + 3] | FLAG_U
    mpu.sp = push_return_trap(memory)  # an RTS from the SYS'd code comes back here (RETURNED)
    mpu.pc = entry
    mpu.pending_interrupt = None
    result = None
    if result_at is not None:
        result = ResultPort(memory)
        try:
            machine.attach(result, result_at, result_at)
        except InputError as exc:
            raise InputError(f"--result ${result_at:04X}: {exc}") from None
    watch = _C64Watch(machine, until, until_value, result)
    observer = watch if wrap is None else wrap(machine, watch)
    frame_cycles = vic_of(machine).video.frame_cycles
    start = machine.cycle
    stopped, instructions = run_frames(machine, start + math.ceil(frames * frame_cycles), frame_cycles, observer)
    vic_of(machine).catch_up(machine.cycle)  # the latches and $D019 as they stand at the end of the run
    unknown = vic_of(machine).fetcher.unknown_latches(vic_of(machine).registers[REG_SPRITE_ENABLE])
    if unknown:
        notes = notes + (f"{' and '.join(unknown)} at the end of the run count the character ROM's bytes as 0: "
                         f"{ROM_MISSING_HINT}",)
    return C64Run(machine=machine, entry=entry, frames_asked=frames, cycles=machine.cycle - start,
                  instructions=instructions, stopped=stopped, halt_pc=watch.halt_pc, sys_line=sys_line,
                  notes=notes, verdict=None if result is None else debug_cart_verdict(
                      result_at, result.written, frames if stopped == FRAMES_DONE else None),
                  printed=stubs.editor.transcript)


def vic_registers(vic: VicDevice) -> dict:
    """The VIC-II's position and registers after a run, as `retro run PROG.prg --json` reports them."""
    frame, line, cycle = vic.beam(vic.start_cycle + vic.synced)
    return {"frame": frame, "line": line, "cycle": cycle,
            "registers": bytes(vic.peek(VIC_BASE + r) for r in range(REGISTER_COUNT)).hex(),
            "d019": vic.peek(VIC_BASE + 0x19), "d01e": vic.sprite_sprite, "d01f": vic.sprite_background}

