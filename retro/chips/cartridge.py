"""An NROM (mapper 0) cartridge as the console sees it: PRG ROM on the CPU's bus, CHR ROM or CHR RAM
on the PPU's, and the nametable mirroring its board is wired for.

Format (nesdev wiki "INES", "NROM"): a 16-byte header (`retro.chips.ines`), a 512-byte trainer when
flags 6 bit 2 is set, PRG ROM (16 or 32 KiB; 16 KiB appears at $8000 and again at $C000), then CHR
ROM (8 KiB), or none: the board then has 8 KiB of CHR RAM the program fills through $2007.
Writes to PRG ROM do nothing (NROM has no registers); PRG RAM at $6000-$7FFF, which many NROM
test ROMs use (blargg's report their results there), is taken to be present.
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.chips.ines import CHR_BANK_SIZE, nrom_prg
from retro.errors import InputError

PRG_START = 0x8000              # PRG ROM fills $8000-$FFFF
NROM_CHR_SIZES = (0, CHR_BANK_SIZE)  # 0: CHR RAM on the board
CARTRIDGE_MIRRORINGS = ("horizontal", "vertical")


@dataclass(frozen=True)
class NromCartridge:
    prg: bytes          # the 32 KiB the CPU sees at $8000-$FFFF (a 16 KiB ROM twice)
    chr: bytes          # 8 KiB: the CHR ROM, or the CHR RAM's power-on content (zeros)
    chr_ram: bool       # the board has CHR RAM (the header gives no CHR ROM)
    mirroring: str      # "horizontal" or "vertical"
    source: str


def read_nrom(data: bytes, source: str = "iNES image") -> NromCartridge:
    """An iNES image -> NromCartridge; InputError naming `source` for anything but an NROM board."""
    header, prg = nrom_prg(data, source)
    if header.chr_size not in NROM_CHR_SIZES:
        raise InputError(f"{source}: NROM has 8 KiB of CHR ROM or none (CHR RAM), the header says "
                         f"{header.chr_size} bytes")
    if header.mirroring not in CARTRIDGE_MIRRORINGS:
        raise InputError(f"{source}: {header.mirroring} mirroring is not supported on NROM "
                         f"(only {' or '.join(CARTRIDGE_MIRRORINGS)})")
    chr_start = header.prg_start + header.prg_size
    chr_data = data[chr_start:chr_start + header.chr_size] if header.chr_size else bytes(CHR_BANK_SIZE)
    return NromCartridge(prg=prg, chr=bytes(chr_data),
                         chr_ram=not header.chr_size, mirroring=header.mirroring, source=source)
