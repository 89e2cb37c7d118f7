"""A C64 as far as timing needs one: the 6510, the VIC-II driving BA and IRQ, and the raster budget.

`build_c64` is the one place a C64 is put together; a VIC-II scene only says what to put in it
(`retro.machines.build_machine` reads it).

No CIA, SID, KERNAL or disk. A scene may ask for the KERNAL's IRQ entry so that a program can hook
the `$0314` vector as it would on a real C64: then the ROM's entry and exit code (a fact of the
machine: `$FF48`-`$FF5A` and `$EA81`-`$EA86` of the KERNAL, as listed in S. Leemon, *Mapping the
Commodore 64*, and every KERNAL disassembly) is placed in RAM and `$FFFE/$FFFF` points at it, so the
handler is reached 29 cycles after the interrupt sequence, as on the real machine.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from retro.chips.vic.beam import position
from retro.chips.vic.constants import CIA2_BASE, CIA2_LAST, VIC_BASE, VIC_LAST
from retro.chips.vic.device import VicDevice
from retro.chips.vic.fetch import VicBankPort, VicFetcher
from retro.chips.vic.model import VicState
from retro.cpu.bus import Device
from retro.cpu.machine import Machine
from retro.errors import InputError
from retro.scenes.vic import IRQ_VECTOR_HARDWARE, IRQ_VECTOR_KERNAL, VicScene

CPU = "6510"
CPU_IRQ_VECTOR = 0xFFFE
KERNAL_IRQ_ENTRY = 0xFF48
# PHA / TXA / PHA / TYA / PHA / TSX / LDA $0104,X / AND #$10 / BEQ +3 / JMP ($0316) / JMP ($0314)
KERNAL_IRQ_ENTRY_CODE = bytes([0x48, 0x8A, 0x48, 0x98, 0x48, 0xBA, 0xBD, 0x04, 0x01, 0x29, 0x10,
                               0xF0, 0x03, 0x6C, 0x16, 0x03, 0x6C, 0x14, 0x03])
KERNAL_IRQ_EXIT = 0xEA81
KERNAL_IRQ_EXIT_CODE = bytes([0x68, 0xA8, 0x68, 0xAA, 0x68, 0x40])  # PLA / TAY / PLA / TAX / PLA / RTI
# The KERNAL's IRQ handler ($EA31: clock, cursor blink, keyboard scan, CIA 1 acknowledge, then the
# exit at $EA81) stood in for by a JMP to its exit: what it does touches only the KERNAL's work
# area and CIA 1, which a program run does not model; it takes fewer cycles than the ROM's.
KERNAL_IRQ_HANDLER = 0xEA31
KERNAL_IRQ_HANDLER_STUB = bytes([0x4C, KERNAL_IRQ_EXIT & 0xFF, KERNAL_IRQ_EXIT >> 8])  # JMP $EA81
# $FEBC, the end of the KERNAL's NMI handler, is the same register restore and RTI as $EA81 [Mapping
# the Commodore 64, $FEBC]; IRQ handlers end with JMP $FEBC to skip the keyboard scan.
KERNAL_NMI_EXIT = 0xFEBC


def build_c64(state: VicState | None = None, *, start_line: int = 0, start_cycle: int = 1,
              irq_vector: str = IRQ_VECTOR_HARDWARE, vic: Device | None = None, reads_memory: bool = False,
              char_rom: bytes | None = None) -> Machine:
    """A fresh C64: a 6510 with a VIC-II holding `state` at $D000-$D3FF, driving the CPU's BA and IRQ
    lines, its beam at line `start_line`, cycle `start_cycle` now, the frame drawn so far in its
    latches ($D01E, $D01F, $D019: `VicDevice.at_beam` with `drawn`); with `irq_vector` "$0314" the
    KERNAL's IRQ entry is in RAM. `vic`: a device of the caller's at the VIC-II's registers instead
    (the latch study's, which answers reads of one case's frame and leaves the CPU's lines alone).

    With `reads_memory` the VIC-II fetches sprite data, screen, character set and colour RAM from
    the machine's RAM (retro.chips.vic.fetch; `char_rom` the character ROM image, if the user has
    one) and CIA 2's port A at $DD00 picks its bank; otherwise `state` holds what it sees."""
    machine = Machine(CPU)
    if vic is None:
        if state is None:
            raise ValueError("build_c64 needs a VIC-II state or a device")
        fetcher = None
        if reads_memory:
            port = machine.attach(VicBankPort(), CIA2_BASE, CIA2_LAST)
            fetcher = VicFetcher(machine.bus.memory, port, char_rom)
        vic = VicDevice.at_beam(state, machine.cycle, start_line, start_cycle, drawn=True, fetcher=fetcher)
    machine.attach(vic, VIC_BASE, VIC_LAST)
    if irq_vector == IRQ_VECTOR_KERNAL:
        install_kernal_irq_entry(machine)
    return machine


def vic_of(machine: Machine) -> VicDevice | None:
    """The machine's VIC-II, or None on a machine without one."""
    device = machine.mpu.lines
    return device if isinstance(device, VicDevice) else None


