"""Run a NES cartridge as the console would, from its reset vector, and read test ROMs' verdicts.

`run_cartridge` powers on the console (`retro.machines.nes.build_nes` with the cartridge), takes the
reset vector and runs for a number of frames, or less when a stop condition holds first. Conditions
are checked after every instruction:
- the PC reaches an address (`until`);
- a byte of memory has a value (`until_value`);
- the program has halted: an instruction jumped or branched to itself (`JMP *`, `BVC *` with V
  clear) while the NMI is off ($2000 bit 7 clear) and no IRQ can come (the I flag set, or the APU's
  frame IRQ inhibited or in the 5-step mode, its flag clear: `irq_next` says never); nothing can
  happen any more, so the run ends there whatever the frame count.
and after every frame:
- a test ROM that reports through $6000 has finished (below).

Test ROM protocols (blargg's; from the readmes of his ROMs, e.g. ppu_vbl_nmi/readme.txt "Output at
$6000", and the sources of the 2005 ROMs, runtime/validation.a):
- $6000 protocol: $6001-$6003 hold $DE $B0 $61 while the data is valid; $6000 is the status ($80
  running, $81 the reset button must be pressed at least 100 ms later, $00-$7F the final result
  code: 0 passed, 1 failed, 2+ failed test N); the text printed so far is at $6004, zero-terminated.
  Detected by its signature.
- result byte protocol (the 2005 ROMs: sprite_hit_tests, sprite_overflow_tests, vbl_nmi_timing):
  the code is kept in zero page at $F8 (1 passed, N >= 2 failed test N), final once the ROM has
  halted in its `forever` loop. Used when the caller names the address (`result_at`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from retro.chips.cartridge import NromCartridge
from retro.chips.ppu.constants import CTRL_NMI, NTSC, PPUSTATUS
from retro.chips.ppu.device import PpuDevice
from retro.cpu.machine import Machine
from retro.cpu.bus import NEVER
from retro.cpu.mpu import BRANCH_OPCODES, FLAG_I
from retro.errors import InputError
from retro.machines.nes import build_nes, ppu_of, reset

JMP_ABSOLUTE = 0x4C
CPU_CYCLES_PER_FRAME = NTSC.dots_per_frame / NTSC.dots_per_cpu_cycle  # 29,780.67 (no odd-frame skip)
MAX_FRAMES = 36_000             # ten minutes of NES time (the host runs about 30 frames a second)
DEFAULT_FRAMES = 600  # ten seconds of NES time: every blargg ROM of the standard suites reports within it
STATUS_ADDRESS = 0x6000
SIGNATURE_ADDRESS = 0x6001
SIGNATURE = (0xDE, 0xB0, 0x61)
TEXT_ADDRESS = 0x6004
TEXT_LIMIT = 0x1FFC             # the text runs to the end of PRG RAM at most
STATUS_RUNNING = 0x80
STATUS_NEEDS_RESET = 0x81
CODE_PASSED = 0                 # $6000 protocol
RESULT_PASSED = 1               # result byte protocol

# why a run stopped
FRAMES_DONE = "frames"
REACHED = "until"
VALUE_SEEN = "until-value"
HALTED = "halted"
REPORTED = "verdict"
INTERRUPTED = "interrupted"


@dataclass(frozen=True)
class Verdict:
    protocol: str               # "$6000" or "result byte $F8"
    code: int | None            # the result code; None while the ROM is still running
    passed: bool | None         # None: no final result yet
    text: str                   # what the ROM printed ($6000 protocol), or the code's meaning

    def summary(self) -> str:
        if self.passed is None:
            return f"{self.protocol}: no result yet ({self.text or 'still running'})"
        outcome = "passed" if self.passed else f"failed (code {self.code})"
        return f"{self.protocol}: {outcome}"

    def as_dict(self) -> dict:
        return {"protocol": self.protocol, "code": self.code, "passed": self.passed, "text": self.text}


@dataclass
class ConsoleRun:
    machine: Machine
    entry: int                  # the reset vector
    frames_asked: int
    cycles: int
    instructions: int
    stopped: str                # FRAMES_DONE, REACHED, VALUE_SEEN, HALTED, REPORTED or INTERRUPTED
    verdict: Verdict | None
    halt_pc: int | None = None  # where the program halted (HALTED)
    peeks: dict[str, list[int]] = field(default_factory=dict)  # filled by the command
    tracer: object = None  # a retro.analysis.trace.Tracer that observed the run (--trace, --watch)

    @property
    def frames_run(self) -> float:
        """The run's length in frames of 341 x 262 dots (odd-frame skips not counted)."""
        return float(self.cycles / CPU_CYCLES_PER_FRAME)

    @property
    def ppu(self) -> PpuDevice:
        return ppu_of(self.machine)


class StopRun(Exception):
    """Raised by a run's observer after the step that meets a stop condition (`reason`)."""

    def __init__(self, reason: str) -> None:
        self.reason = reason


