"""Integer references for the 6502 collision routines in asm/, written from each test's definition.

One pure function per routine with the routine's inputs and outputs (issue 5). They know nothing
of how the assembly computes its answer: boxes are pixel sets, circles compare squared distances,
the product is a product. Every function accepts plain ints or numpy integer arrays of one shape
(a batch), and returns a bool / int or an array of them.

Edge convention (as the rest of retro.geometry): half-open boxes, a box at x with width w covers
pixels x .. x+w-1, so boxes that touch do not overlap and a box of width 0 covers nothing;
circles whose distance equals r1 + r2 do not overlap.
"""

from __future__ import annotations

import numpy as np

from retro.chips.vic.constants import SPRITE_HEIGHT
from retro.chips.vic.screen import (
    CELL_PIXELS,
    COLUMNS,
    ROWS,
    SPRITE_X_AT_COLUMN_0,
    SPRITE_Y_AT_ROW_0,
)

HIGH_BIT_WEIGHT = 256  # the $D010 bit is bit 8 of a sprite's X


def _intervals_share_a_pixel(a_start, a_size, b_start, b_size):
    a_start, a_size, b_start, b_size = (np.asarray(v, dtype=np.int64) for v in (a_start, a_size, b_start, b_size))
    return np.maximum(a_start, b_start) < np.minimum(a_start + a_size, b_start + b_size)


def _result(value):
    if isinstance(value, np.generic) or isinstance(value, np.ndarray) and value.ndim == 0:
        return value.item()
    return value


def aabb8(ax, ay, aw, ah, bx, by, bw, bh):
    """Boxes (ax, ay, aw, ah) and (bx, by, bw, bh) share at least one pixel."""
    return _result(_intervals_share_a_pixel(ax, aw, bx, bw) & _intervals_share_a_pixel(ay, ah, by, bh))


