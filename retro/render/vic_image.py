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
    REG_CONTROL1,
    REG_CONTROL2,
    REG_SPRITE_EXPAND_X,
    REG_SPRITE_MULTICOLOR,
    REG_SPRITE_PRIORITY,
    SPRITE_COUNT,
)
from retro.chips.vic.graphics import colours, foreground_at
from retro.chips.vic.model import FrameCollisions, VicState, placement
from retro.chips.vic.sprite_registers import sprite_colours
from retro.render.images import (
    LABEL_COLOUR,
    LABEL_SIZE,
    PANEL_BACKGROUND,
    from_rgb_array,
    label_font,
    side_by_side,
    upscale,
)
from retro.chips.palettes import C64_DEFAULT_PALETTE, palette
from retro.sprites import decode

SPRITE_SPRITE_HIGHLIGHT = (255, 0, 255)  # magenta: no C64 colour is this saturated
SPRITE_BACKGROUND_HIGHLIGHT = (0, 255, 64)  # bright green
BLANKING_DIM = 0.45
ZOOM_MARGIN = 6
ZOOM_MAX_BOX = (96, 72)  # a wider spread of overlaps zooms on the first one instead
ZOOM_MAX_SCALE = 16
ZOOM_MIN_BOX = (40, 30)  # show some context around a tiny overlap
LEGEND_HEIGHT = 22
MARKER_COLOUR = (255, 220, 0)  # yellow rings at the first pixel that latches $D01E / $D01F
MARKER_RADIUS = 4
ZOOM_PANELS = 4  # zooms at most: one per colliding pair, then per sprite over graphics
ZOOM_MIN_HEIGHT = 240
RULER = 26  # pixels of ruler above and left of a zoom
RULER_STEP = 8  # ruler ticks every 8 X coordinates and 8 lines (a character cell)
RULER_LABEL_SIZE = 10
RULER_LABEL_ROOM = 26  # pixels a ruler number needs


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
    colours = sprite_colours(state.registers, n)
    multicolor = state.sprite_flag(REG_SPRITE_MULTICOLOR, n)
    own = colours.own
    if multicolor:
        values = np.repeat(decode(state.sprite_data[n], True), 2, axis=1).astype(np.int16)
        table = np.array([-1, colours.multicolor0, own, colours.multicolor1])
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
    numbers = colours(video, state.memory, state.registers, lines, xs, state.bad_lines).astype(np.int16)
    fg = foreground_at(video, state.memory, state.registers[REG_CONTROL1], state.registers[REG_CONTROL2], lines, xs,
                       state.bad_lines)
    for n in reversed(range(SPRITE_COUNT)):  # sprite 0 ends up on top
        place = placement(state, n)
        if place is None or place.lines.size == 0:
            continue
        sprite_numbers = _sprite_colour_numbers(state, n)[place.rows, place.cols]  # opaque pixels only
        rr, cc = _image_position(state, place.lines, place.xs)
        show = sprite_numbers >= 0
        if state.sprite_flag(REG_SPRITE_PRIORITY, n):
            show &= ~fg[rr, cc]
        numbers[rr[show], cc[show]] = sprite_numbers[show]
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
        lines = np.concatenate([p.lines for p in places])
        xs = np.concatenate([p.xs for p in places])
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


def _legend(width: int, palette_name: str, collisions: FrameCollisions) -> Image.Image:
    legend = Image.new("RGB", (width, LEGEND_HEIGHT), PANEL_BACKGROUND)
    draw = ImageDraw.Draw(legend)
    x = 8
    for colour, text in ((SPRITE_SPRITE_HIGHLIGHT, f"sprite-sprite overlap ($D01E = ${collisions.d01e:02X})"),
                         (SPRITE_BACKGROUND_HIGHLIGHT, f"sprite-background overlap ($D01F = ${collisions.d01f:02X})"),
                         (MARKER_COLOUR, "first pixel that latches each")):
        draw.rectangle((x, 5, x + 11, 16), fill=colour)
        draw.text((x + 16, 5), text, fill=LABEL_COLOUR, font=label_font())
        x += 16 + int(draw.textlength(text, font=label_font())) + 20
    draw.text((x, 5), f"palette {palette_name}; dimmed: blanking (off-screen); numbers: sprites", fill=LABEL_COLOUR,
              font=label_font())
    return legend


