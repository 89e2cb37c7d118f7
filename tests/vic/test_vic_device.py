"""The VIC-II bus device: registers, latches and beam timing as a 6502 program sees them.

Timing expectations are worked out by hand from the model in docs/vic.md: the run starts at line 0,
cycle 1; a PAL line is 63 cycles; pixel X of a line is drawn in cycle index ((X - $194) mod 504) // 8;
a read sees pixels drawn in earlier cycles; LDA/BIT abs read in their 4th cycle.
"""

from __future__ import annotations

from pathlib import Path

from vic_scenes import rows_with, scene, sprite

from retro.commands.run import run as run_routine
from retro.assembler import assemble_text
from retro.chips.vic.device import VicDevice
from retro.cpu import Machine
from retro.machines import build_machine

PAL_LINE = 63
OVERLAP_LINE = 101  # sprites 0 (X 100) and 1 (X 110), both full at Y 100: first common pixel (101, 110)
OVERLAP_CYCLE_INDEX = (110 - 0x194) % 504 // 8  # 26: cycle 27 of the line
OVERLAP_TIME = OVERLAP_LINE * PAL_LINE + OVERLAP_CYCLE_INDEX


def two_sprites(**kw):
    return scene(sprite(0, 100, 100), sprite(1, 110, 100), **kw)


def machine_with(scene_obj, source: str) -> Machine:
    machine = build_machine(scene_obj)
    machine.load(assemble_text(source))
    return machine


def device(**kw) -> VicDevice:
    return VicDevice(two_sprites(**kw).state, start_cycle=0)


# ---- timing, directly on the device ------------------------------------------------------------

def test_bit_appears_when_the_beam_draws_the_overlap_pixel():
    assert OVERLAP_TIME == 6389
    assert device().read(0xD01E, OVERLAP_TIME) == 0
    assert device().read(0xD01E, OVERLAP_TIME + 1) == 0b11


# VICE test programs VICII/spritecollisions/sprite-sprite-collision-cycle and
# sprite-gfx-collision-cycle (PAL; readme: C64 and C64C show "CC@@@@@" and "CCBBBBB", i.e. 3,3,0,0,0,0,0
# and 3,3,2,2,2,2,2). Sprites 0 and 1 hold one pixel (row 0, column 0) at Y $34 -> line 53; X starts
# at $56 (86) and sprite 0 (both sprites in the $D01E test) moves right by one each frame; the
# $D01F test has solid characters in text row 0, columns 7-14 (X 80-143, lines 51-58).
# When the program reads, worked out by hand from Bauer 3.6.3's 6569 timing diagrams: the stable
# double raster IRQ leaves the handler at cycle 4 of line 51 (RASTER increments at cycle 1); line 51
# is a Bad Line (YSCROLL 3), so the opcode fetch of LDX #1 in cycle 12 waits until cycle 55; the
# clearing LDA $D01E reads in cycle 1 of line 52; the delay loop (74 cycles) loses cycles 55-61 of
# line 52 to the DMA of sprites 0 and 1 (BA low three cycles before sprite 0's s-access in cycle
# 58); the second LDA $D01E reads in cycle 25 of line 53.
VICE_READ_TIME = 53 * PAL_LINE + 24
ONE_PIXEL = rows_with([(0, 0)])


def test_vice_sprite_sprite_collision_cycle():
    for x, expected in zip(range(86, 93), (3, 3, 0, 0, 0, 0, 0)):
        vic = VicDevice(scene(sprite(0, x, 0x34, ONE_PIXEL), sprite(1, x, 0x34, ONE_PIXEL)).state)
        assert vic.read(0xD01E, VICE_READ_TIME) == expected, x


def test_vice_sprite_gfx_collision_cycle():
    memory = {"screen": {"fill": 32, "cells": [{"col": c, "row": 0, "value": 0xA0} for c in range(7, 15)]},
              "charset": {"160": [0xFF] * 8}}  # $A0: the reversed space, all pixels set
    for x, expected in zip(range(86, 93), (3, 3, 2, 2, 2, 2, 2)):
        vic = VicDevice(scene(sprite(0, x, 0x34, ONE_PIXEL), sprite(1, 86, 0x34, ONE_PIXEL), memory=memory).state)
        assert vic.read(0xD01F, VICE_READ_TIME) == expected, x


