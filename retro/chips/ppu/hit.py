"""The sprite-zero hit ($2002 bit 6): whether it happens, at which pixel, and when.

Rules (nesdev wiki "PPU OAM" section "Sprite zero hits", "PPU registers" PPUSTATUS, and blargg's
sprite_hit_tests_2005.10.05 readme, whose tests 01-11 cover them one by one):
- A hit is an opaque pixel (2-bit pattern value not 0) of OAM entry 0 drawn at the same screen
  pixel as an opaque background pixel. Palettes, colours, greyscale, emphasis and the priority bit
  do not matter; other sprites never count.
- No hit when background or sprite rendering is off ($2001 bits 3, 4); at x = 0-7 when either
  left-column bit ($2001 bits 1, 2) is clear; at x = 255; on lines >= 240 (a sprite at OAM Y is
  drawn on lines Y+1.., so Y >= 239 never hits and line 0 never hits).
- The first qualifying pixel in raster order sets the flag, once a frame; it stays set until dot 1
  of the pre-render line.
- Timing: the flag for pixel (x, L) is set at dot x + 1 of line L. `dots_after_vblank` counts PPU
  dots from the vblank flag (line 241, dot 1, of the preceding frame) to that dot, counting the
  pre-render line as a full 341 dots (on NTSC with rendering on, every other frame is one dot
  shorter; see `retro.chips.ppu.clock`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.chips.ppu.constants import (
    DOTS_PER_LINE,
    HIT_DOT_OFFSET,
    LEFT_COLUMN_WIDTH,
    MASK_BACKGROUND,
    MASK_LEFT_COLUMN,
    MASK_SPRITES,
    NO_HIT_X,
    SCREEN_HEIGHT,
    SCREEN_WIDTH,
    VBLANK_DOT,
    VBLANK_LINE,
    VideoStandard,
)
from retro.chips.ppu.pixels import background_values, sprite_values
from retro.chips.ppu.state import PpuState


@dataclass(frozen=True)
class SpriteZeroHit:
    hit: bool
    x: int | None = None                  # screen pixel of the hit
    line: int | None = None               # PPU line (= screen line) of the hit
    dot: int | None = None                # PPU dot of that line at which bit 6 is set (x + 1)
    dots_after_vblank: int | None = None  # dots from the preceding vblank flag to that dot
    reason: str = ""                      # why there is no hit (empty when there is one)
    # the same span in CPU cycles of the scene's standard (3 dots a cycle on NTSC, 3.2 on PAL): what a
    # `bit $2002` loop started at the vblank flag waits; fractional where the ratio makes it so
    cpu_cycles_after_vblank: float | None = None

    def as_json(self) -> dict:
        return {"hit": self.hit, "line": self.line, "dot": self.dot, "x": self.x,
                "dots_after_vblank": self.dots_after_vblank, "cpu_cycles_after_vblank": self.cpu_cycles_after_vblank}


def hit_dot(x: int) -> int:
    return x + HIT_DOT_OFFSET


def dots_after_vblank(line: int, dot: int, video: VideoStandard) -> int:
    """Dots from line 241 dot 1 of the preceding frame to (line, dot) of this one, full pre-render line."""
    return (video.lines_per_frame - VBLANK_LINE + line) * DOTS_PER_LINE + dot - VBLANK_DOT


CPU_CYCLE_DIGITS = 4


def cpu_cycles(dots: int, video: VideoStandard) -> float:
    """PPU dots as CPU cycles of that standard (exact to 4 decimals: the ratios are 3 and 16/5)."""
    return round(float(dots / video.dots_per_cpu_cycle), CPU_CYCLE_DIGITS)


def rendering_enabled_for_hits(mask: int) -> bool:
    return bool(mask & MASK_BACKGROUND) and bool(mask & MASK_SPRITES)


def hit_pixels(state: PpuState) -> tuple[np.ndarray, np.ndarray]:
    """All pixels (lines, xs) where sprite 0 would hit, in raster order (the first one wins)."""
    top, left, sprite = sprite_values(state, 0)
    height, width = sprite.shape
    lines = top + np.arange(height)[:, None] + np.zeros((1, width), dtype=int)
    xs = left + np.arange(width)[None, :] + np.zeros((height, 1), dtype=int)
    on_screen = (lines < SCREEN_HEIGHT) & (xs < SCREEN_WIDTH)
    if not rendering_enabled_for_hits(state.mask) or not on_screen.any():
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    left_column_shown = (state.mask & MASK_LEFT_COLUMN) == MASK_LEFT_COLUMN
    candidates = on_screen & (sprite != 0) & (xs != NO_HIT_X)
    if not left_column_shown:
        candidates &= xs >= LEFT_COLUMN_WIDTH
    lines, xs = lines[candidates], xs[candidates]
    if lines.size:
        opaque = background_values(state, lines, xs) != 0
        lines, xs = lines[opaque], xs[opaque]
    order = np.lexsort((xs, lines))
    return lines[order], xs[order]


def sprite_zero_hit(state: PpuState) -> SpriteZeroHit:
    """The model: whether $2002 bit 6 gets set this frame, for which pixel, at which line and dot."""
    lines, xs = hit_pixels(state)
    if lines.size == 0:
        return SpriteZeroHit(hit=False, reason=_no_hit_reason(state))
    line, x = int(lines[0]), int(xs[0])
    dot = hit_dot(x)
    return SpriteZeroHit(hit=True, x=x, line=line, dot=dot,
                         dots_after_vblank=dots_after_vblank(line, dot, state.video),
                         cpu_cycles_after_vblank=cpu_cycles(dots_after_vblank(line, dot, state.video), state.video))


def _no_hit_reason(state: PpuState) -> str:
    if not state.mask & MASK_BACKGROUND:
        return "background rendering is off ($2001 bit 3)"
    if not state.mask & MASK_SPRITES:
        return "sprite rendering is off ($2001 bit 4)"
    top, left, sprite = sprite_values(state, 0)
    if top >= SCREEN_HEIGHT:
        return f"sprite 0 starts on line {top}, below the visible lines 0-{SCREEN_HEIGHT - 1}"
    if not sprite.any():
        return "sprite 0 has no opaque pixel"
    return "no opaque pixel of sprite 0 meets an opaque background pixel where hits can happen"
