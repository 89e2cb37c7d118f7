"""Where the cycles go: a profile per subroutine of a program run, a handler call or a spec's cases.

`Profiler` is an observer of the CPU's run loop (`MPU6510.run`: told before and after every step),
so nothing of it runs in an unprofiled run. It keeps the call stack as the CPU builds it:
- a JSR opens a frame for its target, from the target's first instruction through the RTS that
  returns from it (the caller's JSR, 6 cycles, stays the caller's, as `Machine.call` counts);
- an interrupt sequence opens a frame for its handler, from the sequence's first cycle (its 7
  cycles are the handler's) through the RTI; entered through the KERNAL's IRQ entry (`$FF48`), the
  frame is named after the handler `JMP ($0314)` reaches;
- an RTS or RTI closes every open frame whose stack pointer before its call it restores (a frame
  dropped by PLA/PLA or left by TXS closes with the next return that passes it; an RTS used as a
  jump, which leaves the stack lower, closes nothing);
- frames still open at the end (a main loop) close there and are counted as `open`.
Per subroutine (by entry address, named by the user's symbols): calls, inclusive cycles (every
cycle of its frames, nested calls and interrupts included), exclusive cycles (inclusive minus the
frames opened inside), min/mean/max inclusive per call, cycles stolen (C64: the VIC-II's Bad Lines
and sprite DMA, `MPU6510.stolen`; NES: OAM DMA, the stall of a write to $4014), and the raster
lines (C64) or scanlines (NES) its calls ran on. The timeline (which frame was innermost at every
cycle) is kept as transitions for the picture (retro/render/profile_image.py).

On the NES the scanline of a cycle counts frames of 341 x 262 dots (the odd-frame dot skip is not
counted: after N frames the position is at most N/2 dots early).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from retro.chips.ppu.constants import DOTS_PER_LINE, OAMDMA

OPCODE_JSR, OPCODE_RTS, OPCODE_RTI, OPCODE_JMP_INDIRECT = 0x20, 0x60, 0x40, 0x6C
ABSOLUTE_STORES = frozenset({0x8D, 0x8E, 0x8C})  # STA/STX/STY abs: the ways to $4014
OPEN_STACK = 0x200  # the stack pointer "before" a frame that never closes (the run's entry)
MAX_TRANSITIONS = 1 << 20  # timeline transitions kept (the most recent): bounded memory on long runs
MAX_LINES_KEPT = 4096  # lines noted per subroutine before it is taken to span every line


@dataclass(frozen=True)
class Beam:
    """Where the beam is: machine cycles (numpy arrays) -> (frame, line, column), the column a CPU
    cycle within the line; `frame_start(f)` the first machine cycle of frame f."""

    unit: str  # "raster line" or "scanline"
    lines: int
    columns: int
    frame_cycles: float
    origin: int  # the machine cycle of frame 0, line 0, column 0
    dots_per_cycle: object = None  # NES: the PPU's dots per CPU cycle (a Fraction); None on the C64

    def positions(self, cycles):
        """(frame, line, column) of machine cycles (ints or numpy arrays)."""
        if self.dots_per_cycle is None:
            frame, within = divmod(cycles - self.origin, int(self.frame_cycles))
            line, column = divmod(within, self.columns)
            return frame, line, column
        ratio = self.dots_per_cycle
        dots = (cycles - self.origin) * ratio.numerator // ratio.denominator
        frame, within = divmod(dots, self.lines * DOTS_PER_LINE)
        line, dot = divmod(within, DOTS_PER_LINE)
        return frame, line, dot * ratio.denominator // ratio.numerator

    def position(self, cycle: int) -> tuple[int, int, int]:
        frame, line, column = self.positions(cycle)
        return int(frame), int(line), int(column)

    def frame_start(self, frame: int) -> int:
        return self.origin + math.ceil(frame * self.frame_cycles)


def vic_beam(vic) -> Beam:
    video = vic.video
    return Beam("raster line", video.lines, video.cycles_per_line, video.frame_cycles, vic.start_cycle)


def ppu_beam(ppu) -> Beam:
    video = ppu.video
    ratio = video.dots_per_cpu_cycle
    return Beam("scanline", video.lines_per_frame, -(-DOTS_PER_LINE * ratio.denominator // ratio.numerator),
                float(video.dots_per_frame / ratio), ppu.origin, ratio)


@dataclass
class RoutineStats:
    address: int
    kind: str  # "entry", "subroutine", "IRQ" or "NMI"
    calls: int = 0
    inclusive: int = 0
    exclusive: int = 0
    least: int | None = None
    most: int = 0
    stolen: int = 0  # of inclusive
    stolen_exclusive: int = 0
    open: int = 0  # frames still open when the run ended (closed there)
    lines: set[int] = field(default_factory=set)
    all_lines: bool = False

    @property
    def mean(self) -> float:
        return self.inclusive / self.calls if self.calls else 0.0


class _Frame:
    __slots__ = ("address", "kind", "start", "stolen", "sp", "child_cycles", "child_stolen", "index")

    def __init__(self, address: int, kind: str, start: int, stolen: int, sp: int, index: int) -> None:
        self.address, self.kind, self.start, self.stolen, self.sp = address, kind, start, stolen, sp
        self.child_cycles = self.child_stolen = 0
        self.index = index


class Profiler:
    """The run loop's observer (module docstring). `inner` is another observer told after this one
    (a run's stop conditions); `beam` the machine's beam (None: no raster figures); `nes` counts
    OAM DMA stalls as stolen; `stubs` the addresses of vector stubs whose frame is named after the
    handler an indirect JMP reaches (the KERNAL's IRQ entry)."""

    def __init__(self, mpu, *, beam: Beam | None = None, inner=None, nes: bool = False,
                 stubs: frozenset[int] = frozenset()) -> None:
        self.mpu = mpu
        self.beam = beam
        self.inner = inner
        self.nes = nes
        self.stubs = stubs
        self.stats: dict[tuple[int, str], RoutineStats] = {}
        self.stack: list[_Frame] = []
        self.order: list[tuple[int, str]] = []  # the routines in order of first call: their colour index
        self.transitions: deque[tuple[int, int]] = deque(maxlen=MAX_TRANSITIONS)  # (cycle, routine index; -1 none)
        self._indices: dict[tuple[int, str], int] = {}
        self.dma_stolen = 0
        self.stolen_start = 0
        self.first_cycle: int | None = None
        self.last_cycle = 0
        self._interrupt = None
        self._cycles = 0
        self._op = -1

    # ---- the run loop's observer --------------------------------------------------------------

    def before(self, mpu) -> None:
        self._cycles = mpu.processorCycles
        interrupt = self._interrupt = mpu.pending_interrupt if mpu.lines is not None else None
        self._op = -1 if interrupt is not None else mpu.memory[mpu.pc]
        if self.inner is not None:
            self.inner.before(mpu)

    def after(self, mpu) -> None:
        op = self._op
        if self._interrupt is not None:
            self._open(mpu.pc, self._interrupt, self._cycles, (mpu.sp + 3) & 0xFF)
        elif op == OPCODE_JSR:
            self._open(mpu.pc, "subroutine", mpu.processorCycles, (mpu.sp + 2) & 0xFF)
        elif op == OPCODE_RTS or op == OPCODE_RTI:
            self._close_to(mpu.sp, mpu.processorCycles)
        elif op == OPCODE_JMP_INDIRECT and self.stack and self.stack[-1].address in self.stubs:
            self._rename(self.stack[-1], mpu.pc)
        elif self.nes and op in ABSOLUTE_STORES:
            pc = mpu.pc - 3
            if mpu.memory[(pc + 1) & 0xFFFF] | mpu.memory[(pc + 2) & 0xFFFF] << 8 == OAMDMA:
                self.dma_stolen += mpu.processorCycles - self._cycles - mpu.cycletime[op]
        self.last_cycle = mpu.processorCycles
        if self.inner is not None:
            self.inner.after(mpu)

    # ---- frames -------------------------------------------------------------------------------

    def stolen_now(self) -> int:
        return self.mpu.stolen + self.dma_stolen

    def enter(self, address: int, kind: str = "entry", sp: int = OPEN_STACK) -> None:
        """Open the frame of the code a run (or each call of a spec's cases) starts in, before it runs."""
        if self.first_cycle is None:
            self.first_cycle = self.mpu.processorCycles
            self.stolen_start = self.stolen_now()
        self.last_cycle = self.mpu.processorCycles
        self._open(address, kind, self.mpu.processorCycles, sp)

    def _key_index(self, key: tuple[int, str]) -> int:
        index = self._indices.get(key)
        if index is None:
            self.stats[key] = RoutineStats(key[0], key[1])
            index = self._indices[key] = len(self.order)
            self.order.append(key)
        return index

    def _open(self, address: int, kind: str, start: int, sp: int) -> None:
        key = (address, kind)
        index = self._key_index(key)
        self.stack.append(_Frame(address, kind, start, self.stolen_now(), sp, index))
        self.transitions.append((start, index))

    def _rename(self, frame: _Frame, address: int) -> None:
        """The stub's frame is the handler's from its first cycle (timeline included)."""
        old = frame.index
        frame.address = address
        frame.index = self._key_index((address, frame.kind))
        if self.transitions and self.transitions[-1] == (frame.start, old):
            self.transitions[-1] = (frame.start, frame.index)
        else:
            self.transitions.append((self.mpu.processorCycles, frame.index))

    def _close_to(self, sp: int, end: int) -> None:
        stack = self.stack
        closed = False
        while stack and stack[-1].sp != OPEN_STACK and sp >= stack[-1].sp:
            self._close(stack.pop(), end)
            closed = True
        if closed:
            self.transitions.append((end, stack[-1].index if stack else -1))

    def _close(self, frame: _Frame, end: int, still_open: bool = False) -> None:
        cycles = end - frame.start
        stolen = self.stolen_now() - frame.stolen
        s = self.stats[(frame.address, frame.kind)]
        s.calls += 1
        s.open += still_open
        s.inclusive += cycles
        s.exclusive += cycles - frame.child_cycles
        s.stolen += stolen
        s.stolen_exclusive += stolen - frame.child_stolen
        s.least = cycles if s.least is None else min(s.least, cycles)
        s.most = max(s.most, cycles)
        if self.beam is not None and cycles > 0 and not s.all_lines:
            self._note_lines(s, frame.start, end - 1)
        if self.stack:
            parent = self.stack[-1]
            parent.child_cycles += cycles
            parent.child_stolen += stolen

    def _note_lines(self, s: RoutineStats, first: int, last: int) -> None:
        beam = self.beam
        if last - first >= beam.frame_cycles:
            s.all_lines = True
            return
        f0, l0, _ = beam.position(first)
        f1, l1, _ = beam.position(last)
        if f1 == f0:
            s.lines.update(range(l0, l1 + 1))
        else:
            s.lines.update(range(l0, beam.lines))
            s.lines.update(range(0, l1 + 1))
        if len(s.lines) >= beam.lines:
            s.all_lines = True

    def finish(self) -> None:
        """Close the frames still open (counted as `open`) at the last cycle run."""
        end = self.last_cycle
        while self.stack:
            self._close(self.stack.pop(), end, still_open=True)
        self.transitions.append((end, -1))


@dataclass
class Profile:
    """A finished profile: per routine (in order of first call), totals, and the timeline."""

    machine: str  # "c64", "nes" or "none"
    source: str  # what ran: "program run", "call", "N cases of SPEC"
    cycles: int
    stolen: int
    routines: list[RoutineStats]
    names: dict[int, str]
    beam: Beam | None
    transitions: list[tuple[int, int]]
    first_cycle: int
    order: list[tuple[int, str]]
    notes: list[str] = field(default_factory=list)
    ba_low: object = None  # C64: the VIC-II's BA-low cycles of a frame (numpy bool), for the picture

    def name(self, address: int) -> str:
        return self.names.get(address, f"${address:04X}")

    def label(self, stats: RoutineStats) -> str:
        name = self.name(stats.address)
        return name if stats.kind in ("subroutine", "entry") else f"{name} ({stats.kind})"


def finished(profiler: Profiler, *, machine: str, source: str, symbols: dict[str, int],
             notes: list[str] | None = None, ba_low=None) -> Profile:
    """The profile of a run the profiler observed (its open frames closed)."""
    profiler.finish()
    names: dict[int, str] = {}
    for name, address in sorted(symbols.items(), key=lambda item: (len(item[0]), item[0])):
        names.setdefault(address, name)
    routines = [s for s in (profiler.stats[key] for key in profiler.order) if s.calls]  # a renamed stub has none
    first = profiler.first_cycle if profiler.first_cycle is not None else 0
    return Profile(machine=machine, source=source, cycles=profiler.last_cycle - first,
                   stolen=profiler.stolen_now() - profiler.stolen_start, routines=routines, names=names, beam=profiler.beam,
                   transitions=list(profiler.transitions), first_cycle=first, order=list(profiler.order),
                   notes=notes or [], ba_low=ba_low)


def line_ranges(lines: set[int]) -> list[tuple[int, int]]:
    """Sorted lines -> [(first, last), ...] runs."""
    out: list[tuple[int, int]] = []
    for line in sorted(lines):
        if out and line == out[-1][1] + 1:
            out[-1] = (out[-1][0], line)
        else:
            out.append((line, line))
    return out

