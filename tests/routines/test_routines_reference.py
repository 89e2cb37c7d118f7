"""The references against hand-worked cases from each test's definition (not from the code)."""

from __future__ import annotations

import numpy as np

from retro.routines import reference
from retro.chips.vic.screen import SCREEN_BASE, cell_of, row_address


def test_aabb8_touching_boxes_do_not_overlap():
    # a covers x 10..17; b starting at 18 touches it, at 17 shares one column.
    assert reference.aabb8(10, 0, 8, 8, 18, 0, 8, 8) is False
    assert reference.aabb8(10, 0, 8, 8, 17, 0, 8, 8) is True
    assert reference.aabb8(10, 0, 8, 8, 17, 8, 8, 8) is False  # shares a column but not a row
    assert reference.aabb8(10, 0, 0, 8, 10, 0, 8, 8) is False  # zero width covers nothing


def test_aabb8_is_plain_integer_arithmetic_past_255():
    # a covers 250..259 (past the byte), b at 255 width 1: they share pixel 255.
    assert reference.aabb8(250, 0, 10, 1, 255, 0, 1, 1) is True
    assert reference.aabb8(250, 0, 10, 1, 3, 0, 1, 1) is False  # no wrap-around


def test_aabb8_batches():
    result = reference.aabb8(np.array([10, 10]), 0, 8, 8, np.array([17, 18]), 0, 8, 8)
    assert result.tolist() == [True, False]


def test_aabb_sprite_across_the_256_boundary():
    # sprite 1 at X 250 with a 10-wide box at offset 2 covers 252..261; sprite 2 at X 256+5 = 261.
    assert reference.aabb_sprite(250, 0, 100, 2, 0, 10, 5, 5, 1, 100, 0, 0, 4, 5) is True
    assert reference.aabb_sprite(250, 0, 100, 2, 0, 10, 5, 6, 1, 100, 0, 0, 4, 5) is False  # 262: touching


def test_circle_three_four_five():
    assert reference.circle(0, 0, 2, 3, 4, 3) is False  # distance 5 == 2 + 3: tangent
    assert reference.circle(0, 0, 3, 3, 4, 3) is True
    assert reference.circle(255, 255, 200, 0, 0, 55) is False  # 2 * 255^2 = 130050 needs 17 bits


def test_mul8_products():
    assert reference.mul8(255, 255) == 65025
    assert reference.mul8(0, 200) == 0
    assert reference.mul8(np.arange(3), 7).tolist() == [0, 7, 14]


def test_mul16_products_need_32_bits():
    assert reference.mul16(0xFFFF, 0xFFFF) == 0xFFFE0001
    assert reference.mul16(0x100, 0x100) == 0x10000
    assert reference.mul16(0, 0xFFFF) == 0
    assert reference.mul16(np.array([0x8000, 3]), np.array([2, 0x5555])).tolist() == [0x10000, 0xFFFF]


def test_screen_cells_and_edges():
    assert cell_of(24, 50) == (0, 0)
    assert cell_of(23, 50) is None and cell_of(24, 49) is None
    assert cell_of(343, 249) == (39, 24)
    assert cell_of(344, 100) is None and cell_of(100, 250) is None
    assert row_address(1) == SCREEN_BASE + 40


def test_tile_and_tile_box_read_the_property_of_the_screen_code():
    screen = [0] * 1000
    screen[40 * 2 + 3] = 7  # row 2, column 3: sprite X 48..55, Y 66..73
    props = [0] * 256
    props[7] = 0b101
    assert reference.tile(48, 0, 66, screen, props) == 0b101
    assert reference.tile(47, 0, 66, screen, props) == 0
    assert reference.tile_box(40, 0, 60, 8, 6, screen, props) == 0  # x 40..47: one column short
    assert reference.tile_box(40, 0, 60, 9, 7, screen, props) == 0b101
    assert reference.tile_box(40, 0, 60, 0, 7, screen, props) == 0  # zero width touches nothing


def test_pixel_masks_meet_only_where_both_are_set():
    a = np.zeros((21, 24), dtype=bool)
    b = np.zeros((21, 24), dtype=bool)
    a[5, 10] = True
    b[0, 0] = True
    assert reference.pixel(10, 5, a, b) is True
    assert reference.pixel(11, 5, a, b) is False
    assert reference.pixel(-30, 0, a, b) is False
    row = [0x80, 0, 0] + [0] * 60
    assert reference.mask_bits(row)[0, 0] and not reference.mask_bits(row)[0, 1]
