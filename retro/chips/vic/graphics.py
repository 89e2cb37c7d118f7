"""The text/bitmap side of the VIC-II: which pixels are foreground (for $D01F) and their colours.

Foreground is a matter of bit patterns, not colours [Bauer 3.7.3, 3.8.2]:
- MCM=0 (standard text, standard bitmap, ECM text, invalid bitmap 1): a `1` bit.
- MCM=1 multicolor modes: the pairs `10` and `11` (the high bit of the pair); `01` is background
  although it is drawn in a colour. In multicolor text mode only characters whose colour RAM bit 3
  is set are multicolor; the others are hires.
- ECM text (and invalid text mode ECM+MCM) fetch the shape of `code & $3F`.
- Invalid bitmap modes (ECM+BMM) fetch with address bits 9 and 10 cleared [Bauer 3.7.3.7-8]; the
  invalid modes are drawn black but their fetched data still collides.
- Idle state shows the idle byte ($3FFF, $39FF with ECM) read with video matrix data 0 [Bauer 3.7.3.9].
Geometry: column c pixel k at X = 24 + 8c + k + XSCROLL; text row r on lines 48 + YSCROLL + 8r ..
+7; lines of the display window outside any row are idle; lines outside the window (RSEL), and all
lines when DEN=0, are vertical border where the sequencer outputs background [Bauer 3.9, 3.10].
A frame without Bad Lines (`bad_lines` False: DEN was clear in line $30) whose border opened
anyway (DEN set in the window's first line) never leaves idle state: every window line shows the
idle byte, which collides like any graphics [Bauer 3.7.1: display state only from a Bad Line;
VICE-testprogs VICII/dentest howto.txt: "idle data ($3FFF)" with the border open and no Bad Line].
The side border (CSEL) covers graphics but does not stop collisions.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from retro.chips.vic.constants import (
    BITMAP_BYTES,
    CELL_WIDTH,
    CHAR_HEIGHT,
    CHARSET_BYTES,
    COLOR_MASK,
    CONTROL1_BMM,
    CONTROL1_DEN,
    CONTROL1_ECM,
    CONTROL1_RSEL,
    CONTROL1_YSCROLL,
    CONTROL2_CSEL,
    CONTROL2_MCM,
    CONTROL2_XSCROLL,
    ECM_BITMAP_ADDRESS_MASK,
    ECM_CODE_MASK,
    GRAPHICS_FIRST_LINE,
    GRAPHICS_FIRST_X,
    MULTICOLOR_TEXT_FLAG,
    REG_BACKGROUND0,
    REG_BORDER_COLOR,
    REG_CONTROL1,
    REG_CONTROL2,
    SCREEN_CELLS,
    TEXT_COLUMNS,
    TEXT_ROWS,
    WINDOW_LINES,
    WINDOW_X,
    Video,
)

IDLE_ROW = TEXT_ROWS  # line slot: the line is in the display window but in idle state
BORDER_ROW = TEXT_ROWS + 1  # line slot: vertical border (no foreground at all)
OUTSIDE_COLUMN = TEXT_COLUMNS  # column slot: no graphics column at this X
BLACK = 0
GEOMETRY_CONTROL1 = CONTROL1_YSCROLL | CONTROL1_RSEL | CONTROL1_DEN  # what line_slots depends on


@dataclass(frozen=True, eq=False)
class VicMemory:
    """What the VIC sees: screen RAM, colour RAM nybbles, charset, bitmap, the idle byte."""

    screen: np.ndarray  # (1000,) uint8
    color: np.ndarray  # (1000,) uint8, low nybble
    charset: np.ndarray  # (2048,) uint8
    bitmap: np.ndarray  # (8000,) uint8
    idle: int = 0

    @classmethod
    def blank(cls) -> "VicMemory":
        return cls(np.zeros(SCREEN_CELLS, np.uint8), np.zeros(SCREEN_CELLS, np.uint8),
                   np.zeros(CHARSET_BYTES, np.uint8), np.zeros(BITMAP_BYTES, np.uint8), 0)


@lru_cache(maxsize=64)
def line_slots(video: Video, control1: int, bad_lines: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Per raster line: text row (0-24), IDLE_ROW or BORDER_ROW; and the row counter RC. Without
    `bad_lines` the window is all IDLE_ROW (module docstring)."""
    rows = np.full(video.lines, BORDER_ROW, dtype=np.int16)
    rcs = np.zeros(video.lines, dtype=np.int16)
    if control1 & CONTROL1_DEN:
        first, last = WINDOW_LINES[1 if control1 & CONTROL1_RSEL else 0]
        lines = np.arange(first, last + 1)
        offset = lines - GRAPHICS_FIRST_LINE - (control1 & CONTROL1_YSCROLL)
        row = offset // CHAR_HEIGHT
        displayed = (offset >= 0) & (row < TEXT_ROWS) & bad_lines
        rows[lines] = np.where(displayed, row, IDLE_ROW)
        rcs[lines] = np.where(displayed, offset % CHAR_HEIGHT, 0)
    rows.flags.writeable = rcs.flags.writeable = False
    return rows, rcs


