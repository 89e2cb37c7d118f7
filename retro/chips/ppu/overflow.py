"""The sprite overflow flag ($2002 bit 5) as the 2C02 sets it, evaluation bug included.

Sprite evaluation (nesdev wiki "PPU sprite evaluation"; blargg's sprite_overflow_tests readme): on
each visible line L (0-239), with rendering on, the PPU looks through OAM for the sprites of line
L + 1, i.e. those whose Y satisfies 0 <= L - Y < height (8, or 16 with $2000 bit 5), in dots
65-256: a sprite's Y is read on an odd dot (sprite n at dot 65 + 2n while none has been copied) and
each in-range sprite costs 6 more dots to copy its other three bytes. Once 8 are found, the PPU goes
on from the next sprite n with m = 0 and reads byte m of sprite n as if it were a Y: in range sets
the overflow flag; out of range steps n and m together (m wrapping 3 -> 0 without carrying into n):
"the diagonal" that makes real hardware miss overflows and see false ones. The flag stays set
until dot 1 of the pre-render line. The dot of the flag is the dot of the read that found it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from retro.chips.ppu.constants import (
    CTRL_SPRITE_8X16,
    DOTS_PER_LINE,
    MASK_RENDERING,
    OAM_ENTRY_SIZE,
    SCREEN_HEIGHT,
    SPRITE_EVALUATION_DOT,
    SPRITE_HEIGHT_8X16,
    SPRITE_HEIGHT_8X8,
    SPRITES_PER_LINE,
)
from retro.chips.ppu.hit import dots_after_vblank
from retro.chips.ppu.state import PpuState

OAM_ENTRIES = 64
DOTS_PER_READ = 2               # an odd dot reads OAM, the even dot after it writes secondary OAM
DOTS_PER_COPY = 6               # the three other bytes of an in-range sprite


def overflow_dot_on_line(oam: bytes, line: int, height: int) -> int | None:
    """The dot of `line` at which evaluation sets the overflow flag, or None."""
    found = 0
    dot = SPRITE_EVALUATION_DOT
    n = 0
    while n < OAM_ENTRIES and found < SPRITES_PER_LINE:
        in_range = 0 <= line - oam[n * OAM_ENTRY_SIZE] < height
        dot += DOTS_PER_READ + (DOTS_PER_COPY if in_range else 0)
        found += in_range
        n += 1
    if found < SPRITES_PER_LINE:
        return None
    m = 0
    while n < OAM_ENTRIES:
        if 0 <= line - oam[n * OAM_ENTRY_SIZE + m] < height:
            return dot
        dot += DOTS_PER_READ
        n += 1
        m = (m + 1) % OAM_ENTRY_SIZE
    return None


def sprites_per_line(oam: bytes, height: int) -> np.ndarray:
    """For each visible line L, how many OAM entries have 0 <= L - Y < height (evaluated on L)."""
    ys = np.frombuffer(bytes(oam), dtype=np.uint8)[::OAM_ENTRY_SIZE].astype(np.int32)
    offsets = np.arange(SCREEN_HEIGHT)[:, None] - ys
    return ((offsets >= 0) & (offsets < height)).sum(axis=1)


@lru_cache(maxsize=64)
def overflow_dots(oam: bytes, tall: bool) -> np.ndarray:
    """Sorted dots within a frame (line x 341 + dot) at which each visible line's evaluation sets the
    flag, for OAM `oam` and 8x16 sprites when `tall`; rendering is taken to be on."""
    height = SPRITE_HEIGHT_8X16 if tall else SPRITE_HEIGHT_8X8
    crowded = sprites_per_line(oam, height) >= SPRITES_PER_LINE
    dots = []
    for line in np.flatnonzero(crowded):
        dot = overflow_dot_on_line(oam, int(line), height)
        if dot is not None:
            dots.append(int(line) * DOTS_PER_LINE + dot)
    return np.array(dots, dtype=np.int64)


def first_overflow(oam: bytes, tall: bool) -> tuple[int, int] | None:
    """(line, dot) of the frame's first overflow, or None."""
    dots = overflow_dots(bytes(oam), tall)
    return divmod(int(dots[0]), DOTS_PER_LINE) if dots.size else None


@dataclass(frozen=True)
class SpriteOverflow:
    set: bool
    line: int | None = None               # the line whose evaluation sets $2002 bit 5
    dot: int | None = None                # the dot of that line
    dots_after_vblank: int | None = None  # from the preceding vblank flag (as the sprite-zero hit's)
    sprites_on_line: int | None = None    # sprites really in range on that line (9+, or 8 for a false overflow)
    reason: str = ""                      # why it is not set (empty when it is)

    def as_json(self) -> dict:
        return {"set": self.set, "line": self.line, "dot": self.dot, "dots_after_vblank": self.dots_after_vblank,
                "sprites_on_line": self.sprites_on_line}


def sprite_overflow(state: PpuState) -> SpriteOverflow:
    """The model: whether $2002 bit 5 gets set in a frame rendered from `state`, on which line and dot."""
    if not state.mask & MASK_RENDERING:
        return SpriteOverflow(False, reason="rendering is off ($2001 bits 3 and 4): no sprite evaluation")
    tall = bool(state.ctrl & CTRL_SPRITE_8X16)
    first = first_overflow(state.oam, tall)
    height = SPRITE_HEIGHT_8X16 if tall else SPRITE_HEIGHT_8X8
    counts = sprites_per_line(state.oam, height)
    if first is None:
        busiest = int(counts.max())
        why = (f"no line has more than {SPRITES_PER_LINE} sprites (at most {busiest})" if busiest <= SPRITES_PER_LINE
               else "lines with more than 8 sprites exist, but the evaluation bug misses them all")
        return SpriteOverflow(False, reason=why)
    line, dot = first
    return SpriteOverflow(True, line=line, dot=dot, dots_after_vblank=dots_after_vblank(line, dot, state.video),
                          sprites_on_line=int(counts[line]))
