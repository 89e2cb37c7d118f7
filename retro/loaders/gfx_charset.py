"""C64 charsets from a file, detected by content -> the 2048 bytes of 256 glyphs.

A glyph is 8 bytes, top row first. Raw charset files are the glyph bytes alone (8n bytes); `.64c`
files are the same bytes behind a 2-byte load address, as every C64 PRG file is (so 2 + 8n
bytes). The lengths differ modulo 8, so the content decides. Files of fewer than 256 glyphs fill
codes 0..n-1 and leave the rest zero.
"""

from __future__ import annotations

from retro.chips.vic.constants import CHAR_HEIGHT, CHARSET_BYTES
from retro.errors import InputError

LOAD_ADDRESS_BYTES = 2


def charset_from_bytes(raw: bytes, name: str) -> bytes:
    """A raw or .64c charset file's bytes -> 2048 bytes."""
    glyphs = raw[LOAD_ADDRESS_BYTES:] if len(raw) % CHAR_HEIGHT == LOAD_ADDRESS_BYTES else raw
    if not glyphs or len(glyphs) % CHAR_HEIGHT or len(glyphs) > CHARSET_BYTES:
        raise InputError(f"{name}: {len(raw)} bytes: a charset is 8 bytes per character (up to 256), "
                         f"raw or behind a 2-byte load address (.64c)")
    return bytes(glyphs).ljust(CHARSET_BYTES, b"\0")
