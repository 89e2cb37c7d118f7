"""iNES cartridge images (.nes): a 16-byte header, PRG ROM, CHR ROM. Only what the probes need.

Format (nesdev wiki "INES"): bytes 0-3 "NES" $1A; byte 4 PRG ROM size in 16 KiB units; byte 5
CHR ROM size in 8 KiB units (0 = the board has CHR RAM); byte 6 bit 0 nametable arrangement
(0: horizontal mirroring, CIRAM A10 = PPU A11; 1: vertical mirroring, CIRAM A10 = PPU A10), bit 1
battery, bit 2 trainer, bit 3 four-screen, bits 4-7 mapper low nibble; byte 7 bits 4-7 mapper
high nibble; bytes 8-15 zero. Mapper 0 (NROM) holds 16 or 32 KiB of PRG at $8000-$FFFF (16 KiB
mirrored) and 8 KiB of CHR.
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.errors import InputError

INES_MAGIC = b"NES\x1a"
HEADER_SIZE = 16
PRG_BANK_SIZE = 0x4000
CHR_BANK_SIZE = 0x2000
FLAG6_VERTICAL_MIRRORING = 0x01
FLAG6_FOUR_SCREEN = 0x08
MAPPER_NIBBLE_SHIFT = 4
NROM = 0
NROM_PRG_SIZES = (PRG_BANK_SIZE, 2 * PRG_BANK_SIZE)
HEADER_MIRRORING = {"horizontal": 0, "vertical": FLAG6_VERTICAL_MIRRORING}


@dataclass(frozen=True)
class InesHeader:
    prg_size: int
    chr_size: int
    mirroring: str
    mapper: int


def nrom_image(prg: bytes, chr_rom: bytes, mirroring: str) -> bytes:
    """An NROM (mapper 0) image: 16 or 32 KiB PRG, 8 KiB CHR ROM, horizontal or vertical mirroring."""
    if len(prg) not in NROM_PRG_SIZES:
        raise InputError(f"NROM PRG must be 16 or 32 KiB, got {len(prg)} bytes")
    if len(chr_rom) != CHR_BANK_SIZE:
        raise InputError(f"NROM CHR ROM must be 8 KiB, got {len(chr_rom)} bytes")
    if mirroring not in HEADER_MIRRORING:
        raise InputError(f"NROM mirroring must be one of {', '.join(HEADER_MIRRORING)}, got {mirroring!r}")
    header = INES_MAGIC + bytes([len(prg) // PRG_BANK_SIZE, len(chr_rom) // CHR_BANK_SIZE,
                                 HEADER_MIRRORING[mirroring] | (NROM << MAPPER_NIBBLE_SHIFT), 0])
    return header.ljust(HEADER_SIZE, b"\0") + bytes(prg) + bytes(chr_rom)


def parse_header(data: bytes, source: str = "iNES image") -> InesHeader:
    if len(data) < HEADER_SIZE or data[:4] != INES_MAGIC:
        raise InputError(f"{source}: not an iNES image (no 'NES\\x1a' header)")
    flags6, flags7 = data[6], data[7]
    mirroring = "four-screen" if flags6 & FLAG6_FOUR_SCREEN else (
        "vertical" if flags6 & FLAG6_VERTICAL_MIRRORING else "horizontal")
    return InesHeader(prg_size=data[4] * PRG_BANK_SIZE, chr_size=data[5] * CHR_BANK_SIZE, mirroring=mirroring,
                      mapper=(flags6 >> MAPPER_NIBBLE_SHIFT) | (flags7 & 0xF0))
