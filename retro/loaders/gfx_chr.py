"""NES pattern data (CHR) from a file, detected by content -> the PPU's 8 KiB pattern space.

- an iNES or NES 2.0 image (`NES` $1A; sizes as retro.chips.ines reads them): the first 8 KiB CHR
  ROM bank, found after the 16-byte header, the 512-byte trainer when flag 6 bit 2 is set, and the
  PRG ROM (nesdev wiki "INES", "NES 2.0"); a board with
  CHR RAM (CHR size 0) has no pattern data in the file, which is an error;
- 8 KiB: both pattern tables ($0000 and $1000);
- 4 KiB: one pattern table, placed at the table the caller names (the other stays zero).
"""

from __future__ import annotations

from retro.chips.ines import INES_MAGIC, parse_header
from retro.chips.ppu.constants import CHR_SIZE, PATTERN_TABLE_SIZE
from retro.errors import InputError


def chr_from_bytes(content: bytes, name: str, table: int = 0) -> bytes:
    """A .chr (4 or 8 KiB) or .nes file's bytes -> 8 KiB of pattern data."""
    if content.startswith(INES_MAGIC):
        header = parse_header(content, name)
        if header.chr_size == 0:
            raise InputError(f"{name}: the cartridge has CHR RAM (CHR ROM size 0): no pattern data in the file")
        start = header.prg_start + header.prg_size
        if len(content) < start + CHR_SIZE:
            raise InputError(f"{name}: the header says CHR ROM starts at byte {start}, "
                             f"the file ends at {len(content)}")
        return bytes(content[start:start + CHR_SIZE])
    if len(content) == CHR_SIZE:
        return bytes(content)
    if len(content) == PATTERN_TABLE_SIZE:
        data = bytearray(CHR_SIZE)
        data[table * PATTERN_TABLE_SIZE:(table + 1) * PATTERN_TABLE_SIZE] = content
        return bytes(data)
    raise InputError(f"{name}: {len(content)} bytes: a CHR file is 4 KiB (one pattern table) or 8 KiB, "
                     f"or an iNES .nes image")