class _Watch:
    """Observer of the run loop: raises StopRun after the instruction that meets a condition. `quiet()`
    says whether no interrupt can come any more (then an instruction jumping to itself halts)."""

    def __init__(self, machine: Machine, until: int | None, until_value: tuple[int, int] | None,
                 quiet: Callable[[], bool]) -> None:
        self.memory = machine.bus.memory
        self.peek = machine.bus.peek
        self.quiet = quiet
        self.until = until
        self.until_value = until_value
        self.pc = -1
        self.halt_pc: int | None = None

    def before(self, mpu) -> None:
        self.pc = mpu.pc if mpu.pending_interrupt is None else -1

    def after(self, mpu) -> None:
        pc = mpu.pc
        if pc == self.pc and self.quiet():
            op = self.memory[pc]
            if op == JMP_ABSOLUTE or op in BRANCH_OPCODES:
                self.halt_pc = pc
                raise StopRun(HALTED)
        if pc == self.until:
            raise StopRun(REACHED)
        if self.until_value is not None and self.peek(self.until_value[0]) == self.until_value[1]:
            raise StopRun(VALUE_SEEN)


def run_frames(machine: Machine, end: int, frame_cycles: int, watch, after_frame=None) -> tuple[str, int]:
    """Run `machine` on from its state to machine cycle `end`, a frame at a time, with `watch` (an
    observer raising StopRun) told of every step; `after_frame()` True ends the run (REPORTED).
    Returns (why it stopped, instructions run); Ctrl-C ends it as INTERRUPTED with the state so far."""
    instructions = 0
    frame_end = machine.cycle
    try:
        while machine.cycle < end:
            frame_end = min(end, frame_end + frame_cycles)
            try:
                instructions += machine.run_on(frame_end - machine.cycle, observer=watch)
            except StopRun as stop:
                return stop.reason, instructions + machine.mpu.executed
            if after_frame is not None and after_frame():
                return REPORTED, instructions
    except KeyboardInterrupt:
        return INTERRUPTED, instructions + machine.mpu.executed
    return FRAMES_DONE, instructions


def blargg_verdict(memory: list[int]) -> Verdict | None:
    """The $6000 protocol's verdict, or None without its signature."""
    if tuple(memory[SIGNATURE_ADDRESS:SIGNATURE_ADDRESS + len(SIGNATURE)]) != SIGNATURE:
        return None
    status = memory[STATUS_ADDRESS]
    raw = bytes(memory[TEXT_ADDRESS:TEXT_ADDRESS + TEXT_LIMIT])
    text = raw.split(b"\0", 1)[0].decode("latin-1").strip()
    if status == STATUS_RUNNING:
        return Verdict("$6000", None, None, text)
    if status == STATUS_NEEDS_RESET:
        return Verdict("$6000", None, None, "the ROM asks for the reset button, which retro run does not press")
    if status > STATUS_NEEDS_RESET:
        return Verdict("$6000", status, None, f"status ${status:02X} is not one the protocol defines")
    return Verdict("$6000", status, status == CODE_PASSED, text)


def result_byte_verdict(value: int, address: int, halted: bool) -> Verdict:
    protocol = f"result byte ${address:02X}" if address < 0x100 else f"result byte ${address:04X}"
    if not halted:
        return Verdict(protocol, None, None, "the ROM had not halted: the result byte is not final")
    if value == RESULT_PASSED:
        return Verdict(protocol, value, True, "passed")
    return Verdict(protocol, value, False, f"failed test #{value}")


def run_cartridge(cartridge: NromCartridge, *, frames: int, until: int | None = None,
                  until_value: tuple[int, int] | None = None, result_at: int | None = None, wrap=None) -> ConsoleRun:
    """Power on a console with `cartridge`, reset, and run up to `frames` frames (module docstring).
    `wrap(machine, watch)`: the observer to run with instead of the stop conditions' (a profiler)."""
    if not 1 <= frames <= MAX_FRAMES:
        raise InputError(f"--frames: {frames:,} is not a frame count in 1..{MAX_FRAMES:,}")
    machine = build_nes(cartridge=cartridge)
    entry = reset(machine)
    ppu = ppu_of(machine)
    mpu = machine.mpu
    watch = _Watch(machine, until, until_value,
                   lambda: not ppu.ctrl & CTRL_NMI and (mpu.p & FLAG_I or ppu.irq_next >= NEVER))
    observer = watch if wrap is None else wrap(machine, watch)
    start = machine.cycle
    verdicts: list[Verdict | None] = [None]

    def reported() -> bool:
        verdicts[0] = blargg_verdict(machine.memory)
        return verdicts[0] is not None and verdicts[0].passed is not None

    stopped, instructions = run_frames(machine, start + math.ceil(frames * CPU_CYCLES_PER_FRAME),
                                       math.ceil(CPU_CYCLES_PER_FRAME), observer, reported)
    verdict = verdicts[0]
    if verdict is None or verdict.passed is None:
        verdict = blargg_verdict(machine.memory) or verdict
    if result_at is not None and (verdict is None or verdict.protocol != "$6000"):
        verdict = result_byte_verdict(machine.bus.peek(result_at), result_at, stopped == HALTED)
    ppu_of(machine).advance(ppu_of(machine).dot_of(machine.cycle))
    return ConsoleRun(machine=machine, entry=entry, frames_asked=frames, cycles=machine.cycle - start,
                      instructions=instructions, stopped=stopped, verdict=verdict, halt_pc=watch.halt_pc)


def ppu_registers(ppu: PpuDevice) -> dict:
    """The PPU's registers and position after a run, as `retro run --json` reports them."""
    frame, line, dot = ppu.where()
    return {"frame": frame, "line": line, "dot": dot, "ctrl": ppu.ctrl, "mask": ppu.mask, "status": ppu.peek(PPUSTATUS),
            "oam_addr": ppu.oam_addr, "v": ppu.v, "t": ppu.t, "fine_x": ppu.fine_x, "w": ppu.w}