@lru_cache(maxsize=64)
def column_slots(video: Video, control2: int) -> tuple[np.ndarray, np.ndarray]:
    """Per X coordinate: graphics column (0-39) or OUTSIDE_COLUMN; and the pixel k within it."""
    offset = np.arange(video.x_positions) - GRAPHICS_FIRST_X - (control2 & CONTROL2_XSCROLL)
    column = offset // CELL_WIDTH
    inside = (offset >= 0) & (column < TEXT_COLUMNS)
    cols = np.where(inside, column, OUTSIDE_COLUMN).astype(np.int16)
    ks = np.where(inside, offset % CELL_WIDTH, 0).astype(np.int16)
    cols.flags.writeable = ks.flags.writeable = False
    return cols, ks


def _fetch(memory: VicMemory, control1: int, control2: int, rows, rcs, cols):
    """The g-access byte and the multicolor flag of each (row, column) cell, idle state included."""
    ecm, bmm = control1 & CONTROL1_ECM, control1 & CONTROL1_BMM
    mcm = bool(control2 & CONTROL2_MCM)
    cell = np.minimum(rows, TEXT_ROWS - 1) * TEXT_COLUMNS + np.minimum(cols, TEXT_COLUMNS - 1)
    idle = rows == IDLE_ROW
    if bmm:
        address = cell * CHAR_HEIGHT + rcs
        if ecm:
            address &= ECM_BITMAP_ADDRESS_MASK
        byte = memory.bitmap[address]
        multicolor = mcm
    else:
        code = memory.screen[cell]
        if ecm:
            code = code & ECM_CODE_MASK
        byte = memory.charset[code.astype(np.intp) * CHAR_HEIGHT + rcs]
        multicolor = ((memory.color[cell] & MULTICOLOR_TEXT_FLAG) != 0) if mcm else False
    if idle.any():
        # idle: video matrix data reads as 0, so only multicolor bitmap modes stay multicolor
        byte = np.where(idle, np.uint8(memory.idle), byte)
        if not isinstance(multicolor, bool):
            multicolor = np.where(idle, mcm and bool(bmm), multicolor)
    return byte, multicolor, cell, idle


def foreground(memory: VicMemory, control1: int, control2: int, rows, rcs, cols, ks) -> np.ndarray:
    """Foreground bits for broadcastable slot arrays (from line_slots / column_slots)."""
    byte, multicolor, _, _ = _fetch(memory, control1, control2, rows, rcs, cols)
    if multicolor is False:
        shift = 7 - ks
    elif multicolor is True:
        shift = 7 - (ks & 6)
    else:
        shift = np.where(multicolor, 7 - (ks & 6), 7 - ks)  # a pair's high bit decides (10, 11)
    bit = (byte >> shift) & 1
    return (bit != 0) & ((rows < BORDER_ROW) & (cols < OUTSIDE_COLUMN))


