"""A sprite X write within a line (docs/vic.md, "A sprite X write within a line").

Sources: [VICE-src] VICE x64sc, vice/src/viciisc/vicii-draw-cycle.c (trigger_sprites starts a
sprite's shift register where the pixel's X equals the X piped at the end of the cycle before and
only while it is not already shifting; draw_sprites ends it when the register runs empty;
update_sprite_data reloads it at the sprite's fetch); the VICE test program VICII/spritex/testsuite
(testsuite.tas, PAL rows: X 95 -> 96 and 95 -> 94 written in the cycle of X 95 keep the old row,
96 -> 95 shows nothing in that line, 97 -> 96 shows the row at 96), whose table is a real C64's.

On the 6569 the sequencer draws X 95 at the last pixel of cycle 25 and X 96 at the first of cycle
26 (constants.COLLISION_LATCH_DELAY): a write in cycle 25 is compared from X 96 on.
"""

from __future__ import annotations

from vic_scenes import FULL, rows_with, scene, sprite

from retro.chips.vic.constants import PAL
from retro.chips.vic.device import VicDevice

D000, D01E = 0xD000, 0xD01E
Y = 100
ROW = 5  # sprite 7's one pixel is in this row: only line Y + 1 + ROW can collide
LINE = Y + 1 + ROW


def at(line: int, cycle: int) -> int:
    return line * PAL.cycles_per_line + cycle - 1


def collisions_after_write(x0: int, x7: int, new_x0: int, cycle: int, pixels=((ROW, 0),), read_at=None) -> int:
    """$D01E after sprite 0 (all pixels) at x0 is moved to new_x0 by a write in `cycle` of LINE,
    sprite 7 (the given pixels) at x7."""
    vic = VicDevice(scene(sprite(0, x0, Y, FULL), sprite(7, x7, Y, rows_with(list(pixels)))).state)
    vic.write(D000, new_x0, at(LINE, cycle))
    return vic.read(D01E, read_at if read_at is not None else at(LINE + 1, 40))


def test_a_row_already_started_keeps_its_x():
    """X 95 -> 96 (testsuite case 2): the row started at 95 ends at 118 and misses sprite 7 at 119;
    written a cycle earlier, before the compare at 95, the row starts at 96 and meets it."""
    assert collisions_after_write(95, 119, 96, 25) == 0
    assert collisions_after_write(95, 119, 96, 24) == 0x81


def test_a_started_row_moved_left_still_shows_its_old_pixels():
    """X 95 -> 94 (testsuite case 8): the row stays at 95-118 and meets sprite 7 at 118."""
    assert collisions_after_write(95, 118, 94, 25) == 0x81
    assert collisions_after_write(95, 118, 94, 24) == 0


def test_a_row_not_started_whose_new_x_is_passed_does_not_show_in_that_line():
    """X 96 -> 95 (testsuite case 12) in cycle 25: the compare saw 96 at X 95 and sees 95 from X 96
    on, so the row does not start in that line (sprite 7 at X 100 is met by neither place)."""
    assert collisions_after_write(96, 100, 95, 25) == 0
    assert collisions_after_write(96, 100, 95, 24) == 0x81
    assert collisions_after_write(97, 100, 96, 25) == 0x81  # case 13: 96 not passed yet


def test_a_started_row_does_not_start_again_at_a_later_x_in_its_line():
    """X 95 -> 200 in cycle 30: no second row at 200 in that line (sprite 7's pixel at 205 in
    LINE is not met); from the next line the row is at 200 (its pixel at 205 in LINE + 1 is)."""
    assert collisions_after_write(95, 205, 200, 30, read_at=at(LINE, 60)) == 0
    assert collisions_after_write(95, 205, 200, 30, pixels=((ROW + 1, 0),)) == 0x81
    assert collisions_after_write(95, 205, 200, 30, pixels=((ROW, 0),)) == 0


def test_a_second_write_can_still_start_a_row_not_started():
    """96 -> 95 in cycle 25 (passed: no row yet), then 95 -> 150 in cycle 30: the sequencer has not
    reached 150, so the row starts there in that line (sprite 7's pixel at 155 is met)."""
    vic = VicDevice(scene(sprite(0, 96, Y, FULL), sprite(7, 155, Y, rows_with([(ROW, 0)]))).state)
    vic.write(D000, 95, at(LINE, 25))
    vic.write(D000, 150, at(LINE, 30))
    assert vic.read(D01E, at(LINE + 1, 40)) == 0x81
