"""A NES as far as timing needs one: the 2A03 and the PPU, with OAM DMA at $4014.

`build_nes` is the one place a NES is put together. An NES scene only says what the PPU holds
(`retro.machines.build_machine` reads it); the program then runs from RAM. With a cartridge
(`retro.chips.cartridge.NromCartridge`) the machine is a console: PRG ROM at $8000-$FFFF, CHR ROM or
RAM in the PPU, the board's mirroring, the 2 KiB of RAM mirrored up to $1FFF, PRG RAM at
$6000-$7FFF, and the APU and controller ports at $4000-$4017 reading as an idle console's: of the
APU only the frame counter's interrupt is modelled (`retro.chips.apu_frame`: `$4017` writes, the
frame flag in `$4015` bit 6, the IRQ line); sound registers ignore writes, `$4015`'s other bits read
0 (no channel playing, no DMC interrupt); `$4016`/`$4017` read $40: no button pressed, the upper bits
the open bus's $40 left by the address (nesdev wiki "APU", "Standard controller", "Open bus behavior").
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.chips.apu_frame import FrameCounter
from retro.chips.cartridge import PRG_START, NromCartridge
from retro.chips.ppu.constants import CTRL_NMI, DOTS_PER_LINE, OAMDMA, PPU_REGISTER_BASE, PPU_REGISTER_END, VBLANK_DOT, VBLANK_LINE, VideoStandard
from retro.chips.ppu.device import PpuDevice
from retro.chips.ppu.state import PpuState
from retro.cpu.machine import Machine
from retro.cpu.mpu import FLAG_I, FLAG_U, INTERRUPT_CYCLES, RESET_VECTOR

CPU = "2a03"
RAM_SIZE = 0x800                # 2 KiB at $0000-$07FF ...
RAM_MIRRORS_START = 0x0800      # ... seen again at $0800-$1FFF
RAM_MIRRORS_END = 0x1FFF
IO_START = 0x4000               # APU and I/O registers $4000-$4017 (+ $4018-$401F, test mode, unused)
IO_END = 0x401F
APU_STATUS = 0x4015
APU_FRAME_COUNTER = 0x4017      # written: the frame counter; read: controller 2
CONTROLLER_PORTS = (0x4016, 0x4017)
IDLE_CONTROLLER = 0x40          # no button (bit 0 = 0); bits 5-7 the open bus's $40
OPEN_BUS_IO = 0x40              # what a write-only register at $40xx reads back
PRG_END = 0xFFFF
RESET_SP = 0xFD                 # the 6502's reset sequence leaves S three pushes below $00


class _RamMirror:
    """$0800-$1FFF: the console's 2 KiB of RAM again (the address lines above A10 are not decoded)."""

    def __init__(self, memory: list[int]) -> None:
        self.memory = memory

    def read(self, address: int, cycle: int) -> int:
        return self.memory[address & (RAM_SIZE - 1)]

    def write(self, address: int, value: int, cycle: int) -> None:
        self.memory[address & (RAM_SIZE - 1)] = value

    def peek(self, address: int) -> int:
        return self.memory[address & (RAM_SIZE - 1)]


class _IdleIo:
    """$4000-$401F but $4014: the APU (its frame counter only) and the controller ports of a console
    nobody plays."""

    def __init__(self, frame_counter: FrameCounter) -> None:
        self.frame_counter = frame_counter

    def read(self, address: int, cycle: int) -> int:
        if address == APU_STATUS:
            return self.frame_counter.read_status(cycle)
        return self.peek(address)

    def write(self, address: int, value: int, cycle: int) -> None:
        if address == APU_FRAME_COUNTER:
            self.frame_counter.write_mode(value, cycle)

    def peek(self, address: int) -> int:
        if address == APU_STATUS:
            return self.frame_counter.peek_status()
        if address in CONTROLLER_PORTS:
            return IDLE_CONTROLLER
        return OPEN_BUS_IO


class _Rom:
    """PRG ROM: data reads see the loaded bytes, writes do nothing (NROM has no mapper registers)."""

    def __init__(self, memory: list[int]) -> None:
        self.memory = memory

    def read(self, address: int, cycle: int) -> int:
        return self.memory[address]

    def write(self, address: int, value: int, cycle: int) -> None:
        pass

    def peek(self, address: int) -> int:
        return self.memory[address]