def foreground_at(video: Video, memory: VicMemory, control1: int, control2: int,
                  lines: np.ndarray, xs: np.ndarray, bad_lines: bool = True) -> np.ndarray:
    """(len(lines), len(xs)) foreground mask: decodes only the given lines and X coordinates."""
    rows, rcs = line_slots(video, control1 & GEOMETRY_CONTROL1, bad_lines)
    cols, ks = column_slots(video, control2 & CONTROL2_XSCROLL)
    r, c = rows[lines], cols[xs]
    if not ((r < BORDER_ROW).any() and (c < OUTSIDE_COLUMN).any()):
        return np.zeros((len(lines), len(xs)), dtype=bool)
    return foreground(memory, control1, control2, r[:, None], rcs[lines][:, None], c[None, :], ks[xs][None, :])


def foreground_points(video: Video, memory: VicMemory, control1: int, control2: int,
                      lines: np.ndarray, xs: np.ndarray, bad_lines: bool = True) -> np.ndarray:
    """Foreground bit of each pixel (lines[i], xs[i]): decodes only those pixels, in one pass."""
    rows, rcs = line_slots(video, control1 & GEOMETRY_CONTROL1, bad_lines)
    cols, ks = column_slots(video, control2 & CONTROL2_XSCROLL)
    return foreground(memory, control1, control2, rows[lines], rcs[lines], cols[xs], ks[xs])


def colours(video: Video, memory: VicMemory, registers: bytes, lines: np.ndarray, xs: np.ndarray,
            bad_lines: bool = True) -> np.ndarray:
    """C64 colour numbers of the graphics and border at (lines x xs), sprites not included (for images)."""
    control1, control2 = registers[REG_CONTROL1], registers[REG_CONTROL2]
    rows, rcs = line_slots(video, control1 & GEOMETRY_CONTROL1, bad_lines)
    cols, ks = column_slots(video, control2 & CONTROL2_XSCROLL)
    r, rc, c, k = rows[lines][:, None], rcs[lines][:, None], cols[xs][None, :], ks[xs][None, :]
    byte, multicolor, cell, idle = _fetch(memory, control1, control2, r, rc, c)
    multicolor = np.broadcast_to(multicolor, byte.shape)
    screen = np.where(idle, 0, memory.screen[cell]).astype(np.int16)
    colour_ram = np.where(idle, 0, memory.color[cell] & COLOR_MASK).astype(np.int16)
    pair = (byte >> (6 - (k & 6))) & 3
    bit = (byte >> (7 - k)) & 1
    background = registers[REG_BACKGROUND0] & COLOR_MASK
    ecm, bmm, mcm = control1 & CONTROL1_ECM, control1 & CONTROL1_BMM, control2 & CONTROL2_MCM
    if ecm and (bmm or mcm):
        out = np.full(byte.shape, BLACK, np.int16)  # invalid modes are black [Bauer 3.7.3.6-8]
    elif bmm:
        hires = np.where(bit == 1, screen >> 4, screen & COLOR_MASK)
        mc = np.select([pair == 0, pair == 1, pair == 2], [background, screen >> 4, screen & COLOR_MASK],
                       colour_ram)
        out = np.where(multicolor, mc, hires)
    elif ecm:
        ecm_background = np.array([registers[REG_BACKGROUND0 + i] & COLOR_MASK for i in range(4)])
        out = np.where(bit == 1, colour_ram, ecm_background[screen >> 6])
    else:
        hires = np.where(bit == 1, colour_ram, background)
        extra = np.array([background, registers[REG_BACKGROUND0 + 1] & COLOR_MASK,
                          registers[REG_BACKGROUND0 + 2] & COLOR_MASK, 0])
        mc = np.where(pair == 3, colour_ram & 7, extra[pair])
        out = np.where(multicolor, mc, hires)
    out = np.where(c < OUTSIDE_COLUMN, out, background)
    out = np.broadcast_to(out, (len(lines), len(xs))).copy()
    left, right = WINDOW_X[1 if control2 & CONTROL2_CSEL else 0]
    side = (xs < left) | (xs > right)
    out[:, side] = registers[REG_BORDER_COLOR] & COLOR_MASK
    out[(r[:, 0] == BORDER_ROW), :] = registers[REG_BORDER_COLOR] & COLOR_MASK
    return out.astype(np.uint8)
