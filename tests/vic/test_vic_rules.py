"""One test per hardware rule of issue 3 (docs/vic.md). Expected values are worked out by hand from
the rule as documented (Bauer's VIC-II article, PRG p.145), never copied from the model's output."""

from __future__ import annotations

import pytest
from vic_scenes import FULL, latches, rows_with, sprite

PIXEL = rows_with([(0, 0)])  # one opaque pixel: row 0, column 0


def text_memory(glyph: list[int], code: int = 1, col: int = 10, row: int = 5, color: int = 1, **extra) -> dict:
    """Screen of spaces (code 32, blank glyph) with one character at (col, row)."""
    return {"screen": {"fill": 32, "cells": [{"col": col, "row": row, "value": code}]},
            "color": {"fill": 1, "cells": [{"col": col, "row": row, "value": color}]},
            "charset": {str(code): glyph}, **extra}


# ---- sprite pixels ---------------------------------------------------------------------------------

def test_pixel_i_of_row_r_is_at_x_plus_i_on_line_y_plus_1_plus_r():
    # A: one pixel at row 3, column 7 -> (line 100+1+3, X 150+7) = (104, 157). B: a full sprite whose
    # top-left is there too, so the only common pixel is that one.
    a = sprite(0, 150, 100, rows_with([(3, 7)]))
    b = sprite(1, 157, 103, FULL)
    r = latches(a, b)
    assert r.d01e == 0b11
    assert r.first_d01e == (104, 157)
    assert latches(a, sprite(1, 158, 103, FULL)).d01e == 0  # one pixel to the right: misses


@pytest.mark.parametrize("value, opaque", [("1", True), ("2", True), ("3", True), (".", False)])
def test_multicolor_pairs_01_10_11_opaque_00_transparent(value, opaque):
    # Pair 2 of row 0 covers X = x + 4 and x + 5 (double-wide pixel).
    a = sprite(0, 100, 100, rows_with([(0, 2)], multicolor=True, value=value), multicolor=True)
    b = sprite(1, 105, 100, PIXEL)  # X 105 = right half of the pair
    assert latches(a, b).d01e == (0b11 if opaque else 0)


def test_x_expansion_doubles_pixels():
    a = sprite(0, 100, 100, rows_with([(0, 1)]), expand_x=True)  # column 1 -> X 102 and 103
    assert latches(a, sprite(1, 103, 100, PIXEL)).d01e == 0b11
    assert latches(a, sprite(1, 104, 100, PIXEL)).d01e == 0
    assert latches(a, sprite(1, 101, 100, PIXEL)).d01e == 0


def test_y_expansion_shows_each_row_on_two_lines():
    a = sprite(0, 100, 100, rows_with([(1, 0)]), expand_y=True)  # row 1 -> lines 103 and 104
    # B's pixel row 0 sits on line y+1
    assert latches(a, sprite(1, 100, 102, PIXEL)).first_d01e == (103, 100)
    assert latches(a, sprite(1, 100, 103, PIXEL)).first_d01e == (104, 100)
    assert latches(a, sprite(1, 100, 104, PIXEL)).d01e == 0
    assert latches(a, sprite(1, 100, 101, PIXEL)).d01e == 0


def test_x_is_nine_bits():
    # 300 = $12C: low byte $2C = 44 and bit 8 in $D010
    assert latches(sprite(0, 300, 100), sprite(1, 300, 100)).d01e == 0b11
    assert latches(sprite(0, 300, 100), sprite(1, 300 - 256, 100)).d01e == 0


# ---- $D01E ---------------------------------------------------------------------------------------------

def test_all_sprites_in_an_overlap_are_set_and_others_not():
    r = latches(sprite(0, 100, 100), sprite(1, 110, 100), sprite(2, 120, 100), sprite(3, 200, 100))
    # 0-1 overlap (X 110-123), 1-2 overlap (120-133), 0-2 overlap (120-123); 3 alone
    assert r.d01e == 0b0111
    assert r.pairs == ((0, 1), (0, 2), (1, 2))


