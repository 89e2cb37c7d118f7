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
    assert not vic.irq_low(at(100, 30))  # the compare is made in the next cycle ...
    assert vic.irq_low(at(100, 31))  # ... where the IRQ line goes low, as at a line's cycle 1
    assert vic.read(D019, at(100, 32)) == 0xF1  # bit 0, bit 7 (enabled in $D01A), unused bits


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


# ---- $D015 written while a sprite is being displayed -------------------------------------------------
# Sprites 0 (X 100) and 1 (X 110) at Y 100 overlap on lines 101-121 (rows 0-20); sprite 1's
# DMA check is in cycles 55 and 56 of line 100, its fetches in cycles 60-61 (sprite 0 holds BA low through 59, so cycle 61 is sprite 1 alone).

def two_sprites(enable: int) -> VicDevice:
    """Sprite 1 enabled in $D015 or not (sprite 0 always)."""
    made = VicDevice(scene(sprite(0, 100, 100), sprite(1, 110, 100, enabled=bool(enable & 2))).state)
    assert made.registers[0x15] == enable
    return made


def test_clearing_d015_does_not_stop_a_sprite_whose_dma_runs():
    """[Bauer 3.8.1; VICE-src check_sprite_display] $D015 is looked at only when the DMA starts:
    sprite 1 switched off in line 102 keeps fetching and showing its rows to row 20, and it
    collides there; in the next frame it does not start."""
    vic = two_sprites(0x03)
    vic.write(D015, 0x01, at(102, 30))
    assert vic.read(D01E, at(103, 1)) == 0b11  # the overlap drawn so far
    assert vic.read(D01E, at(120, 1)) == 0b11  # drawn again on lines 103-119
    assert vic.ba_wait(at(110, 61)) > 0  # its fetch in line 110 still holds the CPU
    frame = PAL.frame_cycles
    assert vic.read(D01E, frame + at(99, 1)) == 0b11  # rows 19-20 drawn in frame 0
    assert vic.read(D01E, frame + at(125, 1)) == 0  # frame 1: sprite 1 never started
    assert vic.ba_wait(frame + at(110, 61)) == 0


def test_setting_d015_shows_a_sprite_only_from_its_next_dma_start():
    vic = two_sprites(0x01)
    vic.write(D015, 0x03, at(102, 30))
    assert vic.read(D01E, at(125, 1)) == 0
    assert vic.ba_wait(at(110, 61)) == 0
    frame = PAL.frame_cycles
    assert vic.read(D01E, frame + at(99, 1)) == 0
    assert vic.read(D01E, frame + at(125, 1)) == 0b11


def test_the_dma_check_sees_d015_in_cycles_55_and_56_the_display_check_in_58():
    """A write in cycle c is seen from c + 1. The DMA starts if $D015 is set in cycle 55 or 56
    [Bauer 3.8.1]; the sprite is shown only if it is still set in cycle 58 [VICE-src
    check_sprite_display]. Enabling in cycle 55 reaches the second check (DMA and display), in 56
    neither; clearing in 54 reaches both DMA checks (nothing), in 55 or 57 only the display check
    (the sprite fetches and steals cycles, unseen), in 58 nothing (fetched and shown)."""
    def this_frame(before: int, after: int, cycle: int) -> tuple[bool, bool]:
        vic = two_sprites(before)
        vic.write(D015, after, at(100, cycle))
        return vic.ba_wait(at(110, 61)) > 0, vic.read(D01E, at(125, 1)) == 0b11

    assert this_frame(0x01, 0x03, 55) == (True, True)
    assert this_frame(0x01, 0x03, 56) == (False, False)
    assert this_frame(0x03, 0x01, 54) == (False, False)
    assert this_frame(0x03, 0x01, 55) == (True, False)
    assert this_frame(0x03, 0x01, 57) == (True, False)
    assert this_frame(0x03, 0x01, 58) == (True, True)


