"""A VIC-II sprite's bits: 63 bytes, 21 rows of 3, most significant bit leftmost [PRG p.145]; hires
one bit per pixel (1 opaque), multicolour two bits per double-wide pixel, 00 transparent and 01, 10,
11 opaque [Bauer 3.8.1, 3.8.2]. What collides is what is opaque. The file formats are in
retro/sprites.py and retro/loaders/; this is what the chip model needs of a sprite.

`switched_mask`: a row whose X expansion or multicolour bit changes while it is shown, as the
sprite sequencer draws it (constants.EXPAND_X_SWITCH_PIXEL; VICE-src viciisc/vicii-draw-cycle.c
draw_sprites: per pixel, while the expansion flip-flop is set the pixel register takes the next bit
(hires) or, every other time (the pair flip-flop), the next two bits (multicolour), and the shift
register moves one bit; the expansion flip-flop then toggles (expanded) or stays set).
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


ROW_BITS = 24
_NO_SOURCE = -1
_PAIR = 100  # a pixel's source code: bit i (hires), _PAIR + i (multicolour pair i, i + 1), _NO_SOURCE


def row_sources(expand_x: bool, multicolor: bool, switches: tuple[tuple[int, bool, bool], ...] = ()) -> tuple[int, ...]:
    """The source of each pixel of a row from its start: bit i, _PAIR + i, or _NO_SOURCE (nothing).
    `switches`: (pixel from the start, expand_x, multicolor) from which the flags are those; a
    multicolour change clears the pair flip-flop (the 6569's and 6567's colour latency)."""
    pending = sorted(switches)
    expand_flop = pair_flop = True
    position = 0
    source = _NO_SOURCE
    sources = []
    pixel = 0
    while position < ROW_BITS or source != _NO_SOURCE:
        while pending and pending[0][0] <= pixel:
            _, expand_x, now_multicolor = pending.pop(0)
            if now_multicolor != multicolor:
                pair_flop = False
            multicolor = now_multicolor
        if expand_flop:
            if multicolor:
                if pair_flop:
                    source = _PAIR + position if position < ROW_BITS else _NO_SOURCE
                pair_flop = not pair_flop
            else:
                source = position if position < ROW_BITS else _NO_SOURCE
            position += 1
        expand_flop = not expand_flop if expand_x else True
        sources.append(source)
        pixel += 1
    while sources and sources[-1] == _NO_SOURCE:
        sources.pop()
    return tuple(sources)


def switched_mask(data: bytes, sources: tuple[int, ...]) -> np.ndarray:
    """(21, len(sources)) bool: the opaque pixels of each row drawn from `sources` (row_sources)."""
    bits = np.zeros((SPRITE_HEIGHT, ROW_BITS + 1), dtype=bool)
    bits[:, :ROW_BITS] = decode(data).astype(bool)
    codes = np.array(sources, dtype=np.int64)
    pair = codes >= _PAIR
    first = np.where(pair, codes - _PAIR, np.maximum(codes, 0))
    opaque = bits[:, first] | (bits[:, np.minimum(first + 1, ROW_BITS)] & pair)
    return opaque & (codes != _NO_SOURCE)