def install_kernal_irq_entry(machine: Machine) -> None:
    """Put the KERNAL's IRQ entry and exit in RAM and point the CPU's IRQ vector at the entry."""
    machine.bus.load(KERNAL_IRQ_ENTRY, KERNAL_IRQ_ENTRY_CODE)
    machine.bus.load(KERNAL_IRQ_EXIT, KERNAL_IRQ_EXIT_CODE)
    machine.bus.load(CPU_IRQ_VECTOR, bytes([KERNAL_IRQ_ENTRY & 0xFF, KERNAL_IRQ_ENTRY >> 8]))


def install_kernal_irq_handler_stub(machine: Machine) -> None:
    """Put the stand-in for the KERNAL's IRQ handler (KERNAL_IRQ_HANDLER_STUB) at $EA31, and the
    KERNAL's register restore at $FEBC."""
    machine.bus.load(KERNAL_IRQ_HANDLER, KERNAL_IRQ_HANDLER_STUB)
    machine.bus.load(KERNAL_NMI_EXIT, KERNAL_IRQ_EXIT_CODE)


@dataclass(frozen=True)
class RasterBudget:
    """Where on the beam a routine ran: first and last cycle as (raster line, 1-based cycle in line).

    `cycles` counts every cycle from the first instruction through the RTS, `stolen` those in which
    the VIC-II held the CPU (Bad Lines, sprite DMA); `lines` is cycles / cycles per line, and
    `frames` how many frame ends the routine ran across (0: it ended in the frame it began in).
    """

    chip: str
    start_line: int
    start_cycle: int
    end_line: int
    end_cycle: int
    cycles: int
    stolen: int
    lines: float
    frames: int

    def ends_before(self, line: int) -> bool:
        """Whether the routine's last cycle is in the frame it started in and above `line`."""
        return self.frames == 0 and self.end_line < line

    def as_dict(self) -> dict:
        return asdict(self)


def raster_budget(device: VicDevice, start: int, cycles: int, stolen: int) -> RasterBudget:
    """The raster budget of a routine that began at machine cycle `start` and took `cycles` cycles."""
    if cycles < 1:
        raise ValueError("a routine takes at least one cycle")
    video = device.video
    first_frame, start_line, start_cycle = position(video, device.time(start))
    last_frame, end_line, end_cycle = position(video, device.time(start + cycles - 1))
    return RasterBudget(chip=video.chip, start_line=start_line, start_cycle=start_cycle, end_line=end_line,
                        end_cycle=end_cycle, cycles=cycles, stolen=stolen,
                        lines=round(cycles / video.cycles_per_line, 2), frames=last_frame - first_frame)


def call_budget(machine, result) -> RasterBudget | None:
    """The raster budget of the `Machine.call` that just returned `result`, or None without a VIC-II.

    The call ended at the machine's clock now, so it began `result.cycles` earlier.
    """
    device = vic_of(machine)
    if device is None:
        return None
    return raster_budget(device, machine.cycle - result.cycles, result.cycles, result.stolen)


OPCODE_RTI = 0x40


def interrupt_budgets(machine, result) -> list[RasterBudget]:
    """The raster budget of every interrupt in the traced `Machine.call` that just returned `result`.

    Each runs from the first cycle of its 7-cycle interrupt sequence through the RTI that returns
    from it (nested interrupts counted inside the outer one). Empty without a VIC-II or a trace.
    """
    device = vic_of(machine)
    if device is None or not result.trace:
        return []
    budgets = []
    at = machine.cycle - result.cycles
    opened: list[tuple[int, int]] = []  # (first cycle, stolen so far) of interrupts not yet returned from
    stolen = 0
    for entry in result.trace:
        if entry.mode == "int":
            opened.append((at, stolen))
        at += entry.cycles
        stolen += entry.stolen
        if entry.opcode == OPCODE_RTI and opened:
            first, stolen_before = opened.pop()
            if not opened:
                budgets.append(raster_budget(device, first, at - first, stolen - stolen_before))
    return budgets


def call_at_line(scene: VicScene, program, entry, line: int, cycle: int = 1, **call_args):
    """Call `entry` of `program` on a fresh C64 with `scene`'s VIC-II, the beam at (line, cycle).

    Returns (CallResult, RasterBudget): what `retro cycles SPEC --scene S --at-line L` needs per call
    (`call_args` go to Machine.call: a=, x=, y=, p=, memory=, budget=, trace=).
    """
    video = scene.state.video
    if not 0 <= line < video.lines or not 1 <= cycle <= video.cycles_per_line:
        raise InputError(f"--at-line: the {video.chip} has lines 0-{video.lines - 1} and cycles "
                         f"1-{video.cycles_per_line}, got line {line} cycle {cycle}")
    machine = build_c64(scene.state, start_line=line, start_cycle=cycle, irq_vector=scene.irq_vector)
    machine.load(program)
    result = machine.call(entry, **call_args)
    return result, call_budget(machine, result)
