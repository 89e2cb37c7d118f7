"""On the 6567R8 a collision latches in the cycle of the sequencer slot that draws it: cycles 62 and
63 both draw X $180-$187 (VICE's cycle_tab_ntsc; the spritegap dumps of a 6567R8 confirm the
sequencer), so every X after them is drawn one cycle later than its X alone would say, and a pair
that meets in the second pass latches in cycle 63.

Worked by hand from the rules in docs/vic.md: cycle 1 of a line starts at X $19C - 4 (the 4-X latch
delay), 8 X a cycle; the 6567R8's cycle 63 repeats the X of cycle 62. A sprite's row 0 is on line
Y + 1. Frame time = line x 65 + (1-based cycle - 1)."""

from __future__ import annotations

from vic_scenes import rows_with, scene, sprite

from retro.chips.vic.model import frame_collisions

Y = 100
LINE = Y + 1
CYCLES_PER_LINE = 65  # 6567R8 [Bauer 3.4]


def ss_times(*sprites, video="ntsc"):
    return frame_collisions(scene(*sprites, video=video).state).ss_times.tolist()


def test_x_after_the_repeated_cycle_latches_one_cycle_later():
    # X $190: slot ($190 - ($19C - 4)) mod 512 = 504, + 8 for the repeated cycle = 512: 0-based cycle 64,
    # cycle 65 (by its X alone, slot 504, it would be cycle 64)
    one = rows_with([(0, 0)])
    assert ss_times(sprite(6, 0x190, Y, one), sprite(7, 0x190, Y, one)) == [LINE * CYCLES_PER_LINE + 64]


def test_a_pair_meeting_in_the_second_pass_latches_in_cycle_63():
    # sprite 7 at X $178 starts at slot 480; its column 16 is slot 496, the first of cycle 63, which
    # draws X $180 again. Sprite 6 at X $180 starts at its first pass, slot 488; its column 8 is slot 496.
    assert ss_times(sprite(6, 0x180, Y, rows_with([(0, 8)])), sprite(7, 0x178, Y, rows_with([(0, 16)]))) == [
        LINE * CYCLES_PER_LINE + 62]
    # the same X in the first pass (columns 0 and 8: slot 488, cycle 62) latches a cycle earlier
    assert ss_times(sprite(6, 0x180, Y, rows_with([(0, 0)])), sprite(7, 0x178, Y, rows_with([(0, 8)]))) == [
        LINE * CYCLES_PER_LINE + 61]


def test_pal_and_the_6567r56a_latch_where_the_x_says():
    # no repeated cycle: X $190 on the 6567R56A (X $19C in cycle 1, 64 cycles): slot 504 -> 0-based cycle 63
    one = rows_with([(0, 0)])
    assert ss_times(sprite(6, 0x190, Y, one), sprite(7, 0x190, Y, one), video="ntsc-old") == [LINE * 64 + 63]
    # 6569 (X $194 in cycle 1, 63 cycles, 504 X): an overlap at X $190-$193 of line L latches in cycle 1
    # of line L + 1 (the 4-X delay carries it over the line's end; docs/vic.md, timing model)
    assert ss_times(sprite(6, 0x190, Y, one), sprite(7, 0x190, Y, one), video="pal") == [LINE * 63 + 63]