def test_start_cycle_offsets_the_frame():
    vic = VicDevice(two_sprites().state, start_cycle=1000)
    assert vic.read(0xD01E, 1000 + OVERLAP_TIME) == 0
    assert vic.read(0xD01E, 1000 + OVERLAP_TIME + 1) == 0b11


def test_raster_registers_follow_the_clock():
    vic = device()
    # In cycle 1 of line 0 the counter still shows the frame's last line (311 = $137): it reaches 0
    # in cycle 2, which is why line 0's raster IRQ comes a cycle late [Bauer 3.12]; issue 15
    # measured the same on VICE x64sc.
    assert vic.read(0xD012, 0) == 311 - 256 and vic.read(0xD011, 0) & 0x80
    assert vic.read(0xD012, 1) == 0 and not vic.read(0xD011, 1) & 0x80
    assert vic.read(0xD012, 100 * PAL_LINE + 62) == 100
    assert vic.read(0xD012, 101 * PAL_LINE) == 101
    assert vic.read(0xD011, 300 * PAL_LINE) == 0x1B | 0x80 and vic.read(0xD012, 300 * PAL_LINE) == 300 - 256
    assert vic.read(0xD012, 312 * PAL_LINE + 1) == 0  # next frame
    ntsc = VicDevice(scene(video="ntsc").state)
    assert ntsc.read(0xD012, 262 * 65 + 64) == 6 and ntsc.read(0xD012, 263 * 65) == 6
    assert ntsc.read(0xD012, 263 * 65 + 1) == 0


# ---- 6502 programs -----------------------------------------------------------------------------------

POLL = """
.org $c000
poll:   lda $d01e
        beq poll
        sta result
        lda $d012
        sta result+1
        lda $d011
        sta result+2
        rts
result: .byte 0, 0, 0
"""


def test_program_polling_d01e_sees_the_bit_on_the_overlap_line():
    machine = machine_with(two_sprites(), POLL)
    machine.call("poll")
    value, line, control = machine.peek("result", 3)
    # reads at 3 + 7k: the first one after 6389 is at 6394; LDA $D012 reads at 6404 -> line 101
    assert value == 0b11
    assert line == OVERLAP_LINE and control & 0x80 == 0


def test_program_sees_raster_bit_8():
    source = """
.org $c000
wait:   bit $d011
        bpl wait
        lda $d012
        sta result
        rts
result: .byte $ff
"""
    machine = machine_with(scene(), source)
    result = machine.call("wait")
    assert machine.peek("result") == [0]  # line 256: low byte 0
    # BIT reads at 3 + 7k; the first read on line 256 (cycle 16128) is at 16131
    assert 16128 <= result.cycles <= 16128 + 20


READS = """
.org $c000
        ; wait for line 130 (after the overlap, lines 101-121)
wait:   lda $d012
        cmp #130
        bne wait
        lda $d01e
        sta out
        lda $d01e       ; cleared by the first read
        sta out+1
        lda #$ff
        sta $d01e       ; writes are ignored
        lda $d01e
        sta out+2
wait2:  lda $d012       ; next frame, line 130 again
        cmp #129
        bne wait2
wait3:  lda $d012
        cmp #130
        bne wait3
        lda $d3de       ; a mirror of $d01e ($d000 + 15*64 + $1e)
        sta out+3
        lda $d01e       ; the mirror read cleared it
        sta out+4
        lda $d02f       ; unused registers read $ff
        sta out+5
        lda $d03f
        sta out+6
        lda $d016       ; bits 6-7 unused: read 1
        sta out+7
        lda $d020       ; bits 4-7 unused
        sta out+8
        lda $d05f       ; mirror of $d01f
        sta out+9
        rts
out:    .byte 0, 0, 0, 0, 0, 0, 0, 0, 0, 0
"""


