"""Sprite files -> opacity masks for the study, through retro.sprites (the one sprite decoder)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from retro import sprites


def is_multicolor(path: Path) -> bool:
    """Raw .spr files do not record the mode; sprites/ marks multicolor ones by name (`mc_*.spr`,
    see sprites/make_sprites.py)."""
    return path.stem.startswith("mc_")


def sprite_opacity(path: Path, frame: int = 0) -> tuple[np.ndarray, bool, bytes]:
    """(mask [21, 24] bool in screen pixels, multicolor, the 63 bytes) of frame `frame` of a .spr file."""
    multicolor = is_multicolor(path)
    data = sprites.read_spr(path, frame)
    return sprites.opaque_mask(data, multicolor), multicolor, data