def test_collisions_in_the_border_and_off_screen_count():
    # Line 5 is in the vertical blank on PAL (visible from line 16); X 400 is in the horizontal blank.
    assert latches(sprite(0, 400, 4), sprite(1, 410, 4)).d01e == 0b11
    # Upper border (visible, outside the display window)
    assert latches(sprite(0, 100, 20), sprite(1, 110, 20)).d01e == 0b11


def test_disabled_sprite_never_collides():
    assert latches(sprite(0, 100, 100), sprite(1, 100, 100, enabled=False)).d01e == 0
    memory = {"screen": {"fill": 1}, "charset": {"1": [255] * 8}}
    assert latches(sprite(0, 100, 100, enabled=False), memory=memory).d01f == 0


def test_priority_does_not_matter():
    memory = {"screen": {"fill": 1}, "charset": {"1": [255] * 8}}
    r = latches(sprite(0, 100, 100, behind=True), sprite(1, 110, 100), memory=memory)
    assert r.d01e == 0b11 and r.d01f == 0b11


# ---- $D01F: foreground is a bit pattern -------------------------------------------------------------------

def test_hires_text_one_bits_are_foreground():
    # Row 5 (YSCROLL 3) starts on line 48+3+40 = 91; column 10 starts at X = 24+80 = 104.
    glyph = [0b00010000, 0, 0, 0, 0, 0, 0, 0]  # pixel k=3 of char row 0 -> (91, 107)
    memory = text_memory(glyph)
    assert latches(sprite(0, 107, 90, PIXEL), memory=memory).d01f == 1
    assert latches(sprite(0, 107, 90, PIXEL), memory=memory).first_d01f == (91, 107)
    assert latches(sprite(0, 106, 90, PIXEL), memory=memory).d01f == 0
    assert latches(sprite(0, 107, 91, PIXEL), memory=memory).d01f == 0  # line 92: glyph row 1 is empty


@pytest.mark.parametrize("pair, foreground", [(0b01, False), (0b10, True), (0b11, True)])
def test_multicolor_text_pairs_10_and_11_are_foreground(pair, foreground):
    # $D016 MCM; colour RAM bit 3 set -> multicolor char. Pair 0 = pixels k=0,1 = X 104, 105.
    memory = text_memory([pair << 6, 0, 0, 0, 0, 0, 0, 0], color=8 | 1)
    for x in (104, 105):
        r = latches(sprite(0, x, 90, PIXEL), registers={"$d016": 0xD8}, memory=memory)
        assert r.d01f == (1 if foreground else 0)


def test_multicolor_text_char_with_colour_bit3_clear_is_hires():
    # Byte %01000000 with colour 1 (bit 3 clear): hires, pixel k=1 (X 105) is foreground, k=0 is not.
    memory = text_memory([0b01000000, 0, 0, 0, 0, 0, 0, 0], color=1)
    assert latches(sprite(0, 105, 90, PIXEL), registers={"$d016": 0xD8}, memory=memory).d01f == 1
    assert latches(sprite(0, 104, 90, PIXEL), registers={"$d016": 0xD8}, memory=memory).d01f == 0


def test_multicolor_bitmap_01_is_background():
    bitmap = {"cells": [{"col": 10, "row": 5, "bytes": [0b01100000, 0, 0, 0, 0, 0, 0, 0]}]}
    regs = {"$d011": 0x3B, "$d016": 0xD8}  # BMM + MCM
    # pair 0 = 01 (X 104,105): background; pair 1 = 10 (X 106,107): foreground
    assert latches(sprite(0, 104, 90, PIXEL), registers=regs, memory={"bitmap": bitmap}).d01f == 0
    assert latches(sprite(0, 107, 90, PIXEL), registers=regs, memory={"bitmap": bitmap}).d01f == 1


