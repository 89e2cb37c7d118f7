"""SpritePad sprite files (.spd), detected by content.

Layouts (from SpritePad's documented file formats, Subchrist Software):
- SpritePad 1.x: no magic. Byte 0 background colour ($D021), bytes 1-2 the shared multicolours
  ($D025, $D026), then 64-byte sprite blocks.
- SpritePad 2.0 beta ("SPD" format version 1): "SPD", version byte 1, sprite count - 1, animation
  count - 1, background, multicolour 1, multicolour 2, then the 64-byte blocks, then the animation
  table (not needed for collisions, so not read).
In both, the 64th byte of each block is the sprite's attribute: low nibble its colour ($D027+n),
bit 4 overlay (SpritePad 2 only), bit 7 multicolour.
SpritePad Pro's "SPD" versions 4 and 5 are refused with a one-line error: their header is not
implemented here.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.chips.vic.constants import SPRITE_BLOCK, SPRITE_BYTES
from retro.errors import InputError
from retro.fileio import read_bytes

SPD_MAGIC = b"SPD"
V1_HEADER = 3  # background, multicolour 1, multicolour 2
BETA_VERSION = 1
BETA_HEADER = 9  # magic, version, sprites - 1, animations - 1, three colours
ATTR_COLOUR_MASK = 0x0F
ATTR_OVERLAY = 0x10
ATTR_MULTICOLOR = 0x80


@dataclass(frozen=True)
class SpritePadSprite:
    data: bytes  # 63 bytes
    colour: int
    multicolor: bool
    overlay: bool


@dataclass(frozen=True)
class SpritePadFile:
    version: str  # "1" or "2.0 beta"
    background: int
    multicolor1: int
    multicolor2: int
    sprites: tuple[SpritePadSprite, ...]


KNOWN_SPD_VERSIONS = (1, 4, 5)  # 4 and 5 are recognised only to be refused by name


def looks_like_spd(raw: bytes) -> bool:
    """True for an "SPD" file of a known version or a headerless SpritePad 1 file (3 + 64n bytes).

    Raw sprite files are 63 or 64n bytes, so a length of 3 + 64n cannot be one of them."""
    if raw.startswith(SPD_MAGIC) and len(raw) > 3 and raw[3] in KNOWN_SPD_VERSIONS:
        return True
    return len(raw) > V1_HEADER and (len(raw) - V1_HEADER) % SPRITE_BLOCK == 0


def _sprites(blocks: bytes) -> tuple[SpritePadSprite, ...]:
    out = []
    for start in range(0, len(blocks), SPRITE_BLOCK):
        attr = blocks[start + SPRITE_BYTES]
        out.append(SpritePadSprite(blocks[start:start + SPRITE_BYTES], attr & ATTR_COLOUR_MASK,
                              bool(attr & ATTR_MULTICOLOR), bool(attr & ATTR_OVERLAY)))
    return tuple(out)


def parse_spd(raw: bytes, name: str = "sprite file") -> SpritePadFile:
    """SpritePad bytes -> sprites with their attributes and the shared colours."""
    if raw.startswith(SPD_MAGIC):
        if len(raw) < BETA_HEADER:
            raise InputError(f"{name}: SpritePad header is {len(raw)} bytes, needs {BETA_HEADER}")
        version = raw[3]
        if version != BETA_VERSION:
            raise InputError(f"{name}: SpritePad format version {version} is not supported "
                             f"(read: SpritePad 1.x and 2.0 beta version 1)")
        count = raw[4] + 1
        end = BETA_HEADER + count * SPRITE_BLOCK
        if len(raw) < end:
            raise InputError(f"{name}: SpritePad header says {count} sprites ({end} bytes), "
                             f"file has {len(raw)} bytes")
        return SpritePadFile("2.0 beta", raw[6] & 15, raw[7] & 15, raw[8] & 15,
                             _sprites(raw[BETA_HEADER:end]))
    if len(raw) <= V1_HEADER or (len(raw) - V1_HEADER) % SPRITE_BLOCK:
        raise InputError(f"{name}: not a SpritePad file: a SpritePad 1 file is 3 + 64n bytes, "
                         f"got {len(raw)}")
    return SpritePadFile("1", raw[0] & 15, raw[1] & 15, raw[2] & 15, _sprites(raw[V1_HEADER:]))


def read_spd(path: str | Path) -> SpritePadFile:
    return parse_spd(read_bytes(path, "sprite file"), str(path))
