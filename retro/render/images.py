"""Image helpers shared by every renderer: scaling, zoom panels, side-by-side layout, PNG output."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from retro.fileio import write_atomic

PANEL_GAP = 8
PANEL_BACKGROUND = (32, 32, 32)
LABEL_COLOUR = (230, 230, 230)


LABEL_SIZE = 12


def label_font(size: int = LABEL_SIZE) -> ImageFont.ImageFont:
    """Pillow's bundled scalable font (Pillow >= 10.1), else its small bitmap font."""
    try:
        return ImageFont.load_default(size=size)
    except TypeError:
        return ImageFont.load_default()


def from_rgb_array(pixels: np.ndarray) -> Image.Image:
    """An (H, W, 3) uint8 array -> PIL image."""
    return Image.fromarray(np.ascontiguousarray(pixels, dtype=np.uint8), "RGB")


def upscale(image: Image.Image, scale: int) -> Image.Image:
    """Integer nearest-neighbour scaling: every source pixel becomes a scale x scale block."""
    if scale == 1:
        return image
    return image.resize((image.width * scale, image.height * scale), Image.NEAREST)


def zoom(image: Image.Image, box: tuple[int, int, int, int], scale: int) -> Image.Image:
    """Crop box (left, top, right, bottom; clipped to the image) and scale it up by an integer."""
    left, top, right, bottom = box
    left, top = max(0, left), max(0, top)
    right, bottom = min(image.width, max(right, left + 1)), min(image.height, max(bottom, top + 1))
    return upscale(image.crop((left, top, right, bottom)), scale)


def side_by_side(panels: list[Image.Image], titles: list[str] | None = None) -> Image.Image:
    """Panels left to right on a dark background, each with an optional title above it."""
    title_height = LABEL_SIZE + 4 if titles else 0
    width = sum(p.width for p in panels) + PANEL_GAP * (len(panels) + 1)
    height = max(p.height for p in panels) + title_height + PANEL_GAP * 2
    sheet = Image.new("RGB", (width, height), PANEL_BACKGROUND)
    draw = ImageDraw.Draw(sheet)
    x = PANEL_GAP
    for index, panel in enumerate(panels):
        if titles:
            draw.text((x, PANEL_GAP // 2), titles[index], fill=LABEL_COLOUR, font=label_font())
        sheet.paste(panel, (x, PANEL_GAP + title_height))
        x += panel.width + PANEL_GAP
    return sheet


def png_bytes(image: Image.Image) -> bytes:
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


def save_png(image: Image.Image, path: str | Path) -> Path:
    """Write a PNG atomically (temp file + rename)."""
    return write_atomic(path, png_bytes(image))
