"""The C64 text screen as the tile routines see it (VIC-II defaults after power-on).

Sources: C64 Programmer's Reference Guide (screen memory at $0400, 40 x 25 cells of 8 x 8 pixels);
the VIC-II sprite coordinate system puts the first visible pixel of the 320 x 200 display window at
sprite X 24, Y 50 (Programmer's Reference Guide, "Sprite positioning").
"""

from __future__ import annotations

from retro.chips.vic.constants import (
    CELL_WIDTH,
    GRAPHICS_FIRST_LINE,
    GRAPHICS_FIRST_X,
    SPRITE_BYTES_PER_ROW,
    TEXT_COLUMNS,
    TEXT_ROWS,
    X_BITS_MASK,
)

SCREEN_BASE = 0x0400  # screen memory after power-on (Programmer's Reference Guide)
COLUMNS = TEXT_COLUMNS
ROWS = TEXT_ROWS
CELL_PIXELS = CELL_WIDTH
POWER_ON_YSCROLL = 3  # $D011 = $1B after power-on
SPRITE_X_AT_COLUMN_0 = GRAPHICS_FIRST_X
# A sprite's first row is shown on line Y + 1, and text row 0 starts on line 48 + YSCROLL.
SPRITE_Y_AT_ROW_0 = GRAPHICS_FIRST_LINE + POWER_ON_YSCROLL - 1
SPRITE_X_LIMIT = X_BITS_MASK + 1  # 9-bit X: low byte plus the $D010 bit
SPRITE_ROW_BYTES = SPRITE_BYTES_PER_ROW


def cell_of(x: int, y: int) -> tuple[int, int] | None:
    """(column, row) of the screen cell under sprite-coordinate pixel (x, y), None off screen."""
    px, py = x - SPRITE_X_AT_COLUMN_0, y - SPRITE_Y_AT_ROW_0
    if 0 <= px < COLUMNS * CELL_PIXELS and 0 <= py < ROWS * CELL_PIXELS:
        return px // CELL_PIXELS, py // CELL_PIXELS
    return None


def row_address(row: int) -> int:
    return SCREEN_BASE + COLUMNS * row