def aabb_sprite(x1, x1h, y1, ox1, oy1, w1, h1, x2, x2h, y2, ox2, oy2, w2, h2):
    """Sprite hitboxes overlap: sprite n at X = xn + 256 * xnh, Y = yn, hitbox (oxn, oyn, wn, hn) inside it."""
    left1 = np.asarray(x1, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(x1h, dtype=np.int64) + ox1
    left2 = np.asarray(x2, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(x2h, dtype=np.int64) + ox2
    top1 = np.asarray(y1, dtype=np.int64) + oy1
    top2 = np.asarray(y2, dtype=np.int64) + oy2
    return _result(_intervals_share_a_pixel(left1, w1, left2, w2) & _intervals_share_a_pixel(top1, h1, top2, h2))


def circle(x1, y1, r1, x2, y2, r2):
    """Circles overlap: squared distance of the centres below (r1 + r2)^2 (tangent circles do not)."""
    x1, y1, r1, x2, y2, r2 = (np.asarray(v, dtype=np.int64) for v in (x1, y1, r1, x2, y2, r2))
    return _result((x1 - x2) ** 2 + (y1 - y2) ** 2 < (r1 + r2) ** 2)


def mul8(a, b):
    """The 16-bit product of two bytes."""
    return _result(np.asarray(a, dtype=np.int64) * np.asarray(b, dtype=np.int64))


def mul16(a, b):
    """The 32-bit product of two 16-bit words."""
    return _result(np.asarray(a, dtype=np.int64) * np.asarray(b, dtype=np.int64))


def cell_under(x, xh, y):
    """(column, row, on_screen) of the text-screen cell under sprite-coordinate pixel (x + 256 xh, y)."""
    px = np.asarray(x, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(xh, dtype=np.int64) - SPRITE_X_AT_COLUMN_0
    py = np.asarray(y, dtype=np.int64) - SPRITE_Y_AT_ROW_0
    on = (px >= 0) & (px < COLUMNS * CELL_PIXELS) & (py >= 0) & (py < ROWS * CELL_PIXELS)
    return px // CELL_PIXELS, py // CELL_PIXELS, on


def tile(x, xh, y, screen, props):
    """Property byte of the cell under the point: props[screen code], 0 off the screen.

    screen: COLUMNS * ROWS screen codes, row by row; props: 256 property bytes.
    """
    screen = np.asarray(screen, dtype=np.int64)
    props = np.asarray(props, dtype=np.int64)
    column, row, on = cell_under(x, xh, y)
    index = np.where(on, row * COLUMNS + column, 0)
    return _result(np.where(on, props[screen[index]], 0))


def _cell_span(start, size, origin: int, cells: int):
    """First and last cell (inclusive, clipped to 0..cells-1) that the pixels start..start+size-1 touch,
    and whether there is any."""
    start = np.asarray(start, dtype=np.int64)
    size = np.asarray(size, dtype=np.int64)
    first = (start - origin) // CELL_PIXELS
    last = (start + size - 1 - origin) // CELL_PIXELS
    any_cell = (size >= 1) & (last >= 0) & (first < cells)
    return np.clip(first, 0, cells - 1), np.clip(last, 0, cells - 1), any_cell


def tile_box(x, xh, y, w, h, screen, props):
    """OR of the property bytes of every on-screen cell that shares a pixel with the box.

    Over arrays: per property bit, a table of running counts over the screen's cells tells whether
    any cell of the box's rectangle of cells has that bit."""
    left = np.asarray(x, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(xh, dtype=np.int64)
    grid = np.asarray(props, dtype=np.int64)[np.asarray(screen, dtype=np.int64)].reshape(ROWS, COLUMNS)
    c0, c1, any_column = _cell_span(left, w, SPRITE_X_AT_COLUMN_0, COLUMNS)
    r0, r1, any_row = _cell_span(y, h, SPRITE_Y_AT_ROW_0, ROWS)
    result = np.zeros(np.broadcast(left, c0, r0).shape, dtype=np.int64)
    for bit in range(8):
        counts = np.zeros((ROWS + 1, COLUMNS + 1), dtype=np.int64)
        counts[1:, 1:] = ((grid >> bit) & 1).cumsum(axis=0).cumsum(axis=1)
        inside = counts[r1 + 1, c1 + 1] - counts[r0, c1 + 1] - counts[r1 + 1, c0] + counts[r0, c0]
        result |= (inside > 0).astype(np.int64) << bit
    return _result(np.where(any_column & any_row, result, 0))


def mask_bits(rows: bytes | list[int]) -> np.ndarray:
    """A C64 sprite mask (3 bytes a row, bit 7 leftmost) as a SPRITE_HEIGHT x SPRITE_WIDTH bool array."""
    data = np.frombuffer(bytes(rows), dtype=np.uint8)[:SPRITE_HEIGHT * 3].reshape(SPRITE_HEIGHT, 3)
    return np.unpackbits(data, axis=1).astype(bool)


def pixel(dx: int, dy: int, mask_a, mask_b) -> bool:
    """Some pixel is set in both masks when mask B's top-left is at (dx, dy) relative to mask A's."""
    a = np.asarray(mask_a, dtype=bool)
    b = np.asarray(mask_b, dtype=bool)
    height, width = a.shape
    canvas = np.zeros((height + 2 * b.shape[0], width + 2 * b.shape[1]), dtype=bool)
    oy, ox = b.shape
    if not (-oy < dy < height and -ox < dx < width):
        return False
    canvas[oy + dy:oy + dy + b.shape[0], ox + dx:ox + dx + b.shape[1]] = b
    return bool((canvas[oy:oy + height, ox:ox + width] & a).any())


# ---- routines in the conventions games use: edges prepared once per object ------------------------

def aabb_edges(a_left, a_top, a_right1, a_bottom1, b_left, b_right, b_top, b_bottom):
    """Box A's columns a_left..a_right1 and rows a_top..a_bottom1 (inclusive) share a pixel with box B's
    columns b_left..b_right-1 and rows b_top..b_bottom-1."""
    return _result(_intervals_share_a_pixel(a_left, np.asarray(a_right1, dtype=np.int64) - a_left + 1, b_left,
                                            np.asarray(b_right, dtype=np.int64) - b_left)
                   & _intervals_share_a_pixel(a_top, np.asarray(a_bottom1, dtype=np.int64) - a_top + 1, b_top,
                                              np.asarray(b_bottom, dtype=np.int64) - b_top))


def box_edges(px, py, pw, ph) -> dict:
    """The six edges aabb_edges_prepare makes of a box at (px, py) of size pw x ph."""
    return {"left": px, "top": py, "right1": px + pw - 1, "right": px + pw, "bottom1": py + ph - 1,
            "bottom": py + ph}


def circle_r(x1, y1, radius_sum, x2, y2):
    """Circles with centres (x1, y1), (x2, y2) and radii summing to radius_sum overlap (tangent: no)."""
    x1, y1, radius_sum, x2, y2 = (np.asarray(v, dtype=np.int64) for v in (x1, y1, radius_sum, x2, y2))
    return _result((x1 - x2) ** 2 + (y1 - y2) ** 2 < radius_sum ** 2)


def radius_sum(r1, r2):
    return r1 + r2


def sprite_edges(a_left, a_top, a_bottom1, a_left_hi, a_right, a_right_hi, b_left, b_left_hi, b_right,
                 b_right_hi, b_top, b_bottom):
    """Hitbox A (columns a_left + 256 a_left_hi .. a_right + 256 a_right_hi - 1, rows a_top..a_bottom1)
    shares a pixel with hitbox B (columns b_left.. b_right - 1, rows b_top .. b_bottom - 1)."""
    a0 = np.asarray(a_left, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(a_left_hi, dtype=np.int64)
    a1 = np.asarray(a_right, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(a_right_hi, dtype=np.int64)
    b0 = np.asarray(b_left, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(b_left_hi, dtype=np.int64)
    b1 = np.asarray(b_right, dtype=np.int64) + HIGH_BIT_WEIGHT * np.asarray(b_right_hi, dtype=np.int64)
    return _result(_intervals_share_a_pixel(a0, a1 - a0, b0, b1 - b0)
                   & _intervals_share_a_pixel(a_top, np.asarray(a_bottom1, dtype=np.int64) - a_top + 1, b_top,
                                              np.asarray(b_bottom, dtype=np.int64) - b_top))


def sprite_hitbox_edges(sx, sxh, sy, ox, oy, w, h) -> dict:
    """The edges sprite_edges_prepare makes: left and right (exclusive) as 16-bit, top, bottom, bottom - 1."""
    left = sx + HIGH_BIT_WEIGHT * sxh + ox
    top = sy + oy
    return {"left": left & 0xFF, "left_hi": left >> 8, "right": (left + w) & 0xFF, "right_hi": (left + w) >> 8,
            "top": top, "bottom": top + h, "bottom1": top + h - 1}
