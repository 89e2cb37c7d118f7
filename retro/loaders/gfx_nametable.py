"""NES nametable files (.nam): one nametable as the PPU holds it, attribute table included.

Layout (nesdev wiki, "PPU nametables" and "PPU attribute tables"): a nametable is 1024 bytes,
32 x 30 tile numbers (960 bytes, row by row from the top left), then the 64-byte attribute table,
an 8 x 8 array of bytes each covering 4 x 4 tiles; the byte's bits 1-0 give the palette of its
top-left 2 x 2 tiles, bits 3-2 the top-right, 5-4 the bottom-left, 7-6 the bottom-right. A `.nam`
file (NES Screen Arranger, NES Screen Tool) is those 1024 bytes as they would be written to $2000.

Read by size, each a whole number of nametables in that layout:
- 1024 bytes: one nametable;
- 960 bytes: its 32 x 30 tile numbers only (the attribute table left out): attributes read as 0;
- 2048 or 4096 bytes: two or four nametables back to back, as the PPU addresses them from $2000
  ($2000, $2400, $2800, $2C00; nesdev wiki "PPU nametables", "PPU memory map").
`nametables_from_bytes` gives every nametable of a file; a scene's `[[nametable]]` takes one
(`nametable_from_bytes`: a 960- or 1024-byte file).

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


MULTI_COUNTS = (2, 4)  # nametables in a 2048- or 4096-byte file
PPU_ADDRESSES = (0x2000, 0x2400, 0x2800, 0x2C00)


@dataclass(frozen=True)
class NametableFile:
    tiles: bytes       # 960 tile numbers
    attributes: bytes  # 64 attribute bytes
    has_attributes: bool = True  # False: a 960-byte file (attributes are 0)

    def palette(self, col: int, row: int) -> int:
        """The background palette (0-3) of tile (col, row), from its attribute byte."""
        return palette_at(self.attributes, col, row)


def palette_at(attributes: bytes, col: int, row: int) -> int:
    byte = attributes[(row // TILES_PER_ATTRIBUTE) * ATTRIBUTE_COLUMNS + col // TILES_PER_ATTRIBUTE]
    shift = ((row % TILES_PER_ATTRIBUTE) // TILES_PER_QUADRANT * 2
             + (col % TILES_PER_ATTRIBUTE) // TILES_PER_QUADRANT) * 2
    return (byte >> shift) & 3


def nametables_from_bytes(raw: bytes, name: str = "nametable file") -> tuple[NametableFile, ...]:
    """Every nametable of a .nam file (see the module notes for the sizes)."""
    size = len(raw)
    if size == NAMETABLE_TILES:
        return (NametableFile(bytes(raw), bytes(ATTRIBUTE_BYTES), False),)
    if size % NAMETABLE_SIZE or size // NAMETABLE_SIZE not in (1,) + MULTI_COUNTS:
        raise InputError(f"{name}: file size: {size} bytes: a nametable file is {NAMETABLE_SIZE} bytes "
                         f"({NAMETABLE_TILES} tile numbers, 32 x 30, then {ATTRIBUTE_BYTES} attribute bytes), "
                         f"{NAMETABLE_TILES} (tile numbers only), or 2 or 4 nametables of {NAMETABLE_SIZE} bytes")
    return tuple(NametableFile(bytes(raw[at:at + NAMETABLE_TILES]), bytes(raw[at + NAMETABLE_TILES:at + NAMETABLE_SIZE]))
                 for at in range(0, size, NAMETABLE_SIZE))


def nametable_from_bytes(raw: bytes, name: str = "nametable file") -> NametableFile:
    """One nametable: a 1024-byte file, or a 960-byte one without the attribute table."""
    tables = nametables_from_bytes(raw, name)
    if len(tables) > 1:
        where = ", ".join(f"${a:04X}" for a in PPU_ADDRESSES[:len(tables)])
        raise InputError(f"{name}: file size: {len(raw)} bytes hold {len(tables)} nametables ({where}): a "
                         f"[[nametable]] file is one nametable, {NAMETABLE_SIZE} bytes or {NAMETABLE_TILES} without "
                         f"attributes; split the file into {NAMETABLE_SIZE}-byte parts")
    return tables[0]
