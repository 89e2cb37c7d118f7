"""NES nametable files (.nam): one nametable as the PPU holds it, attribute table included.

Layout (nesdev wiki, "PPU nametables" and "PPU attribute tables"): a nametable is 1024 bytes,
32 x 30 tile numbers (960 bytes, row by row from the top left), then the 64-byte attribute table,
an 8 x 8 array of bytes each covering 4 x 4 tiles; the byte's bits 1-0 give the palette of its
top-left 2 x 2 tiles, bits 3-2 the top-right, 5-4 the bottom-left, 7-6 the bottom-right. A `.nam`
file (NES Screen Arranger, NES Screen Tool) is those 1024 bytes as they would be written to $2000.

The palette never decides a sprite-zero hit, but the attribute bytes can: a Y scroll of 240-255
shows them as tiles (docs/nes.md, "Scrolling").
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.chips.ppu.constants import NAMETABLE_COLUMNS, NAMETABLE_ROWS, NAMETABLE_SIZE
from retro.errors import InputError

NAMETABLE_TILES = NAMETABLE_COLUMNS * NAMETABLE_ROWS  # 960
ATTRIBUTE_BYTES = NAMETABLE_SIZE - NAMETABLE_TILES    # 64
ATTRIBUTE_COLUMNS = 8
TILES_PER_ATTRIBUTE = 4  # an attribute byte covers 4 x 4 tiles
TILES_PER_QUADRANT = 2


@dataclass(frozen=True)
class NametableFile:
    tiles: bytes       # 960 tile numbers
    attributes: bytes  # 64 attribute bytes

    def palette(self, col: int, row: int) -> int:
        """The background palette (0-3) of tile (col, row), from its attribute byte."""
        return palette_at(self.attributes, col, row)


def palette_at(attributes: bytes, col: int, row: int) -> int:
    byte = attributes[(row // TILES_PER_ATTRIBUTE) * ATTRIBUTE_COLUMNS + col // TILES_PER_ATTRIBUTE]
    shift = ((row % TILES_PER_ATTRIBUTE) // TILES_PER_QUADRANT * 2
             + (col % TILES_PER_ATTRIBUTE) // TILES_PER_QUADRANT) * 2
    return (byte >> shift) & 3


def nametable_from_bytes(raw: bytes, name: str = "nametable file") -> NametableFile:
    if len(raw) != NAMETABLE_SIZE:
        raise InputError(f"{name}: file size: {len(raw)} bytes: a nametable file is {NAMETABLE_SIZE} bytes "
                         f"({NAMETABLE_TILES} tile numbers, 32 x 30, then {ATTRIBUTE_BYTES} attribute bytes)")
    return NametableFile(bytes(raw[:NAMETABLE_TILES]), bytes(raw[NAMETABLE_TILES:]))