def test_ecm_uses_the_shape_of_code_and_3f():
    # Code $41 = %01000001: ECM shows glyph 1 (on background colour 1). Glyph $41 is left blank.
    memory = text_memory([0xFF] * 8, code=1)
    memory["screen"]["cells"][0]["value"] = 0x41
    assert latches(sprite(0, 104, 90, PIXEL), registers={"$d011": 0x5B}, memory=memory).d01f == 1
    assert latches(sprite(0, 104, 90, PIXEL), registers={"$d011": 0x1B}, memory=memory).d01f == 0


def test_invalid_text_mode_collides_from_fetched_data():
    # ECM+MCM (invalid, drawn black): the fetch is as in ECM (code & $3F), multicolor by colour bit 3.
    memory = text_memory([0b10000000] + [0] * 7, code=1, color=8)
    memory["screen"]["cells"][0]["value"] = 0xC1
    assert latches(sprite(0, 105, 90, PIXEL), registers={"$d011": 0x5B, "$d016": 0xD8}, memory=memory).d01f == 1


def test_invalid_bitmap_mode_fetch_loses_address_bits_9_and_10():
    # Cell (row 2, col 24): VC = 104, offset 104*8 = $340. Without bits 9,10: $140 = cell 40 = (row 1, col 0).
    bitmap = {"cells": [{"col": 0, "row": 1, "bytes": [0xFF] * 8}]}
    line = 48 + 3 + 16  # row 2, char row 0
    x = 24 + 8 * 24  # column 24
    probe = sprite(0, x, line - 1, PIXEL)
    assert latches(probe, registers={"$d011": 0x7B}, memory={"bitmap": bitmap}).d01f == 1  # ECM+BMM
    assert latches(probe, registers={"$d011": 0x3B}, memory={"bitmap": bitmap}).d01f == 0  # BMM only
    assert latches(probe, registers={"$d011": 0x7B, "$d016": 0xD8}, memory={"bitmap": bitmap}).d01f == 1


def test_idle_state_byte_collides():
    # YSCROLL 7: the first bad line is 55, so lines 51-54 of the window are idle and show the idle byte.
    regs = {"$d011": 0x1F}
    probe = sprite(0, 100, 51, PIXEL)  # line 52, X 100 (column 9, k=4)
    assert latches(probe, registers=regs, memory={"idle": 0xFF}).d01f == 1
    assert latches(probe, registers=regs, memory={"idle": 0x00}).d01f == 0
    assert latches(probe, registers={"$d011": 0x5F}, memory={"idle": 0x08}).d01f == 1  # ECM too; k=4 is bit 3


def test_graphics_x_follows_xscroll():
    memory = text_memory([0b10000000] + [0] * 7)  # pixel k=0 of column 10
    for xscroll in range(8):
        regs = {"$d016": 0xC8 | xscroll}
        assert latches(sprite(0, 104 + xscroll, 90, PIXEL), registers=regs, memory=memory).d01f == 1
        assert latches(sprite(0, 103 + xscroll, 90, PIXEL), registers=regs, memory=memory).d01f == 0


def test_text_rows_start_at_48_plus_yscroll_plus_8r():
    memory = text_memory([0xFF] + [0] * 7)  # only char row 0 of row 5
    for yscroll in range(8):
        regs = {"$d011": 0x18 | yscroll}
        start = 48 + yscroll + 40
        assert latches(sprite(0, 104, start - 1, PIXEL), registers=regs, memory=memory).d01f == 1
        assert latches(sprite(0, 104, start - 2, PIXEL), registers=regs, memory=memory).d01f == 0


def test_vertical_border_suppresses_sprite_background():
    # Row 0 with YSCROLL 3 is lines 51-58. RSEL=0 moves the window top to line 55.
    memory = {"screen": {"fill": 1}, "charset": {"1": [0xFF] * 8}}
    probe = sprite(0, 100, 51, PIXEL)  # line 52
    assert latches(probe, registers={"$d011": 0x1B}, memory=memory).d01f == 1
    assert latches(probe, registers={"$d011": 0x13}, memory=memory).d01f == 0
    assert latches(sprite(0, 100, 54, PIXEL), registers={"$d011": 0x13}, memory=memory).d01f == 1  # line 55
    assert latches(sprite(0, 100, 100), registers={"$d011": 0x0B}, memory=memory).d01f == 0  # DEN=0