def test_clear_on_read_mirrors_ignored_writes_unused_bits():
    machine = machine_with(two_sprites(registers={"$d016": 0x08, "$d020": 0x0E}), READS)
    machine.call(0xC000)
    out = machine.peek("out", 10)
    assert out[0] == 0b11  # accumulated since the overlap
    assert out[1] == 0  # cleared by the read
    assert out[2] == 0  # the $ff write did not land
    assert out[3] == 0b11  # next frame's overlap, read through a mirror
    assert out[4] == 0  # the mirror read cleared it
    assert out[5] == 0xFF and out[6] == 0xFF
    assert out[7] == 0x08 | 0xC0
    assert out[8] == 0x0E | 0xF0
    assert out[9] == 0  # no sprite-background collision in this scene


ACK = """
.org $c000
wait:   lda $d012
        cmp #130
        bne wait
        lda $d019
        sta out         ; sprite-sprite (bit 2) and raster (bit 0, line 0) latched, bit 7 (enabled)
        inc $d019       ; RMW: writes the old value back first, acknowledging every latched bit
        lda $d019
        sta out+1
wait2:  lda $d012       ; next frame, after the overlap: $D01E was never read, so no new latch
        cmp #129
        bne wait2
wait3:  lda $d012
        cmp #130
        bne wait3
        lda $d019
        sta out+2
        lda $d01e       ; reading $d01e does not touch $d019 ...
        lda $d019
        sta out+3
        sta $d019       ; ... acknowledge the raster bit again by writing 1s
wait4:  lda $d012       ; ... but now $d01e is zero, so the next overlap latches bit 2 again
        cmp #129
        bne wait4
wait5:  lda $d012
        cmp #130
        bne wait5
        lda $d019
        sta out+4
        rts
out:    .byte 0, 0, 0, 0, 0
"""


def test_d019_latches_on_zero_to_nonzero_and_acks_with_inc():
    machine = machine_with(two_sprites(registers={"$d01a": 0x04}), ACK)
    machine.call(0xC000)
    out = machine.peek("out", 5)
    assert out[0] == 0x80 | 0x70 | 0x04 | 0x01
    assert out[1] == 0x70
    assert out[2] == 0x70 | 0x01  # only the raster bit of the new frame; bit 2 did not latch again
    assert out[3] == out[2]
    assert out[4] == 0x80 | 0x70 | 0x04 | 0x01


def test_irq_bit7_needs_the_source_enabled():
    vic = device(registers={"$d01a": 0x02})  # only sprite-background enabled
    assert vic.read(0xD019, 200 * PAL_LINE) == 0x70 | 0x04 | 0x01
    vic.write(0xD01A, 0x04, 200 * PAL_LINE + 1)
    assert vic.read(0xD019, 200 * PAL_LINE + 2) == 0x80 | 0x70 | 0x04 | 0x01
    assert vic.read(0xD01A, 200 * PAL_LINE + 3) == 0xF4


MOVE = """
.org $c000
wait:   lda $d012
        cmp #150
        bne wait
        lda #180        ; move both sprites to Y 180 (rows on lines 181-201): they overlap there
        sta $d001
        sta $d003
poll:   lda $d01e
        beq poll
        lda $d012
        sta out
        rts
out:    .byte 0
"""


def test_register_writes_between_bands_are_honoured():
    # sprites 0 (X 100) and 1 (X 110), apart vertically at first: Y 20 and Y 200 -> no overlap
    apart = scene(sprite(0, 100, 20), sprite(1, 110, 200))
    machine = machine_with(apart, MOVE)
    machine.call(0xC000)
    assert machine.peek("out") == [181]


SEPARATE = """
.org $c000
wait:   lda $d012
        cmp #150
        bne wait
        lda #20         ; move sprite 1 away before the overlap at lines 201-221
        sta $d003
wait2:  lda $d012
        cmp #240
        bne wait2
        lda $d01e
        sta out
        rts
out:    .byte $ff
"""


def test_moving_a_sprite_away_before_the_beam_gets_there_prevents_the_collision():
    together = scene(sprite(0, 100, 200), sprite(1, 110, 200))
    machine = machine_with(together, SEPARATE)
    machine.call(0xC000)
    assert machine.peek("out") == [0]


