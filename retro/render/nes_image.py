"""Picture of a sprite-zero hit: the frame (background + sprite 0) and a zoomed panel on sprite 0.

Colours are for people, not the PPU (palettes never affect the hit): background pattern values
in greys, sprite 0 in reds, pixels where both are opaque in green, from the 2C02 palette. The
columns where hits cannot happen are shaded blue (x = 0-7 when either left-column bit of $2001 is
clear, and x = 255 always); the hit pixel is outlined in yellow.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from retro.chips.ppu.constants import (
    LEFT_COLUMN_WIDTH,
    MASK_BACKGROUND,
    MASK_LEFT_COLUMN,
    MASK_SPRITES,
    NO_HIT_X,
    SCREEN_HEIGHT,
    SCREEN_WIDTH,
)
from retro.chips.ppu.hit import SpriteZeroHit
from retro.chips.ppu.pixels import background_frame, sprite_values
from retro.chips.ppu.state import PpuState
from retro.render.images import (
    LABEL_COLOUR,
    PANEL_BACKGROUND,
    from_rgb_array,
    label_font,
    side_by_side,
    upscale,
    zoom,
)
from retro.chips.palettes import palette

# 2C02 colour numbers used for the picture.
BACKGROUND_COLOURS = (0x0F, 0x00, 0x10, 0x3D)   # pattern values 0-3: black to light grey
SPRITE_COLOURS = (None, 0x06, 0x16, 0x26)       # pattern values 1-3: reds
OVERLAP_COLOUR = 0x2A                           # both opaque: where a hit may happen
SHADE_RGB = np.array([40, 60, 170])             # blended into columns that cannot hit
SHADE_WEIGHT = 0.45
MARK_RGB = (255, 230, 0)
ZOOM_MARGIN = 4
ZOOM_PIXELS = 12                                # each pixel of the zoom panel becomes this many x scale
LEGEND_HEIGHT = 22
SWATCH = 11


def frame_rgb(state: PpuState) -> np.ndarray:
    """(240, 256, 3) picture of the background with sprite 0 drawn over it, hit-free columns shaded."""
    nes = np.array(palette("nes"), dtype=np.float64)
    background = background_frame(state) if state.mask & MASK_BACKGROUND else np.zeros((SCREEN_HEIGHT, SCREEN_WIDTH), int)
    rgb = nes[np.array(BACKGROUND_COLOURS)[background]]
    if state.mask & MASK_SPRITES:
        top, left, sprite = sprite_values(state, 0)
        for r, c in zip(*np.nonzero(sprite)):
            line, x = top + r, left + c
            if line < SCREEN_HEIGHT and x < SCREEN_WIDTH:
                colour = OVERLAP_COLOUR if background[line, x] else SPRITE_COLOURS[sprite[r, c]]
                rgb[line, x] = nes[colour]
    shaded = np.zeros(SCREEN_WIDTH, dtype=bool)
    shaded[NO_HIT_X] = True
    if state.mask & MASK_LEFT_COLUMN != MASK_LEFT_COLUMN:
        shaded[:LEFT_COLUMN_WIDTH] = True
    rgb[:, shaded] = rgb[:, shaded] * (1 - SHADE_WEIGHT) + SHADE_RGB * SHADE_WEIGHT
    return rgb.round().astype(np.uint8)


def _outline(image: Image.Image, x: int, y: int, size: int) -> None:
    draw = ImageDraw.Draw(image)
    pad = max(2, size // 4)
    draw.rectangle((x * size - pad, y * size - pad, (x + 1) * size + pad - 1, (y + 1) * size + pad - 1),
                   outline=MARK_RGB, width=max(1, size // 3))


def sprite_zero_image(state: PpuState, result: SpriteZeroHit, scale: int = 2) -> Image.Image:
    frame = from_rgb_array(frame_rgb(state))
    big = upscale(frame, scale)
    top, left, sprite = sprite_values(state, 0)
    height, width = sprite.shape
    box = (left - ZOOM_MARGIN, top - ZOOM_MARGIN, left + width + ZOOM_MARGIN, top + height + ZOOM_MARGIN)
    zoom_scale = ZOOM_PIXELS * scale
    if top < SCREEN_HEIGHT:
        panel = zoom(frame, box, zoom_scale)
    else:
        panel = Image.new("RGB", (zoom_scale * 4, zoom_scale * 4), (0, 0, 0))
    if result.hit:
        _outline(big, result.x, result.line, scale)
        _outline(panel, result.x - max(0, box[0]), result.line - max(0, box[1]), zoom_scale)
        title = f"hit at x={result.x}, line {result.line}: bit 6 set at dot {result.dot}"
    else:
        title = f"no hit: {result.reason}"
    sheet = side_by_side([big, panel], [title, f"sprite 0 at x={left}, lines {top}-{top + height - 1} (zoom)"])
    legend = _legend(sheet.width)
    out = Image.new("RGB", (sheet.width, sheet.height + legend.height), PANEL_BACKGROUND)
    out.paste(sheet, (0, 0))
    out.paste(legend, (0, sheet.height))
    return out


def _legend(width: int) -> Image.Image:
    """What each colour means: background shades, sprite 0, both opaque, the hit, the columns that
    cannot hit."""
    nes = palette("nes")
    shade = tuple(int(v) for v in (np.array(nes[BACKGROUND_COLOURS[0]]) * (1 - SHADE_WEIGHT) + SHADE_RGB * SHADE_WEIGHT))
    items = [(nes[BACKGROUND_COLOURS[3]], "background (pattern 1-3)"), (nes[SPRITE_COLOURS[3]], "sprite 0 (pattern 1-3: darker to lighter)"),
             (nes[OVERLAP_COLOUR], "both opaque (may hit)"), (MARK_RGB, "the hit pixel"),
             (shade, "columns that cannot hit (x = 255; x < 8 when clipped)")]
    legend = Image.new("RGB", (width, LEGEND_HEIGHT), PANEL_BACKGROUND)
    draw = ImageDraw.Draw(legend)
    font = label_font()
    x = 8
    for colour, text in items:
        draw.rectangle((x, 5, x + SWATCH, 5 + SWATCH), fill=tuple(colour))
        draw.text((x + SWATCH + 5, 5), text, fill=LABEL_COLOUR, font=font)
        x += SWATCH + 5 + int(draw.textlength(text, font=font)) + 16
    return legend
