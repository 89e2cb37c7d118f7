"""The sprite-zero hit model, rule by rule. Every expected value is worked out by hand from the
rule it tests (nesdev wiki "PPU OAM", "PPU scrolling", "PPU frame timing"; blargg's
sprite_hit_tests readme), in the comment next to it."""

from __future__ import annotations

import pytest
from nes_build import SOLID, make_state, one_pixel

from retro.chips.ppu.constants import PAL
from retro.chips.ppu.hit import sprite_zero_hit

BG_TILE_AT_120_128 = {(0, 15, 16): 1}     # nametable 0, row 15 (lines 120-127), column 16 (x 128-135)


def hit_at(state):
    result = sprite_zero_hit(state)
    return (result.x, result.line) if result.hit else None


def test_basic_hit_pixel_dot_and_dots_after_vblank():
    result = sprite_zero_hit(make_state(cells=BG_TILE_AT_120_128, sprite=(119, 1, 0, 128)))
    # Y = 119 -> first line 120; both solid from x = 128: pixel (128, 120); flag at dot 128 + 1.
    # From line 241 dot 1 to line 262 (= next frame's line 0) dot 1 is 21 lines; then 120 lines and
    # 128 more dots: 141 * 341 + 128 = 48081 + 128 = 48209.
    assert (result.hit, result.x, result.line, result.dot, result.dots_after_vblank) == (True, 128, 120, 129, 48209)


def test_pal_counts_312_lines():
    result = sprite_zero_hit(make_state(cells=BG_TILE_AT_120_128, video=PAL))
    # (312 - 241 + 120) * 341 + 128 = 191 * 341 + 128 = 65131 + 128
    assert result.dots_after_vblank == 65259
    assert result.cpu_cycles_after_vblank == 65259 * 5 / 16  # PAL: 3.2 dots a CPU cycle -> 20393.4375


def test_sprite_is_drawn_from_y_plus_one():
    # Background only on lines 112-119 (row 14): a sprite at Y = 111 covers 112-119 and hits at 112;
    # one at Y = 119 starts at line 120 and misses it.
    cells = {(0, 14, 16): 1}
    assert hit_at(make_state(cells=cells, sprite=(111, 1, 0, 128))) == (128, 112)
    assert hit_at(make_state(cells=cells, sprite=(119, 1, 0, 128))) is None
    # Y = 0 starts at line 1, so line 0 never hits even with background everywhere.
    assert hit_at(make_state(fill_page={0: 1}, sprite=(0, 1, 0, 40))) == (40, 1)


def test_palette_priority_greyscale_and_emphasis_do_not_matter():
    base = hit_at(make_state(cells=BG_TILE_AT_120_128))
    assert hit_at(make_state(cells=BG_TILE_AT_120_128, sprite=(119, 1, 0x23, 128))) == base   # behind bg, palette 3
    assert hit_at(make_state(cells=BG_TILE_AT_120_128, mask=0xFF)) == base                    # greyscale + emphasis


def test_only_sprite_zero_counts():
    # Sprite 0 below the screen, sprite 1 right on the background tile: no hit.
    state = make_state(cells=BG_TILE_AT_120_128, sprite=(240, 1, 0, 128), others=[(119, 1, 0, 128)])
    assert hit_at(state) is None


@pytest.mark.parametrize("value", [1, 2, 3])
def test_any_nonzero_pattern_value_is_opaque(value):
    # Only pixel (row 3, col 5) of the sprite is opaque: screen (128 + 5, 120 + 3).
    tiles = {(0, 1): SOLID, (0, 2): one_pixel(3, 5, value)}
    assert hit_at(make_state(tiles=tiles, cells=BG_TILE_AT_120_128, sprite=(119, 2, 0, 128))) == (133, 123)


def test_transparent_background_pixels_do_not_hit():
    # Background tile with only pixel (row 6, col 2) opaque, solid sprite over it: hit there only.
    tiles = {(0, 1): SOLID, (0, 3): one_pixel(6, 2)}
    assert hit_at(make_state(tiles=tiles, cells={(0, 15, 16): 3}, sprite=(119, 1, 0, 128))) == (130, 126)


def test_flips_are_applied_first():
    tiles = {(0, 1): SOLID, (0, 2): one_pixel(3, 5)}
    cells = BG_TILE_AT_120_128
    # Horizontal flip: column 5 -> 7 - 5 = 2. Vertical: row 3 -> 7 - 3 = 4. Both: (2, 4).
    assert hit_at(make_state(tiles=tiles, cells=cells, sprite=(119, 2, 0x40, 128))) == (130, 123)
    assert hit_at(make_state(tiles=tiles, cells=cells, sprite=(119, 2, 0x80, 128))) == (133, 124)
    assert hit_at(make_state(tiles=tiles, cells=cells, sprite=(119, 2, 0xC0, 128))) == (130, 124)