def build_nes(state: PpuState | None = None, cartridge: NromCartridge | None = None) -> Machine:
    """A fresh NES: a 2A03 with a PPU holding `state` (power-on state without one) at $2000-$3FFF
    (8-byte mirrors) and $4014, its clock at line 0, dot 0 now. With `cartridge`, the console
    around it (module docstring); `state` then defaults to the cartridge's CHR and mirroring."""
    machine = Machine(CPU)
    if cartridge is not None and state is None:
        state = PpuState(mirroring=cartridge.mirroring, chr=cartridge.chr)
    # OAM DMA copies a page of the CPU's memory and holds the CPU meanwhile: the PPU needs both
    device = PpuDevice(state, read_memory=machine.bus.peek, stall=machine.mpu.stall,
                       chr_writable=cartridge is None or cartridge.chr_ram)
    device.start_clock(machine.cycle)
    machine.attach(device, PPU_REGISTER_BASE, PPU_REGISTER_END)
    machine.attach(device, OAMDMA, OAMDMA)
    if cartridge is not None:
        memory = machine.bus.memory
        machine.attach(_RamMirror(memory), RAM_MIRRORS_START, RAM_MIRRORS_END)
        # the console starts at this cycle (`reset`): power-on's implied $4017 write comes just before
        device.irq_source = frame_counter = FrameCounter(device, device.origin, machine.cycle)
        io = _IdleIo(frame_counter)
        machine.attach(io, IO_START, OAMDMA - 1)
        machine.attach(io, OAMDMA + 1, IO_END)
        machine.bus.load(PRG_START, cartridge.prg)
        machine.attach(_Rom(memory), PRG_START, PRG_END)
        machine.mpu.stop_on_brk = False  # BRK is an instruction of the program, not the end of a call
    return machine


def reset(machine: Machine) -> int:
    """The CPU's reset sequence: PC from $FFFC, S = $FD, I set; returns the entry address."""
    mpu = machine.mpu
    mpu.pc = machine.bus.peek(RESET_VECTOR) | machine.bus.peek(RESET_VECTOR + 1) << 8
    mpu.sp = RESET_SP
    mpu.p = FLAG_U | FLAG_I
    mpu.pending_interrupt = None
    return mpu.pc


def ppu_of(machine: Machine) -> PpuDevice | None:
    """The machine's PPU, or None on a machine without one."""
    device = machine.mpu.lines
    return device if isinstance(device, PpuDevice) else None


# An NMI handler's first cycle when the NMI is taken at once: the vblank flag is set at line 241,
# dot 1 (nesdev wiki "PPU frame timing") and the 7-cycle interrupt sequence (21 dots on NTSC) follows.
# A handler entered later (the NMI waits for the current instruction to end) has that much less.
VBLANK_START_DOT = VBLANK_LINE * DOTS_PER_LINE + VBLANK_DOT


@dataclass(frozen=True)
class FrameEntry:
    """Where in the frame a call starts: its first CPU cycle, counted from line 0, dot 0 (the first
    cycle beginning at or after the dot asked for), the line and dot that cycle begins at, and the
    CPU cycles from it to the pre-render line, where rendering starts (the vblank budget of a call
    entered in vblank)."""

    cycle: int
    line: int
    dot: int
    rendering_cycles: int
    in_nmi: bool = False


