"""The APU frame counter's interrupt (retro/chips/apu_frame.py), each rule against the numbers of its
source (nesdev wiki "APU Frame Counter", "APU"; blargg's blargg_apu_2005.07.30 readme.txt and
tests.txt), written here as literals so that changing a constant fails a test; and OAM DMA coming
after the interrupt poll of the `$4014` write (retro/cpu/mpu.py `stall`; cpu_interrupts_v2 4-irq_and_dma),
on a console: the frame IRQ through the I/O ports and the PPU's lines, the PPU's own OAM DMA.

Cycles are machine cycles; the counter's origin is 0, so odd cycles begin an APU cycle (writes there
restart the sequence 3 cycles later, writes on even cycles 4).
"""

from __future__ import annotations

from retro.chips.apu_frame import FrameCounter
from retro.chips.cartridge import read_nrom
from retro.chips.ines import nrom_image
from retro.machines.nes import build_nes, ppu_of

NEVER = 1 << 62
ON_APU_CYCLE = 100_001     # odd: "during an APU cycle"
BETWEEN = 100_002          # even: "between APU cycles", one cycle later


class Lines:
    irq_next = NEVER


def counter(first_instruction: int = 0) -> tuple[FrameCounter, Lines]:
    lines = Lines()
    return FrameCounter(lines, 0, first_instruction), lines


def written(value: int, cycle: int) -> tuple[FrameCounter, Lines]:
    frame_counter, lines = counter()
    frame_counter.write_mode(0x40, cycle - 40_000)  # power-on's sequence out of the way
    frame_counter.write_mode(value, cycle)
    return frame_counter, lines


def test_flag_first_set_29831_cycles_after_a_write_on_an_apu_cycle():
    frame_counter, lines = written(0x00, ON_APU_CYCLE)
    assert not frame_counter.flag(ON_APU_CYCLE + 29830)
    assert frame_counter.flag(ON_APU_CYCLE + 29831)
    assert lines.irq_next == ON_APU_CYCLE + 29831


def test_a_write_between_apu_cycles_sets_it_a_cycle_later():
    frame_counter, _ = written(0x00, BETWEEN)
    assert not frame_counter.flag(BETWEEN + 29831)
    assert frame_counter.flag(BETWEEN + 29832)


def test_the_flag_is_set_three_cycles_in_a_row():
    first = ON_APU_CYCLE + 29831
    for read_at, sees, still_set_after in ((first, True, True), (first + 1, True, True),
                                           (first + 2, True, True), (first + 3, True, False)):
        frame_counter, _ = written(0x00, ON_APU_CYCLE)
        assert bool(frame_counter.read_status(read_at)) is sees, read_at - first
        assert frame_counter.flag(read_at + 1) is still_set_after, read_at - first


def test_a_read_clears_the_flag_and_the_next_sequence_sets_it_29830_cycles_later():
    frame_counter, lines = written(0x00, ON_APU_CYCLE)
    first = ON_APU_CYCLE + 29831
    assert frame_counter.read_status(first + 10) == 0x40
    assert frame_counter.read_status(first + 11) == 0x00
    assert lines.irq_next == first + 29830
    assert not frame_counter.flag(first + 29829)
    assert frame_counter.flag(first + 29830)


def test_inhibit_clears_the_flag_and_keeps_it_clear_five_step_never_sets_it():
    frame_counter, lines = written(0x00, ON_APU_CYCLE)
    set_at = ON_APU_CYCLE + 29831 + 5
    frame_counter.write_mode(0x40, set_at)
    assert not frame_counter.flag(set_at) and not frame_counter.flag(set_at + 200_000)
    assert lines.irq_next == NEVER
    frame_counter, lines = written(0x80, ON_APU_CYCLE)
    assert not frame_counter.flag(ON_APU_CYCLE + 200_000) and lines.irq_next == NEVER


def test_clearing_the_inhibit_leaves_the_flag_as_it_is():
    frame_counter, _ = written(0x00, ON_APU_CYCLE)
    set_at = ON_APU_CYCLE + 29831 + 5
    frame_counter.write_mode(0x00, set_at)  # the flag set before stays set
    assert frame_counter.flag(set_at + 1)


