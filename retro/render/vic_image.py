"""Overlap images of a VIC-II frame: the whole raster, sprites in their colours, overlaps marked.

Layout: the full frame in the order the beam draws it, starting at the first visible line and the
first visible X coordinate (so the picture looks like the screen, border included); the lines and
X coordinates that fall in the blanking intervals come last (right and bottom) and are dimmed,
because sprites collide there too. Sprites are drawn over the border so that overlaps under it stay
visible. Sprite-sprite overlap pixels and sprite-background overlap pixels get two highlight
colours that are not in the C64 palette. A second panel zooms on the overlap region.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from retro.chips.vic.constants import (
    COLOR_MASK,
    REG_CONTROL1,
    REG_CONTROL2,
    REG_SPRITE_COLOR0,
    REG_SPRITE_EXPAND_X,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_MC0,
    REG_SPRITE_MC1,
    REG_SPRITE_MULTICOLOR,
    REG_SPRITE_PRIORITY,
    SPRITE_COUNT,
)
from retro.chips.vic.graphics import colours, foreground_at
from retro.chips.vic.model import FrameCollisions, VicState, placement, sprite_rows
from retro.render.images import (
    LABEL_COLOUR,
    PANEL_BACKGROUND,
    from_rgb_array,
    side_by_side,
    upscale,
)
from retro.render.palette import C64_DEFAULT_PALETTE, palette
from retro.sprites import decode

SPRITE_SPRITE_HIGHLIGHT = (255, 0, 255)  # magenta: no C64 colour is this saturated
SPRITE_BACKGROUND_HIGHLIGHT = (0, 255, 64)  # bright green
BLANKING_DIM = 0.45
ZOOM_MARGIN = 6
ZOOM_MAX_BOX = (96, 72)  # a wider spread of overlaps zooms on the first one instead
ZOOM_MAX_SCALE = 16
ZOOM_MIN_BOX = (40, 30)  # show some context around a tiny overlap
LEGEND_HEIGHT = 22


def frame_order(state: VicState) -> tuple[np.ndarray, np.ndarray]:
    """Raster lines (image rows) and X coordinates (image columns) in display order."""
    video = state.video
    lines = (video.first_visible_line + np.arange(video.lines)) % video.lines
    xs = (video.first_visible_x + np.arange(video.x_positions)) % video.x_positions
    return lines, xs


def _image_position(state: VicState, lines: np.ndarray, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    video = state.video
    return (lines - video.first_visible_line) % video.lines, (xs - video.first_visible_x) % video.x_positions


def _sprite_colour_numbers(state: VicState, n: int) -> np.ndarray:
    """(21, 24|48) colour numbers of sprite n's pixels, -1 where transparent."""
    regs = state.registers
    multicolor = state.sprite_flag(REG_SPRITE_MULTICOLOR, n)
    own = regs[REG_SPRITE_COLOR0 + n] & COLOR_MASK
    if multicolor:
        values = np.repeat(decode(state.sprite_data[n], True), 2, axis=1).astype(np.int16)
        table = np.array([-1, regs[REG_SPRITE_MC0] & COLOR_MASK, own, regs[REG_SPRITE_MC1] & COLOR_MASK])
        numbers = table[values]
    else:
        numbers = np.where(decode(state.sprite_data[n]) == 1, own, -1)
    if state.sprite_flag(REG_SPRITE_EXPAND_X, n):
        numbers = np.repeat(numbers, 2, axis=1)
    return numbers


def frame_rgb(state: VicState, collisions: FrameCollisions, palette_name: str = C64_DEFAULT_PALETTE) -> np.ndarray:
    """(lines, x_positions, 3) uint8: graphics, sprites, highlights, blanking dimmed."""
    video = state.video
    rgb_table = np.array(palette(palette_name), dtype=np.uint8)
    lines, xs = frame_order(state)
    numbers = colours(video, state.memory, state.registers, lines, xs).astype(np.int16)
    fg = foreground_at(video, state.memory, state.registers[REG_CONTROL1], state.registers[REG_CONTROL2], lines, xs)
    for n in reversed(range(SPRITE_COUNT)):  # sprite 0 ends up on top
        place = placement(state, n)
        if place is None or place.lines.size == 0:
            continue
        rows = sprite_rows(video, state.sprite_y(n), state.sprite_flag(REG_SPRITE_EXPAND_Y, n))
        sprite_numbers = _sprite_colour_numbers(state, n)[rows[place.lines]]
        rr, cc = _image_position(state, place.lines, place.xs)
        target = numbers[rr[:, None], cc[None, :]]
        show = sprite_numbers >= 0
        if state.sprite_flag(REG_SPRITE_PRIORITY, n):
            show &= ~fg[rr[:, None], cc[None, :]]
        numbers[rr[:, None], cc[None, :]] = np.where(show, sprite_numbers, target)
    rgb = rgb_table[numbers]
    for (pl, px), colour in ((collisions.sb_pixels, SPRITE_BACKGROUND_HIGHLIGHT),
                             (collisions.ss_pixels, SPRITE_SPRITE_HIGHLIGHT)):
        if pl.size:
            rr, cc = _image_position(state, pl, px)
            rgb[rr, cc] = colour
    dim = np.ones(rgb.shape[:2], dtype=bool)
    dim[:video.visible_lines, :video.visible_pixels] = False
    rgb[dim] = (rgb[dim] * BLANKING_DIM).astype(np.uint8)
    return rgb