# ---- DEN switched late or off in the middle of a frame ---------------------------------------------
# YSCROLL 3: Bad Lines $33, $3B, ... ($6B = 107 among them); BA low in cycles 12-54 of a Bad Line.
# Sprite 0 at (100, 140) over a screen of solid characters collides with the graphics on lines
# 141-161 (text rows 11-14).

SOLID = {"screen": {"fill": 0xA0}, "charset": {"160": [0xFF] * 8}}


def den_device(control1: int) -> VicDevice:
    return VicDevice(scene(sprite(0, 100, 140), registers={"$d011": control1}, memory=SOLID).state)


def bad_line_107(vic: VicDevice, frame: int = 0) -> bool:
    return vic.ba_wait(frame * PAL.frame_cycles + at(107, 20)) > 0


def sprite_background(vic: VicDevice, frame: int = 0) -> int:
    """$D01F as read after line 165 of the frame, cleared before line 130."""
    vic.read(0xD01F, frame * PAL.frame_cycles + at(130, 1))
    return vic.read(0xD01F, frame * PAL.frame_cycles + at(165, 1))


def test_den_cleared_after_line_30_keeps_the_frame_drawn_and_its_bad_lines():
    """[Bauer 3.5, 3.9] Bad Lines need DEN in line $30 only, and the border opened in line 51 stays
    open to line 251: DEN cleared in line 100 changes nothing until the next frame, which has no Bad
    Line and no graphics."""
    vic = den_device(0x1B)
    vic.write(D011, 0x0B, at(100, 30))
    assert bad_line_107(vic)
    assert sprite_background(vic) == 0x01
    assert not bad_line_107(vic, 1)
    assert sprite_background(vic, 1) == 0


def test_den_set_after_line_30_waits_for_the_next_frame():
    vic = den_device(0x0B)
    vic.write(D011, 0x1B, at(60, 30))
    assert not bad_line_107(vic)
    assert sprite_background(vic) == 0
    assert bad_line_107(vic, 1)
    assert sprite_background(vic, 1) == 0x01


def test_den_counts_in_any_cycle_of_line_30():
    """[Bauer 3.5: "set during an arbitrary cycle of raster line $30"; VICII/dentest den01-48-*]"""
    vic = den_device(0x0B)
    vic.write(D011, 0x1B, at(0x30, 60))
    assert bad_line_107(vic)
    assert sprite_background(vic) == 0x01
    late = den_device(0x0B)
    late.write(D011, 0x1B, at(0x31, 1))
    assert not bad_line_107(late)


def test_den_set_in_line_30_then_cleared_keeps_bad_lines_but_not_the_display():
    """DEN set in line $30 then cleared before line 51: Bad Lines this frame, but the vertical border
    stays closed (no graphics, no $D01F) [Bauer 3.9; VICII/dentest den10-48-*: idle or closed]."""
    vic = den_device(0x1B)
    vic.write(D011, 0x0B, at(0x30, 20))
    assert bad_line_107(vic)
    assert sprite_background(vic) == 0


def test_the_display_opens_if_den_is_set_in_any_cycle_of_the_first_window_line():
    """[Bauer 3.9; VICE-src check_vborder_top] DEN set in line $30, off in line 49, on again in
    line 51 (RSEL 1) cycle 40: the border opens. On again in line 52: it stays closed."""
    for line, opened in ((51, True), (52, False)):
        vic = den_device(0x1B)
        vic.write(D011, 0x0B, at(49, 10))
        vic.write(D011, 0x1B, at(line, 40))
        assert sprite_background(vic) == (0x01 if opened else 0), line
        assert bad_line_107(vic)


# ---- collision IRQs with Y-scroll changes ----------------------------------------------------------
# Sprites 0 and 1 overlap first at line 101, X 110: latched in cycle 27 (docs/vic.md, timing model).