def test_the_running_sequence_shows_through_until_the_restart_3_cycles_after_the_write():
    old_flag = ON_APU_CYCLE + 29831                   # even; the writes below are on APU cycles (odd)
    for write_at, shows in ((old_flag - 3, False), (old_flag - 1, True)):
        frame_counter, _ = written(0x00, ON_APU_CYCLE)
        frame_counter.write_mode(0x00, write_at)     # restarts at write_at + 3
        assert frame_counter.flag(old_flag + 2) is shows, old_flag - write_at


def test_irq_line_low_from_the_flags_first_cycle():
    frame_counter, _ = written(0x00, ON_APU_CYCLE)
    assert not frame_counter.irq_low(ON_APU_CYCLE + 29830)
    assert frame_counter.irq_low(ON_APU_CYCLE + 29831)


def test_power_on_acts_as_a_00_write_10_cycles_before_the_first_instruction():
    frame_counter, lines = counter(first_instruction=11)   # the implied write at cycle 1, an APU cycle
    assert lines.irq_next == 1 + 29831
    frame_counter, lines = counter(first_instruction=12)   # at cycle 2, between: a cycle later
    assert lines.irq_next == 2 + 29832


def _console(body: list[int]):
    """A console whose NROM PRG holds `body` at $C000 and the IRQ handler at $C100: it keeps the
    pushed PC's low byte at $10 and returns with I set (TSX, LDA $0102,X, STA $10, LDA $0101,X,
    ORA #$04, STA $0101,X, RTI)."""
    prg = bytearray([0xEA] * 0x4000)
    prg[:len(body)] = bytes(body)
    prg[0x100:0x10F] = bytes([0xBA, 0xBD, 0x02, 0x01, 0x85, 0x10, 0xBD, 0x01, 0x01, 0x09, 0x04, 0x9D, 0x01, 0x01, 0x40])
    prg[0x3FFE:0x4000] = bytes([0x00, 0xC1])
    return build_nes(cartridge=read_nrom(nrom_image(bytes(prg), bytes(0x2000), "horizontal"), "test.nes"))


def _irq_from(machine, cycle: int) -> bool:
    """Set the frame flag from machine cycle `cycle` with a $4017 = $00 write 29831 cycles before it,
    if that write lands on an APU cycle (else no write can: the flag starts only on every other cycle)."""
    frame_counter = ppu_of(machine).irq_source
    frame_counter.write_mode(0x00, cycle - 29831)
    return frame_counter.lines.irq_next == cycle


def _return_address_of_irq(irq_at: int) -> tuple[int, int]:
    """LDA #$02, STA $4014 (OAM DMA; the STA's cycles 0-3 counted from 0), NOP, NOP, RTS on a console
    with the frame flag set from cycle `irq_at`, after a BIT $10 (3 cycles) where that puts the STA on
    a cycle the flag can start at: (the pushed PC's low byte counted from the LDA, DMA cycles)."""
    body = [0xA9, 0x02, 0x8D, 0x14, 0x40, 0xEA, 0xEA, 0x60]
    for prefix, cycles in (([], 0), ([0x24, 0x10], 3)):
        machine = _console(prefix + body)
        if _irq_from(machine, machine.cycle + cycles + 2 + irq_at):
            machine.call(0xC000, p=0x20, budget=2_000)
            return machine.bus.peek(0x10) - len(prefix), ppu_of(machine).dma_stalled
    raise AssertionError(f"no start puts the flag at {irq_at}")


def test_an_irq_asserted_during_oam_dma_is_taken_after_the_next_instruction():
    # the STA polls in its cycle 2; its write (cycle 3) starts the DMA (cycles 4 .. 3 + dma); the NOP
    # after it polls in its first cycle, 4 + dma. Pushed PC: 5 (after the STA), 6 (after the NOP), 7.
    for irq_at in (0, 1, 2, 3, 4, 300, *range(510, 520)):  # the second NOP polls at 6 + dma
        pushed, dma = _return_address_of_irq(irq_at)
        assert dma in (513, 514)
        expected = 0x05 if irq_at <= 2 else 0x06 if irq_at <= 4 + dma else 0x07
        assert pushed == expected, (irq_at, dma)