def _zoom_box(state: VicState, collisions: FrameCollisions) -> tuple[int, int, int, int] | None:
    """(left, top, right, bottom) in image pixels around the overlaps (or the sprites if none)."""
    lines = np.concatenate([collisions.ss_pixels[0], collisions.sb_pixels[0]])
    xs = np.concatenate([collisions.ss_pixels[1], collisions.sb_pixels[1]])
    if lines.size == 0:
        places = [p for p in (placement(state, n) for n in range(SPRITE_COUNT)) if p is not None and p.lines.size]
        if not places:
            return None
        lines = np.concatenate([np.repeat(p.lines, p.xs.size) for p in places])
        xs = np.concatenate([np.tile(p.xs, p.lines.size) for p in places])
    rows, cols = _image_position(state, lines, xs)
    top, bottom, left, right = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    if right - left > ZOOM_MAX_BOX[0] or bottom - top > ZOOM_MAX_BOX[1]:
        # overlaps spread out: zoom on the densest cluster (by ZOOM_MAX_BOX-sized bins)
        bins = (rows // ZOOM_MAX_BOX[1]) * 10_000 + cols // ZOOM_MAX_BOX[0]
        values, counts = np.unique(bins, return_counts=True)
        chosen = bins == values[np.argmax(counts)]
        rows, cols = rows[chosen], cols[chosen]
        top, bottom, left, right = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    pad_w, pad_h = max(0, (ZOOM_MIN_BOX[0] - (right - left)) // 2), max(0, (ZOOM_MIN_BOX[1] - (bottom - top)) // 2)
    left, right, top, bottom = left - pad_w, right + pad_w, top - pad_h, bottom + pad_h
    return (int(left) - ZOOM_MARGIN, int(top) - ZOOM_MARGIN, int(right) + ZOOM_MARGIN, int(bottom) + ZOOM_MARGIN)


def _legend(width: int, palette_name: str) -> Image.Image:
    legend = Image.new("RGB", (width, LEGEND_HEIGHT), PANEL_BACKGROUND)
    draw = ImageDraw.Draw(legend)
    x = 8
    for colour, text in ((SPRITE_SPRITE_HIGHLIGHT, "sprite-sprite overlap ($D01E)"),
                         (SPRITE_BACKGROUND_HIGHLIGHT, "sprite-background overlap ($D01F)")):
        draw.rectangle((x, 5, x + 11, 16), fill=colour)
        draw.text((x + 16, 5), text, fill=LABEL_COLOUR)
        x += 16 + int(draw.textlength(text)) + 20
    draw.text((x, 5), f"palette {palette_name}; dimmed: blanking (off-screen)", fill=LABEL_COLOUR)
    return legend


def overlap_image(state: VicState, collisions: FrameCollisions, scale: int = 2,
                  palette_name: str = C64_DEFAULT_PALETTE) -> Image.Image:
    """The frame at an integer scale beside a zoom on the overlaps, with a legend underneath."""
    video = state.video
    frame = from_rgb_array(frame_rgb(state, collisions, palette_name))
    panels = [upscale(frame, scale)]
    titles = [f"{video.name.upper()} {video.chip}, full frame x{scale} (lines from {video.first_visible_line}, "
              f"X from ${video.first_visible_x:X})"]
    box = _zoom_box(state, collisions)
    if box is not None:
        left, top, right, bottom = box
        crop = frame.crop((max(0, left), max(0, top), min(frame.width, right), min(frame.height, bottom)))
        zoom_scale = max(1, min(ZOOM_MAX_SCALE, panels[0].height // max(1, crop.height),
                                max(1, 640 // max(1, crop.width))))
        panels.append(upscale(crop, zoom_scale))
        lines, xs = frame_order(state)
        titles.append(f"zoom x{zoom_scale}: lines {lines[max(0, top)]}-{lines[min(frame.height, bottom) - 1]}, "
                      f"X {xs[max(0, left)]}-{xs[min(frame.width, right) - 1]}")
    sheet = side_by_side(panels, titles)
    legend = _legend(sheet.width, palette_name)
    out = Image.new("RGB", (sheet.width, sheet.height + legend.height), PANEL_BACKGROUND)
    out.paste(sheet, (0, 0))
    out.paste(legend, (0, sheet.height))
    return out