def test_a_yscroll_write_moves_the_bad_line_under_a_sprite_sprite_irq():
    """[Bauer 3.5] The Bad Line condition is (line & 7) == YSCROLL in every cycle: with YSCROLL 3
    ($1B) line 99 is a Bad Line and 101 is not; YSCROLL 5 written in line 100 makes 101 one (BA low from
    cycle 12 through the sprites' DMA in 55-61, so the CPU is held when the collision IRQ latches in cycle 27); written in cycle
    20 of line 101 it holds the CPU from cycle 21. The IRQ itself latches in cycle 27 either way:
    sprite-sprite collisions do not depend on the graphics."""
    def device() -> VicDevice:
        return VicDevice(scene(sprite(0, 100, 100), sprite(1, 110, 100), registers={"$d01a": 0x04}).state)

    steady = device()
    assert steady.ba_wait(at(99, 20)) > 0 and steady.ba_wait(at(101, 20)) == 0
    moved = device()
    moved.write(D011, 0x1D, at(100, 5))
    assert moved.ba_wait(at(99, 20) + PAL.frame_cycles) == 0
    assert moved.ba_wait(at(101, 12)) == 61 - 12 + 1  # merged with sprites 0-1 DMA (55-61)
    assert not moved.irq_low(at(101, 26) - 1) and moved.irq_low(at(101, 27))
    late = device()
    assert late.ba_wait(at(101, 20)) == 0
    late.write(D011, 0x1D, at(101, 20))
    assert late.ba_wait(at(101, 21)) == 61 - 21 + 1
    assert not late.irq_low(at(101, 26) - 1) and late.irq_low(at(101, 27))


def test_a_program_writing_the_current_line_to_d012_takes_the_irq_at_once():
    """On the 6510 (docs/vic.md, CPU timeline): entered at line 100 cycle 1 with I clear, LDA #
    (cycles 1-2), STA $D012 writing in its 4th cycle (6): the compare matches from cycle 7, the NOP
    that follows polls in its first cycle (7) and the 7-cycle sequence (9-15) reaches the handler in
    cycle 16 of line 100. Without the rule no interrupt comes in the call at all."""
    from test_vic_timeline import DEN_OFF, irq_run, handler_start  # the IRQ harness of the timeline tests

    result, entries = irq_run(100, 1, "", "lda #100\n sta $d012\n nop\n nop\n nop", compare=200)
    assert DEN_OFF & 0x10 == 0  # no Bad Line moves the cycles
    assert handler_start(entries) == (100, 16)


# ---- the idle byte in a border opened without Bad Lines ---------------------------------------------

def idle_device(idle: int) -> VicDevice:
    """DEN clear in line $30 (no Bad Line this frame), set in line 51 (RSEL 1): the border opens."""
    memory = {**SOLID, "idle": idle}
    vic = VicDevice(scene(sprite(0, 100, 140), registers={"$d011": 0x0B}, memory=memory).state)
    vic.write(D011, 0x1B, at(51, 40))
    return vic


def test_an_open_border_without_bad_lines_shows_the_idle_byte_and_it_collides():
    """[Bauer 3.7.1: display state comes only from a Bad Line; 3.8.2: idle graphics collide;
    VICII/dentest howto.txt: "idle data ($3FFF)" when the border opens without Bad Lines] The solid
    characters are never fetched: the sprite meets the idle byte, every line of the window."""
    assert not bad_line_107(idle_device(0xFF))
    assert sprite_background(idle_device(0xFF)) == 0x01
    assert sprite_background(idle_device(0x00)) == 0     # an idle byte of 0: nothing to meet
    pixel = idle_device(0x01)                             # only pixel 7 of each column is foreground
    assert sprite_background(pixel) == 0x01


def test_the_idle_byte_of_a_border_open_without_bad_lines_is_not_the_characters():
    """With Bad Lines the same sprite meets the solid characters whatever the idle byte is."""
    vic = VicDevice(scene(sprite(0, 100, 140), registers={"$d011": 0x1B}, memory={**SOLID, "idle": 0}).state)
    assert sprite_background(vic) == 0x01
