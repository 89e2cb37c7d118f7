"""Koala Painter pictures (.koa, .kla): a multicolour bitmap with its screen and colour RAM.

Layout ("KOALA-PAINT-FORMAT" in *All About Your 64* and the Padua ml-tutorial; Arndt Dettke's
GoDot loader notes; archiveteam's "KoalaPainter"): 8000 bytes of bitmap, 1000 of screen RAM
(the colours of pixel pairs `01` and `10`), 1000 of colour RAM (pair `11`, low nibble), 1 byte the
background colour ($D021): 10001 bytes. As a C64 file it has a 2-byte load address in front,
$6000 (sometimes $4400): 10003 bytes. Files that came off a disk through other tools may carry a
few padding bytes after that; they are ignored when the load address is $6000 or $4400.

Compressed Koala pictures ("GG" files) are not read: they are shorter than 10001 bytes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.chips.vic.constants import BITMAP_BYTES, COLOR_MASK, SCREEN_CELLS
from retro.errors import InputError

DATA_BYTES = BITMAP_BYTES + 2 * SCREEN_CELLS + 1  # 10001
LOAD_ADDRESS_BYTES = 2
FILE_BYTES = LOAD_ADDRESS_BYTES + DATA_BYTES  # 10003
LOAD_ADDRESSES = (0x6000, 0x4400)
MAX_PADDING = 254  # a disk block's worth of trailing bytes


@dataclass(frozen=True, eq=False)
class KoalaPicture:
    bitmap: np.ndarray   # (8000,) uint8
    screen: np.ndarray   # (1000,) uint8
    colour: np.ndarray   # (1000,) uint8, low nibbles
    background: int      # $D021
    load_address: int | None  # None: the file had no load address (10001 bytes)


def looks_like_koala(raw: bytes) -> bool:
    if len(raw) in (DATA_BYTES, FILE_BYTES):
        return True
    return (FILE_BYTES < len(raw) <= FILE_BYTES + MAX_PADDING
            and (raw[0] | raw[1] << 8) in LOAD_ADDRESSES)


def koala_from_bytes(raw: bytes, name: str = "Koala picture") -> KoalaPicture:
    """A Koala picture's bytes (with or without its load address) -> its parts."""
    if not looks_like_koala(raw):
        raise InputError(f"{name}: file size: {len(raw)} bytes: a Koala picture is {FILE_BYTES} bytes (load address "
                         f"$6000, 8000 bitmap, 1000 screen, 1000 colour, 1 background) or {DATA_BYTES} without the "
                         f"load address; compressed (GG) pictures are not read")
    load = None
    data = raw
    if len(raw) != DATA_BYTES:
        load = raw[0] | raw[1] << 8
        data = raw[LOAD_ADDRESS_BYTES:LOAD_ADDRESS_BYTES + DATA_BYTES]
    values = np.frombuffer(data, dtype=np.uint8)
    screen_at = BITMAP_BYTES
    colour_at = screen_at + SCREEN_CELLS
    return KoalaPicture(values[:screen_at].copy(), values[screen_at:colour_at].copy(),
                        values[colour_at:colour_at + SCREEN_CELLS] & COLOR_MASK,
                        int(values[-1]) & COLOR_MASK, load)
