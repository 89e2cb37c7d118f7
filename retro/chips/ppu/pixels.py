"""2-bit pattern values of the background and of sprite 0 at screen pixels (numpy, vectorised).

Only pattern values (0 = transparent, 1-3 = opaque) matter for the sprite-zero hit; palettes,
greyscale and emphasis never do (nesdev wiki "PPU OAM", sprite zero hits).

Background (nesdev wiki "PPU scrolling", "PPU rendering"): the displayed pixel at screen (line, x)
comes from the 512x480 arrangement of the four logical nametables, starting at the base nametable
($2000 bits 0-1) offset by the $2005 scroll. Horizontally, coarse X wraps from 31 to 0 and toggles
the horizontal nametable. Vertically, coarse Y wraps from 29 to 0 and toggles the vertical
nametable, but a scroll of 240-255 (coarse Y 30 or 31, the attribute rows) runs on to 31 and wraps
to 0 without toggling. Pattern table from $2000 bit 4.

Sprite 0 (nesdev wiki "PPU OAM"): drawn on lines Y+1 .. Y+8 (Y+16 in 8x16 mode); flips are
applied first; 8x8 sprites take the pattern table from $2000 bit 3; 8x16 sprites take it from
tile bit 0, the top tile is `index & $FE`, the bottom one the next tile, and a vertical flip
swaps the halves (it flips the whole 16-line sprite).
"""

from __future__ import annotations

import numpy as np

from retro.chips.ppu.constants import (
    ATTR_FLIP_H,
    ATTR_FLIP_V,
    COARSE_SHIFT,
    CTRL_BACKGROUND_TABLE,
    CTRL_NAMETABLE,
    CTRL_SPRITE_8X16,
    CTRL_SPRITE_TABLE,
    NAMETABLE_COLUMNS,
    NAMETABLE_ROW_SLOTS,
    NAMETABLE_ROWS,
    PATTERN_TABLE_SIZE,
    PLANE_OFFSET,
    SCREEN_HEIGHT,
    SCREEN_WIDTH,
    SPRITE_WIDTH,
    SPRITE_Y_OFFSET,
    TALL_SPRITE_TILE_MASK,
    TILE_BYTES,
    TILE_SIZE,
)
from retro.chips.ppu.state import PpuState

NAMETABLE_HEIGHT_PIXELS = NAMETABLE_ROWS * TILE_SIZE          # 240: coarse Y 29 -> 0 toggles the nametable
ROW_SLOT_PIXELS = NAMETABLE_ROW_SLOTS * TILE_SIZE             # 256: coarse Y 31 -> 0 does not
NAMETABLE_WIDTH_PIXELS = NAMETABLE_COLUMNS * TILE_SIZE        # 256


def pattern_values(chr_data: np.ndarray, table: np.ndarray | int, tile: np.ndarray | int,
                   row: np.ndarray | int, column: np.ndarray | int) -> np.ndarray:
    """2-bit pixel values of tiles: plane 0 gives bit 0, plane 1 (8 bytes on) bit 1; column 0 is bit 7."""
    address = np.asarray(table) * PATTERN_TABLE_SIZE + np.asarray(tile) * TILE_BYTES + np.asarray(row)
    shift = (TILE_SIZE - 1) - np.asarray(column)
    low = (chr_data[address] >> shift) & 1
    high = (chr_data[address + PLANE_OFFSET] >> shift) & 1
    return (low | (high << 1)).astype(np.uint8)


def vertical_positions(scroll_y: int, base_y: int, lines: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For screen lines: (vertical nametable bit, pixel row 0-255 inside that nametable)."""
    lines = np.asarray(lines)
    if scroll_y < NAMETABLE_HEIGHT_PIXELS:
        position = scroll_y + lines
        return base_y ^ ((position // NAMETABLE_HEIGHT_PIXELS) & 1), position % NAMETABLE_HEIGHT_PIXELS
    # Coarse Y 30/31: the attribute rows are fetched as tiles until coarse Y wraps 31 -> 0, no toggle.
    before_wrap = ROW_SLOT_PIXELS - scroll_y
    after = lines - before_wrap
    row = np.where(lines < before_wrap, scroll_y + lines, after % NAMETABLE_HEIGHT_PIXELS)
    toggles = np.where(lines < before_wrap, 0, (after // NAMETABLE_HEIGHT_PIXELS) & 1)
    return base_y ^ toggles, row


def background_values(state: PpuState, lines: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """Background pattern values at screen pixels (lines and xs broadcast together)."""
    lines, xs = np.broadcast_arrays(np.asarray(lines), np.asarray(xs))
    base = state.ctrl & CTRL_NAMETABLE
    nt_y, row = vertical_positions(state.scroll_y, base >> 1, lines)
    column = (base & 1) * NAMETABLE_WIDTH_PIXELS + state.scroll_x + xs
    nt_x = (column // NAMETABLE_WIDTH_PIXELS) & 1
    column = column % NAMETABLE_WIDTH_PIXELS
    cell = (row >> COARSE_SHIFT) * NAMETABLE_COLUMNS + (column >> COARSE_SHIFT)
    tiles = state.nametables()[nt_y * 2 + nt_x, cell]
    table = 1 if state.ctrl & CTRL_BACKGROUND_TABLE else 0
    return pattern_values(state.chr_array(), table, tiles, row % TILE_SIZE, column % TILE_SIZE)


def background_frame(state: PpuState) -> np.ndarray:
    """(240, 256) background pattern values of the whole visible frame."""
    return background_values(state, np.arange(SCREEN_HEIGHT)[:, None], np.arange(SCREEN_WIDTH)[None, :])


def sprite_height(ctrl: int) -> int:
    return 2 * TILE_SIZE if ctrl & CTRL_SPRITE_8X16 else TILE_SIZE


def sprite_values(state: PpuState, entry: int = 0) -> tuple[int, int, np.ndarray]:
    """(first screen line, left x, (height, 8) pattern values as displayed, flips applied) of an OAM entry."""
    y, tile, attr, x = state.oam[entry * 4: entry * 4 + 4]
    height = sprite_height(state.ctrl)
    rows = np.arange(height)[:, None]
    columns = np.arange(SPRITE_WIDTH)[None, :]
    source_rows = (height - 1 - rows) if attr & ATTR_FLIP_V else rows
    source_columns = (SPRITE_WIDTH - 1 - columns) if attr & ATTR_FLIP_H else columns
    if height == TILE_SIZE:
        table = 1 if state.ctrl & CTRL_SPRITE_TABLE else 0
        tiles = np.full_like(source_rows, tile)
    else:
        table = tile & 1
        tiles = (tile & TALL_SPRITE_TILE_MASK) + source_rows // TILE_SIZE
    values = pattern_values(state.chr_array(), table, tiles, source_rows % TILE_SIZE, source_columns)
    return y + SPRITE_Y_OFFSET, x, values