def _annotate_frame(panel: Image.Image, state: VicState, collisions: FrameCollisions, scale: int) -> None:
    """Sprite numbers at each sprite's top-left; a ring and a label at each latch's first pixel."""
    draw = ImageDraw.Draw(panel)
    font = label_font()
    for n in range(SPRITE_COUNT):
        place = placement(state, n)
        if place is None or place.lines.size == 0:
            continue
        rows, cols = _image_position(state, place.lines.min(keepdims=True), np.array([place.x]))
        x, y = int(cols[0]) * scale, int(rows[0]) * scale
        box = draw.textbbox((x + 1, y - LABEL_SIZE - 2), str(n), font=font)
        draw.rectangle(box, fill=PANEL_BACKGROUND)
        draw.text((x + 1, y - LABEL_SIZE - 2), str(n), fill=LABEL_COLOUR, font=font)
    for first, name in ((collisions.first_ss, "$D01E"), (collisions.first_sb, "$D01F")):
        if first is None:
            continue
        rows, cols = _image_position(state, np.array([first[0]]), np.array([first[1]]))
        cx, cy = int(cols[0]) * scale + scale // 2, int(rows[0]) * scale + scale // 2
        radius = MARKER_RADIUS + scale
        draw.ellipse((cx - radius, cy - radius, cx + radius, cy + radius), outline=MARKER_COLOUR, width=2)
        text = f"{name} first: line {first[0]}, X {first[1]}"
        draw.text((cx + radius + 3, cy - LABEL_SIZE // 2), text, fill=MARKER_COLOUR, font=font)


def _zoom(frame: Image.Image, state: VicState, rows: np.ndarray, cols: np.ndarray, height: int,
          title: str) -> tuple[Image.Image, str]:
    """A zoom on the image pixels (rows, cols), with rulers every 8 X coordinates and 8 lines. Pixels
    spread wider than ZOOM_MAX_BOX (a pair meeting in two places) zoom on the part around the first."""
    first = int(np.argmin(rows * frame.width + cols))
    near = (np.abs(rows - rows[first]) <= ZOOM_MAX_BOX[1]) & (np.abs(cols - cols[first]) <= ZOOM_MAX_BOX[0])
    rows, cols = rows[near], cols[near]
    top, bottom, left, right = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    pad_w = max(0, (ZOOM_MIN_BOX[0] - (right - left)) // 2)
    pad_h = max(0, (ZOOM_MIN_BOX[1] - (bottom - top)) // 2)
    left, right = max(0, left - pad_w - ZOOM_MARGIN), min(frame.width, right + pad_w + ZOOM_MARGIN)
    top, bottom = max(0, top - pad_h - ZOOM_MARGIN), min(frame.height, bottom + pad_h + ZOOM_MARGIN)
    crop = frame.crop((int(left), int(top), int(right), int(bottom)))
    zoom_scale = max(1, min(ZOOM_MAX_SCALE, height // max(1, crop.height), max(1, 480 // max(1, crop.width))))
    zoomed = upscale(crop, zoom_scale)
    ruled = Image.new("RGB", (zoomed.width + RULER, zoomed.height + RULER), PANEL_BACKGROUND)
    ruled.paste(zoomed, (RULER, RULER))
    draw = ImageDraw.Draw(ruled)
    lines, xs = frame_order(state)
    font = label_font(RULER_LABEL_SIZE)
    # label every tick that leaves room for its number (at small zooms every 2nd, 4th ... tick)
    every = RULER_STEP * max(1, -(-RULER_LABEL_ROOM // (RULER_STEP * zoom_scale)))
    for col in range(int(left), int(right)):
        if xs[col] % RULER_STEP == 0:
            x = RULER + (col - int(left)) * zoom_scale
            draw.line((x, RULER - 4, x, RULER - 1), fill=LABEL_COLOUR)
            if xs[col] % every == 0:
                draw.text((x + 2, 1), str(int(xs[col])), fill=LABEL_COLOUR, font=font)
    for row in range(int(top), int(bottom)):
        if lines[row] % RULER_STEP == 0:
            y = RULER + (row - int(top)) * zoom_scale
            draw.line((RULER - 4, y, RULER - 1, y), fill=LABEL_COLOUR)
            if lines[row] % every == 0:
                draw.text((1, y + 1), str(int(lines[row])), fill=LABEL_COLOUR, font=font)
    return ruled, (f"{title} x{zoom_scale}: lines {lines[int(top)]}-{lines[int(bottom) - 1]}, "
                   f"X {xs[int(left)]}-{xs[int(right) - 1]}")


def _zoom_sets(state: VicState, collisions: FrameCollisions) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(title, image rows, image cols) of each colliding pair, of each sprite over graphics, or of
    all sprites when nothing collides."""
    sets = []
    for a, b in collisions.pairs[:ZOOM_PANELS]:
        lines, xs = collisions.pair_pixels(a, b)
        if lines.size:
            sets.append((f"sprites {a}+{b}", *_image_position(state, lines, xs)))
    for n in range(SPRITE_COUNT):
        lines, xs = collisions.background_pixels(n)
        if lines.size and len(sets) < ZOOM_PANELS:
            sets.append((f"sprite {n} over graphics", *_image_position(state, lines, xs)))
    if not sets:
        box = _zoom_box(state, collisions)
        if box is not None:
            left, top, right, bottom = box
            sets.append(("sprites (no collision)", np.array([top + ZOOM_MARGIN, bottom - ZOOM_MARGIN - 1]),
                         np.array([left + ZOOM_MARGIN, right - ZOOM_MARGIN - 1])))
    return sets


def overlap_image(state: VicState, collisions: FrameCollisions, scale: int = 2,
                  palette_name: str = C64_DEFAULT_PALETTE) -> Image.Image:
    """The frame at an integer scale (sprite numbers, first-latch markers) beside a zoom with rulers on
    each colliding pair and each sprite over graphics, with a legend (register values) underneath."""
    video = state.video
    frame = from_rgb_array(frame_rgb(state, collisions, palette_name))
    full = upscale(frame, scale)
    _annotate_frame(full, state, collisions, scale)
    panels = [full]
    titles = [f"{video.name.upper()} {video.chip}, full frame x{scale} (lines from {video.first_visible_line}, "
              f"X from ${video.first_visible_x:X})"]
    zoom_height = max(ZOOM_MIN_HEIGHT, full.height // max(1, min(2, len(_zoom_sets(state, collisions)))))
    for title, rows, cols in _zoom_sets(state, collisions):
        panel, text = _zoom(frame, state, rows, cols, zoom_height, title)
        panels.append(panel)
        titles.append(text)
    sheet = side_by_side(panels, titles)
    legend = _legend(sheet.width, palette_name, collisions)
    out = Image.new("RGB", (sheet.width, sheet.height + legend.height), PANEL_BACKGROUND)
    out.paste(sheet, (0, 0))
    out.paste(legend, (0, sheet.height))
    return out
