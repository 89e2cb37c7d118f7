"""A sprite as a PNG preview: the preview colours of retro/sprites.py (which its PNG reader reads
back exactly), scaled by whole pixels, written atomically."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from retro.chips.vic.constants import SPRITE_HEIGHT, SPRITE_WIDTH
from retro.chips.vic.sprite_bits import decode
from retro.render.images import save_png, upscale
from retro.sprites import HIRES_PREVIEW, MULTICOLOR_PREVIEW


def to_image(data: bytes, multicolor: bool = False) -> Image.Image:
    """The sprite as a 24x21 RGB image in the preview colours (what read_png reads back)."""
    rgb = np.zeros((SPRITE_HEIGHT, SPRITE_WIDTH, 3), dtype=np.uint8)
    if multicolor:
        values = np.repeat(decode(data, True), 2, axis=1)
        for value, colour in MULTICOLOR_PREVIEW.items():
            rgb[values == value] = colour
    else:
        rgb[decode(data).astype(bool)] = HIRES_PREVIEW
    return Image.fromarray(rgb, "RGB")


def write_png(path: str | Path, data: bytes, multicolor: bool = False, scale: int = 1) -> Path:
    return save_png(upscale(to_image(data, multicolor), scale), path)
