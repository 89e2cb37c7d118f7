"""Koala Painter pictures (.koa, .kla): a multicolour bitmap with its screen and colour RAM.

Layout ("KOALA-PAINT-FORMAT" in *All About Your 64* and the Padua ml-tutorial; Arndt Dettke's
GoDot loader notes; archiveteam's "KoalaPainter"): 8000 bytes of bitmap, 1000 of screen RAM
(the colours of pixel pairs `01` and `10`), 1000 of colour RAM (pair `11`, low nibble), 1 byte the
background colour ($D021): 10001 bytes. As a C64 file it has a 2-byte load address in front,
$6000 (sometimes $4400): 10003 bytes. Files that came off a disk through other tools may carry a
few padding bytes after that; they are ignored when the load address is $6000 or $4400.

Compressed Koala pictures ("GG" files, as the C64 tools that pack Koala pictures write them): a
2-byte load address, then a run-length stream that unpacks to the 10001 bytes above. A byte $FE is
followed by a value and a count (the value `count` times; 0 times for a count of 0); any other byte
stands for itself. Unpacking stops at 10001 bytes (a run past the end is cut there). Sources, which
agree on every point: RECOIL (Piotr Fusik; recoil.c, RECOIL_DecodeGg and C64KoalaStream_ReadCommand,
as in demozoo/pyrecoil) and onyx_image (codecs/koala.cpp, decompress_gg). A file shorter than 10001
bytes is read as GG where a Koala picture is asked for (`memory.koala`), and, by content, when its
load address is $6000 and its stream unpacks to exactly 10001 bytes and ends with the file; a stream
that stops short is one line giving how far it got, as is one with more than 254 bytes after its end.
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
GG_ESCAPE = 0xFE
GG_RUN = 3  # escape, value, count


@dataclass(frozen=True, eq=False)
class KoalaPicture:
    bitmap: np.ndarray   # (8000,) uint8
    screen: np.ndarray   # (1000,) uint8
    colour: np.ndarray   # (1000,) uint8, low nibbles
    background: int      # $D021
    load_address: int | None  # None: the file had no load address (10001 bytes)


def _plain_koala(raw: bytes) -> bool:
    if len(raw) in (DATA_BYTES, FILE_BYTES):
        return True
    return (FILE_BYTES < len(raw) <= FILE_BYTES + MAX_PADDING
            and (raw[0] | raw[1] << 8) in LOAD_ADDRESSES)


def unpack_gg(raw: bytes, name: str = "Koala picture") -> tuple[bytes, int]:
    """A GG file -> (the 10001 unpacked bytes, where the stream ended); one line if it falls short."""
    if len(raw) < LOAD_ADDRESS_BYTES:
        raise InputError(f"{name}: file size: {len(raw)} bytes: not a Koala picture")
    out = bytearray()
    at = LOAD_ADDRESS_BYTES
    while len(out) < DATA_BYTES and at < len(raw):
        if raw[at] == GG_ESCAPE:
            if at + GG_RUN > len(raw):
                raise InputError(f"{name}: GG run at byte {at}: needs {GG_RUN} bytes ($FE, value, count), the file "
                                 f"ends at byte {len(raw)}")
            value, count = raw[at + 1], raw[at + 2]
            out += bytes([value]) * min(count, DATA_BYTES - len(out))
            at += GG_RUN
        else:
            out.append(raw[at])
            at += 1
    if len(out) < DATA_BYTES:
        raise InputError(f"{name}: file size: {len(raw)} bytes: not a Koala picture ({FILE_BYTES} bytes, or "
                         f"{DATA_BYTES} without the load address), and as a compressed (GG) picture it unpacks "
                         f"to {len(out)} of {DATA_BYTES} bytes")
    return bytes(out), at


def looks_like_koala(raw: bytes) -> bool:
    """A plain Koala picture by its size, or a GG picture loading at $6000 whose stream unpacks to
    exactly 10001 bytes and ends with the file."""
    if _plain_koala(raw):
        return True
    if not (LOAD_ADDRESS_BYTES < len(raw) < DATA_BYTES and (raw[0] | raw[1] << 8) == LOAD_ADDRESSES[0]):
        return False
    try:
        return unpack_gg(raw)[1] == len(raw)
    except InputError:
        return False


def koala_from_bytes(raw: bytes, name: str = "Koala picture") -> KoalaPicture:
    """A Koala picture's bytes (with or without its load address, or GG-compressed) -> its parts."""
    if not _plain_koala(raw):
        if len(raw) >= DATA_BYTES:
            raise InputError(f"{name}: file size: {len(raw)} bytes: a Koala picture is {FILE_BYTES} bytes (load "
                             f"address $6000, 8000 bitmap, 1000 screen, 1000 colour, 1 background) or {DATA_BYTES} "
                             f"without the load address, or a compressed (GG) picture of fewer than {DATA_BYTES} bytes")
        data, end = unpack_gg(raw, name)
        if len(raw) - end > MAX_PADDING:
            raise InputError(f"{name}: file size: {len(raw)} bytes: as a compressed (GG) picture it is whole at byte "
                             f"{end}, {len(raw) - end} bytes before the end of the file (at most {MAX_PADDING} may "
                             f"follow): not a Koala picture")
        return _parts(data, raw[0] | raw[1] << 8)
    load = None
    data = raw
    if len(raw) != DATA_BYTES:
        load = raw[0] | raw[1] << 8
        data = raw[LOAD_ADDRESS_BYTES:LOAD_ADDRESS_BYTES + DATA_BYTES]
    return _parts(data, load)


def _parts(data: bytes, load: int | None) -> KoalaPicture:
    values = np.frombuffer(data, dtype=np.uint8)
    screen_at = BITMAP_BYTES
    colour_at = screen_at + SCREEN_CELLS
    return KoalaPicture(values[:screen_at].copy(), values[screen_at:colour_at].copy(),
                        values[colour_at:colour_at + SCREEN_CELLS] & COLOR_MASK,
                        int(values[-1]) & COLOR_MASK, load)
