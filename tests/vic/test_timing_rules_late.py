"""The C64 timing rules of issue 26 part 5, each worked by hand from its public source.

Sources: [Bauer] C. Bauer, "The MOS 6567/6569 video controller (VIC-II)" 3.5 (the Bad Line
condition: DEN set in any cycle of line $30), 3.8.1 (sprite DMA switched on in cycles 55-56 when
MxE is set and Y matches; off when MCBASE reaches 63), 3.9 (the vertical border flip-flop), 3.12
(the raster compare); [VICE-src] VICE x64sc, vice/src/viciisc/vicii-cycle.c (the raster compare
latches when it goes from no match to a match, checked every cycle; allow_bad_lines set by DEN in
any cycle of line $30; the vertical border opened by DEN in any cycle of the top line;
check_sprite_dma / check_sprite_display test $D015 only when a sprite's DMA starts); the VICE
test programs VICII/dentest (howto.txt: the results of DEN switched around lines $30 and 51).

Times are device times: line L, 1-based cycle c is L * cycles + c - 1; a write at t changes what
the chip sees from t + 1 on (docs/vic.md, timing model).
"""

from __future__ import annotations

from vic_scenes import scene, sprite

from retro.chips.vic.constants import PAL
from retro.chips.vic.device import VicDevice

PAL_LINE = PAL.cycles_per_line
D011, D012, D015, D019, D01A, D01E = 0xD011, 0xD012, 0xD015, 0xD019, 0xD01A, 0xD01E


def at(line: int, cycle: int, video=PAL) -> int:
    return line * video.cycles_per_line + cycle - 1


def quiet_device(**registers) -> VicDevice:
    """A PAL VIC-II with no sprite and the raster compare at line 200."""
    regs = {"$d012": 200, "$d01a": 0x01, **registers}
    return VicDevice(scene(registers=regs).state)


# ---- a $D012 write that matches the current line ------------------------------------------------

def test_a_d012_write_onto_the_current_line_latches_the_raster_irq():
    """[VICE-src] The compare is made every cycle and latches on no-match -> match; a write in the
    middle of line 100 that sets the compare to 100 latches $D019 bit 0 at once (Bauer 3.12's "the
    line is reached" is the common case of the same rule)."""
    vic = quiet_device()
    assert vic.read(D019, at(100, 29)) & 0x01 == 0
    vic.write(D012, 100, at(100, 30))
    assert vic.read(D019, at(100, 31)) == 0xF1  # bit 0, bit 7 (enabled in $D01A), unused bits
    assert vic.irq_low(at(100, 31))


def test_a_d012_write_onto_a_line_already_passed_waits_for_the_next_frame():
    vic = quiet_device()
    vic.write(D012, 99, at(100, 30))
    assert vic.read(D019, at(100, 40)) & 0x01 == 0
    assert vic.read(D019, at(99, 1) + PAL.frame_cycles - 1) & 0x01 == 0
    assert vic.read(D019, at(99, 1) + PAL.frame_cycles + 1) & 0x01 == 1


def test_only_a_change_to_a_match_latches_again():
    """Acknowledged after the write, the compare still matching: a $D011 write that leaves the
    compare line alone does not latch; moving the compare away and back within the line does."""
    vic = quiet_device()
    vic.write(D012, 100, at(100, 10))
    vic.write(D019, 0x01, at(100, 12))
    vic.write(D011, 0x1C, at(100, 14))  # YSCROLL 4: the compare line stays 100
    assert vic.read(D019, at(100, 16)) & 0x01 == 0
    vic.write(D012, 101, at(100, 20))
    assert vic.read(D019, at(100, 22)) & 0x01 == 0
    vic.write(D012, 100, at(100, 24))
    assert vic.read(D019, at(100, 26)) & 0x01 == 1


def test_bit_8_written_through_d011_matches_too():
    """Line 300 ($12C): $D012 = $2C first (compare $2C), then $D011 bit 7 -> compare $12C in line 300."""
    vic = quiet_device()
    vic.write(D012, 0x2C, at(300, 5))
    vic.write(D019, 0x01, at(300, 7))
    assert vic.read(D019, at(300, 9)) & 0x01 == 0
    vic.write(D011, 0x9B, at(300, 10))
    assert vic.read(D019, at(300, 12)) & 0x01 == 1


def test_compare_line_0_written_in_cycle_1_of_line_0_latches_once_in_cycle_2():
    """In cycle 1 of line 0 the counter still reads the last line (docs/vic.md: line 0's IRQ comes a
    cycle late): a write there does not match; the compare does when the counter reaches 0."""
    vic = quiet_device()
    frame = PAL.frame_cycles
    vic.write(D019, 0x01, frame - 3)  # line 200's compare acknowledged
    vic.write(D012, 0, frame + at(0, 1) - 1)  # the last cycle of line 311
    assert vic.read(D019, frame + at(0, 1)) & 0x01 == 0
    assert vic.read(D019, frame + at(0, 2) + 1) & 0x01 == 1