def test_retro_run_attaches_the_scene(tmp_path: Path):
    scene_file = tmp_path / "s.toml"
    scene_file.write_text('chip = "vic-ii"\n[[sprite]]\nindex = 0\nx = 100\ny = 100\ndata = "' + "ff " * 63
                          + '"\n[[sprite]]\nindex = 1\nx = 110\ny = 100\ndata = "' + "ff " * 63 + '"\n')
    source = tmp_path / "poll.s"
    source.write_text(POLL)
    report = run_routine(source, "poll", scene=scene_file, peeks=["result:2"])
    assert report.peeks["result"] == [0b11, OVERLAP_LINE]


def test_unused_bits_of_every_register_read_1():
    # Bauer 3.2 register table: unused are $D016 bits 6-7, $D018 bit 0, $D019 bits 4-6, $D01A bits 4-7,
    # $D020-$D02E bits 4-7; every other register uses all 8 bits; $D02F-$D03F read $FF.
    unused = {0x16: 0xC0, 0x18: 0x01, 0x1A: 0xF0, **{r: 0xF0 for r in range(0x20, 0x2F)}}
    vic = VicDevice(scene(registers={f"$d0{r:02x}": 0 for r in (0x16, 0x18, 0x1A, 0x20, 0x2E)}).state)
    for register in (0x15, 0x16, 0x17, 0x18, 0x1A, 0x1B, 0x1C, 0x1D, 0x20, 0x21, 0x25, 0x27, 0x2E):
        assert vic.read(0xD000 + register, 10) == unused.get(register, 0), hex(register)
    assert vic.read(0xD019, 10) == 0x70 | 0x01  # bits 4-6; raster compare line 0 passed at cycle 2


GFX_MEMORY = {"screen": {"fill": 32, "cells": [{"col": c, "row": 0, "value": 0xA0} for c in range(7, 15)]},
              "charset": {"160": [0xFF] * 8}}  # solid characters under the sprites' one pixel (above)
PAL_FRAME = 312 * PAL_LINE
IRQ_SPRITE_BACKGROUND_BIT = 0x02


def test_d01f_clears_on_read_and_d019_bit1_latches_only_from_zero():
    vic = VicDevice(scene(sprite(0, 86, 0x34, ONE_PIXEL), sprite(1, 86, 0x34, ONE_PIXEL), memory=GFX_MEMORY).state)
    t = VICE_READ_TIME
    assert vic.read(0xD019, t) & IRQ_SPRITE_BACKGROUND_BIT  # latched when $D01F went from 0 to non-zero
    vic.write(0xD019, IRQ_SPRITE_BACKGROUND_BIT, t + 1)  # acknowledged; $D01F is not read
    assert vic.read(0xD019, t + PAL_FRAME) & IRQ_SPRITE_BACKGROUND_BIT == 0  # $D01F still non-zero: no latch
    assert vic.read(0xD01F, t + PAL_FRAME + 1) == 0b11
    assert vic.read(0xD01F, t + PAL_FRAME + 2) == 0  # cleared by the read
    assert vic.read(0xD019, t + 2 * PAL_FRAME) & IRQ_SPRITE_BACKGROUND_BIT  # from zero again: latched
    assert vic.read(0xD01F, t + 2 * PAL_FRAME + 1) == 0b11


def test_a_register_write_takes_effect_in_the_next_cycle():
    # The first common pixel of the two sprites, sprite 1's first (X 110), is drawn in cycle
    # OVERLAP_TIME (above). Moving sprite 1 away by a write in that very cycle is too late (the
    # cycle still compared the old X, and a started row keeps its X: docs/vic.md, "A sprite X write
    # within a line"); a write one cycle earlier is in time. (Sprite 0's row started at X 100 in the
    # cycle before: moving it then no longer moves that row.)
    vic = device()
    vic.write(0xD002, 200, OVERLAP_TIME)
    assert vic.read(0xD01E, OVERLAP_TIME + 1) == 0b11
    vic = device()
    vic.write(0xD002, 200, OVERLAP_TIME - 1)
    assert vic.read(0xD01E, OVERLAP_TIME + 1) == 0
    vic = device()
    vic.write(0xD000, 200, OVERLAP_TIME - 1)
    assert vic.read(0xD01E, OVERLAP_TIME + 1) == 0b11
