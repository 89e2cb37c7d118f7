"""The C64 text screen as the tile routines see it (VIC-II defaults after power-on).

Sources: C64 Programmer's Reference Guide (screen memory at $0400, 40 x 25 cells of 8 x 8 pixels);
the VIC-II sprite coordinate system puts the first visible pixel of the 320 x 200 display window at
sprite X 24, Y 50 (Programmer's Reference Guide, "Sprite positioning").
"""

from __future__ import annotations

SCREEN_BASE = 0x0400
COLUMNS = 40
ROWS = 25
CELL_PIXELS = 8
SPRITE_X_AT_COLUMN_0 = 24
SPRITE_Y_AT_ROW_0 = 50
SPRITE_X_LIMIT = 512  # 9-bit X: low byte plus the $D010 bit

# Sprite masks (C64 layout): 24 x 21 pixels, 3 bytes a row, bit 7 of a row's first byte leftmost.
SPRITE_WIDTH = 24
SPRITE_HEIGHT = 21
SPRITE_ROW_BYTES = 3


def cell_of(x: int, y: int) -> tuple[int, int] | None:
    """(column, row) of the screen cell under sprite-coordinate pixel (x, y), None off screen."""
    px, py = x - SPRITE_X_AT_COLUMN_0, y - SPRITE_Y_AT_ROW_0
    if 0 <= px < COLUMNS * CELL_PIXELS and 0 <= py < ROWS * CELL_PIXELS:
        return px // CELL_PIXELS, py // CELL_PIXELS
    return None


def row_address(row: int) -> int:
    return SCREEN_BASE + COLUMNS * row
