"""A VIC-II sprite's bits: 63 bytes, 21 rows of 3, most significant bit leftmost [PRG p.145]; hires
one bit per pixel (1 opaque), multicolour two bits per double-wide pixel, 00 transparent and 01, 10,
11 opaque [Bauer 3.8.1, 3.8.2]. What collides is what is opaque. The file formats are in
retro/sprites.py and retro/loaders/; this is what the chip model needs of a sprite.
"""

from __future__ import annotations

import numpy as np

from retro.chips.vic.constants import SPRITE_BLOCK, SPRITE_BYTES, SPRITE_BYTES_PER_ROW, SPRITE_HEIGHT
from retro.errors import InputError


def decode(data: bytes, multicolor: bool = False) -> np.ndarray:
    """63 (or 64) bytes -> (21, 24) uint8 of 0/1 (hires) or (21, 12) uint8 of 0-3 (multicolor)."""
    raw = np.frombuffer(bytes(data[:SPRITE_BYTES]), dtype=np.uint8)
    if raw.size != SPRITE_BYTES:
        raise InputError(f"sprite data: expected {SPRITE_BYTES} or {SPRITE_BLOCK} bytes, got {len(data)}")
    bits = np.unpackbits(raw.reshape(SPRITE_HEIGHT, SPRITE_BYTES_PER_ROW), axis=1)
    if not multicolor:
        return bits
    return bits[:, 0::2] * 2 + bits[:, 1::2]


def opaque_mask(data: bytes, multicolor: bool = False) -> np.ndarray:
    """(21, 24) bool: where the sprite outputs a non-transparent pixel (what collides)."""
    if not multicolor:
        return decode(data).astype(bool)
    return np.repeat(decode(data, True) != 0, 2, axis=1)