def test_side_border_does_not_suppress():
    # CSEL=0: the window starts at X 31, but column 0 is still drawn (under the border) from X 24.
    memory = {"screen": {"fill": 1}, "charset": {"1": [0xFF] * 8}}
    assert latches(sprite(0, 24, 100, PIXEL), registers={"$d016": 0xC0}, memory=memory).d01f == 1
    # XSCROLL 7 pushes column 39's pixel 7 to X = 24 + 312 + 7 + 7 = 350, right of the border at 343.
    assert latches(sprite(0, 350, 100, PIXEL), registers={"$d016": 0xC7 | 0x08}, memory=memory).d01f == 1
    assert latches(sprite(0, 351, 100, PIXEL), registers={"$d016": 0xCF}, memory=memory).d01f == 0


# ---- X and Y ranges ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("x", [0x1F8, 0x1FC, 0x1FF])
def test_pal_x_1f8_to_1ff_do_not_exist(x):
    # A full sprite there would cover X x..x+23; on the 6569 it never shows.
    assert latches(sprite(0, x, 100), sprite(1, x, 100)).d01e == 0
    assert latches(sprite(0, x, 100), sprite(1, x, 100), video="ntsc").d01e == 0b11


def test_pal_sprite_near_the_right_end_continues_at_x0():
    # X = $1F0 (496): pixels 0-7 at 496-503, pixel 8 at X 0 (the 6569's X runs to $1F7).
    a = sprite(0, 0x1F0, 100, rows_with([(0, 8)]))
    assert latches(a, sprite(1, 0, 100, PIXEL)).first_d01e == (101, 0)
    # NTSC has 512 positions: pixel 8 is at $1F8
    assert latches(a, sprite(1, 0x1F8, 100, PIXEL), video="ntsc").first_d01e == (101, 0x1F8)
    assert latches(a, sprite(1, 0, 100, PIXEL), video="ntsc").d01e == 0


def test_pal_small_y_shows_again_on_lines_256_and_up():
    # Y=10 matches lines 10 and 266 (266 & $FF = 10): rows on 11-31 and 267-287. Y=250: rows on 251-271.
    a, b = sprite(0, 100, 10), sprite(1, 100, 250)
    r = latches(a, b)
    assert r.d01e == 0b11 and r.first_d01e[0] == 267
    # NTSC has 263 lines: line 266 does not exist, so no second display and no collision.
    assert latches(a, b, video="ntsc").d01e == 0


def test_sprite_past_the_last_line_continues_at_the_top():
    # PAL Y=300 is impossible (8 bits), but Y=40 also matches line 296: rows 297-311 then 0-5.
    r = latches(sprite(0, 100, 40), sprite(1, 100, 40, rows_with([(20, 0)])))
    # sprite 1's row 20 shows on line 61 and (second display) on line 296+1+20-312 = 5
    assert r.first_d01e == (5, 100)


# VICE test program VICII/spritecollisions/sprite-sprite.tas (PAL; readme: C64 and C64C pass): sprites
# 6 and 7 with one pixel (row 0, column 0) at the same (X, Y); $D01E after a few frames is $C0
# everywhere except at X $1FF, which the 6569 does not have.
@pytest.mark.parametrize("x, y, expected", [
    (0, 0, 0xC0), (23, 50, 0xC0), (24, 50, 0xC0), (0, 50, 0xC0), (50, 50, 0xC0), (255, 50, 0xC0),
    (250, 250, 0xC0), (255, 100, 0xC0), (0x1FF, 50, 0), (0x157, 50, 0xC0)])
def test_vice_sprite_sprite_table(x, y, expected):
    assert latches(sprite(6, x, y, PIXEL), sprite(7, x, y, PIXEL)).d01e == expected