def test_8x16_table_from_tile_bit_0_top_tile_even_and_flip_swaps_halves():
    bg = {(0, 1): SOLID}
    # Tile number 3 in 8x16 mode: pattern table 1 (bit 0), top tile 2, bottom tile 3. Table 0 holds
    # decoys at tiles 2 and 3 that must not be used.
    tiles = {**bg, (0, 2): SOLID, (0, 3): SOLID, (1, 2): one_pixel(0, 7), (1, 3): one_pixel(2, 0)}
    full_bg = {0: 1}
    # Top tile row 0 col 7 -> line 120, x 135.
    assert hit_at(make_state(tiles=tiles, fill_page=full_bg, ctrl=0x20, sprite=(119, 3, 0, 128))) == (135, 120)
    # Without the top-tile pixel, the bottom tile's row 2 col 0 -> sprite row 10 -> line 130, x 128.
    tiles_bottom = {**tiles, (1, 2): ["00000000"] * 8}
    assert hit_at(make_state(tiles=tiles_bottom, fill_page=full_bg, ctrl=0x20, sprite=(119, 3, 0, 128))) == (128, 130)
    # Vertical flip over 16 lines: sprite row 10 -> 15 - 10 = 5 -> line 125.
    assert hit_at(make_state(tiles=tiles_bottom, fill_page=full_bg, ctrl=0x20, sprite=(119, 3, 0x80, 128))) == (128, 125)
    # The 8x16 sprite reaches 16 lines down: background only on lines 128-135 (row 16) still hits at 128
    # for a solid 8x16 sprite at Y = 119 (lines 120-135).
    solid16 = {(0, 1): SOLID, (0, 4): SOLID, (0, 5): SOLID}
    assert hit_at(make_state(tiles=solid16, cells={(0, 16, 16): 1}, ctrl=0x20, sprite=(119, 4, 0, 128))) == (128, 128)
    # ... and an 8x8 sprite at the same place (lines 120-127) does not.
    assert hit_at(make_state(tiles=solid16, cells={(0, 16, 16): 1}, ctrl=0x00, sprite=(119, 4, 0, 128))) is None


def test_pattern_tables_from_ctrl_bits_3_and_4():
    # Sprite tile 2 is solid only in table 1: needs $2000 bit 3. Background tile 1 solid in table 0 only.
    tiles = {(0, 1): SOLID, (1, 2): SOLID}
    assert hit_at(make_state(tiles=tiles, cells=BG_TILE_AT_120_128, sprite=(119, 2, 0, 128), ctrl=0x00)) is None
    assert hit_at(make_state(tiles=tiles, cells=BG_TILE_AT_120_128, sprite=(119, 2, 0, 128), ctrl=0x08)) == (128, 120)
    # Background tile 5 solid only in table 1: needs $2000 bit 4.
    tiles = {(0, 1): SOLID, (1, 5): SOLID}
    cells = {(0, 15, 16): 5}
    assert hit_at(make_state(tiles=tiles, cells=cells, ctrl=0x00)) is None
    assert hit_at(make_state(tiles=tiles, cells=cells, ctrl=0x10)) == (128, 120)


@pytest.mark.parametrize("mask", [0x16, 0x0E, 0x06, 0x00])
def test_no_hit_with_background_or_sprites_off(mask):
    assert sprite_zero_hit(make_state(cells=BG_TILE_AT_120_128, mask=mask)).hit is False


@pytest.mark.parametrize("mask", [0x1E, 0x1C, 0x1A, 0x18])
def test_left_column_needs_both_bits(mask):
    # Background solid everywhere. A sprite at X = 4 covers x 4-11: its first pixel (4) hits when
    # both left-column bits ($2001 bits 1, 2) are set, else the first is x 8.
    both = mask & 0x06 == 0x06
    assert hit_at(make_state(fill_page={0: 1}, sprite=(119, 1, 0, 4), mask=mask)) == ((4, 120) if both else (8, 120))
    # A sprite at X = 0 covers only x 0-7: it hits at x 0 or not at all.
    assert hit_at(make_state(fill_page={0: 1}, sprite=(119, 1, 0, 0), mask=mask)) == ((0, 120) if both else None)


def test_x_255_never_hits():
    # Sprite with only its column 7 opaque: at X = 248 it is x 255 (no hit), at X = 247 it is x 254.
    tiles = {(0, 1): SOLID, (0, 2): ["00000003"] * 8}
    assert hit_at(make_state(tiles=tiles, fill_page={0: 1, 1: 1}, sprite=(119, 2, 0, 248))) is None
    assert hit_at(make_state(tiles=tiles, fill_page={0: 1, 1: 1}, sprite=(119, 2, 0, 247))) == (254, 120)