def frame_entry(video: VideoStandard, line: int, dot: int, in_nmi: bool = False) -> FrameEntry:
    """The call's start at the first CPU cycle beginning at or after (`line`, `dot`) of a frame."""
    ratio = video.dots_per_cpu_cycle
    return entry_at_cycle(video, -(-(line * DOTS_PER_LINE + dot) * ratio.denominator // ratio.numerator), in_nmi)


def entry_at_cycle(video: VideoStandard, cycle: int, in_nmi: bool = False) -> FrameEntry:
    """The call's start at CPU cycle `cycle` of a frame (`retro.chips.ppu.clock`: it begins at dot
    floor(cycle x dots per cycle))."""
    ratio = video.dots_per_cpu_cycle
    begins = cycle * ratio.numerator // ratio.denominator
    rendering = video.pre_render_line * DOTS_PER_LINE
    return FrameEntry(cycle, begins // DOTS_PER_LINE, begins % DOTS_PER_LINE,
                      (rendering - begins) * ratio.denominator // ratio.numerator, in_nmi)


def nmi_entry(video: VideoStandard, sequence_counted: bool = False) -> FrameEntry:
    """An NMI handler's start: its first instruction the cycle after the 7-cycle sequence begun at
    the vblank flag (`VBLANK_START_DOT`); `sequence_counted` (a spec entered as "nmi", whose cycles
    count the sequence): the sequence's first cycle."""
    handler = frame_entry(video, 0, VBLANK_START_DOT + INTERRUPT_CYCLES * video.dots_per_cpu_cycle)
    return entry_at_cycle(video, handler.cycle - (INTERRUPT_CYCLES if sequence_counted else 0), in_nmi=True)


def position_after(video: VideoStandard, entry: FrameEntry, cycles: int) -> tuple[int, int, int]:
    """(line, dot, frames crossed) where a call entered at `entry` returns after `cycles` cycles (the
    dot its next cycle begins at; frames of full length: frame 0 is even, it never skips a dot)."""
    ratio = video.dots_per_cpu_cycle
    frames, within = divmod((entry.cycle + cycles) * ratio.numerator // ratio.denominator, video.dots_per_frame)
    return within // DOTS_PER_LINE, within % DOTS_PER_LINE, frames


def enter_frame(machine: Machine, entry: FrameEntry) -> int:
    """Put the NES's PPU where a call entered at `entry` starts: the clock so that the machine's next
    cycle is entry.cycle of frame 0, the frame drawn so far (vblank, sprite-0 hit and overflow flags
    as set by then) and an NMI edge of this frame's vblank taken already (the NMI came before the
    call, or is the call). Returns the absolute dot of that cycle."""
    ppu = ppu_of(machine)
    ppu.start_clock(machine.cycle - entry.cycle)
    ppu.advance(ppu.dot_of(machine.cycle))
    ppu.nmi_pending = False
    ppu._refresh_nmi_next()
    return ppu.dot_of(machine.cycle)


def cycles_to_nmi(ppu: PpuDevice, entry: FrameEntry) -> int | None:
    """CPU cycles from a call's start at `entry` to the next NMI edge the CPU could see, with the
    scene's $2000 (None: the NMI is off)."""
    if not ppu.ctrl & CTRL_NMI:
        return None
    video = ppu.video
    entered = entry.line * DOTS_PER_LINE + entry.dot
    # the next vblank flag, one dot early at most (the odd-frame skip of the frame before it)
    vblank = VBLANK_START_DOT + (video.dots_per_frame - 1 if entered >= VBLANK_START_DOT else 0)
    ratio = video.dots_per_cpu_cycle
    return max(0, vblank * ratio.denominator // ratio.numerator - entry.cycle)


def vblank_budget(machine: Machine, start: int, cycles: int, dma_before: int) -> dict:
    """A call that began at machine cycle `start` (after `enter_frame`) and took `cycles`: where it began
    and ended (line, dot), the CPU cycles of vblank left when it returned (before the pre-render line,
    where rendering starts; negative: it ran into it), and the cycles OAM DMA held the CPU."""
    ppu = ppu_of(machine)
    video = ppu.video
    frame_dots = video.dots_per_frame
    ratio = video.dots_per_cpu_cycle
    first = ppu.dot_of(start) % frame_dots
    end = ppu.dot_of(start + cycles) % frame_dots
    rendering = video.pre_render_line * DOTS_PER_LINE
    left = (rendering - ppu.dot_of(start + cycles)) * ratio.denominator // ratio.numerator
    return {"start_line": first // DOTS_PER_LINE, "start_dot": first % DOTS_PER_LINE,
            "end_line": end // DOTS_PER_LINE, "end_dot": end % DOTS_PER_LINE, "cycles": cycles,
            "vblank_cycles_left": int(left), "oam_dma_cycles": ppu.dma_stalled - dma_before}