def test_lines_from_240_never_hit():
    full = {0: 1, 1: 1}
    assert hit_at(make_state(fill_page=full, sprite=(238, 1, 0, 50))) == (50, 239)   # lines 239-246
    assert hit_at(make_state(fill_page=full, sprite=(239, 1, 0, 50))) is None        # lines 240-247
    assert hit_at(make_state(fill_page=full, sprite=(255, 1, 0, 50))) is None


def test_first_pixel_in_raster_order_wins():
    # Opaque sprite pixels at (row 0, col 7) and (row 1, col 0): row 0 comes first on screen.
    rows = ["00000003", "30000000"] + ["00000000"] * 6
    tiles = {(0, 1): SOLID, (0, 2): rows}
    assert hit_at(make_state(tiles=tiles, fill_page={0: 1}, sprite=(119, 2, 0, 100))) == (107, 120)


def test_fine_and_coarse_horizontal_scroll():
    # scroll_x = 4: nametable x 128-135 shows at screen x 124-131; a sprite at x 120-127 hits at 124.
    assert hit_at(make_state(cells=BG_TILE_AT_120_128, scroll_x=4, sprite=(119, 1, 0, 120))) == (124, 120)
    # scroll_x = 200: screen x 56 shows x 0 of the next horizontal nametable (vertical mirroring:
    # CIRAM page 1). A tile at page 1 col 0 row 15 -> screen x 56-63.
    assert hit_at(make_state(cells={(1, 15, 0): 1}, scroll_x=200, sprite=(119, 1, 0, 52))) == (56, 120)
    # The same tile in page 0 is at nametable x 0-7, scrolled off to the left: no hit at 52-59.
    assert hit_at(make_state(cells={(0, 15, 0): 1}, scroll_x=200, sprite=(119, 1, 0, 52))) is None
    # Horizontal mirroring: the next horizontal nametable is page 0 again, so page 0 col 0 shows at 56.
    assert hit_at(make_state(cells={(0, 15, 0): 1}, scroll_x=200, sprite=(119, 1, 0, 52),
                             mirroring="horizontal")) == (56, 120)


def test_base_nametable_from_ctrl():
    # $2000 bits 0-1 = 1: the screen shows nametable 1 (page 1 with vertical mirroring).
    cells = {(1, 15, 16): 1}
    assert hit_at(make_state(cells=cells, ctrl=0x00)) is None
    assert hit_at(make_state(cells=cells, ctrl=0x01)) == (128, 120)
    # Nametable 2 under vertical mirroring is page 0 again.
    assert hit_at(make_state(cells=BG_TILE_AT_120_128, ctrl=0x02)) == (128, 120)


def test_vertical_scroll_and_wrap():
    # scroll_y = 8: nametable row 15 (y 120-127) shows on screen lines 112-119.
    assert hit_at(make_state(cells=BG_TILE_AT_120_128, scroll_y=8, sprite=(111, 1, 0, 128))) == (128, 112)
    # scroll_y = 16: screen line 224 shows y 240 = row 0 of the next vertical nametable (horizontal
    # mirroring: page 1).
    cells = {(1, 0, 16): 1}
    assert hit_at(make_state(cells=cells, scroll_y=16, mirroring="horizontal", sprite=(223, 1, 0, 128))) == (128, 224)
    # With vertical mirroring the next vertical nametable is page 0, whose row 0 then shows there.
    assert hit_at(make_state(cells={(0, 0, 16): 1}, scroll_y=16, sprite=(223, 1, 0, 128))) == (128, 224)


def test_scroll_y_240_and_up_reads_attribute_rows_then_wraps_without_toggle():
    # scroll_y = 248: coarse Y 31. Lines 0-7 show row 31 (attribute bytes $3E0-$3FF of the same
    # nametable); line 8 wraps to row 0 of the SAME nametable.
    state = make_state(cells={(0, 0, 16): 1}, scroll_y=248, sprite=(7, 1, 0, 128), mirroring="horizontal")
    assert hit_at(state) == (128, 8)
    attribute_as_tile = make_state(cells={(0, 31, 16): 1}, scroll_y=248, sprite=(0, 1, 0, 128), mirroring="horizontal")
    assert hit_at(attribute_as_tile) == (128, 1)
    # The other vertical nametable (page 1) must not appear at line 8.
    assert hit_at(make_state(cells={(1, 0, 16): 1}, scroll_y=248, sprite=(7, 1, 0, 128), mirroring="horizontal")) is None
