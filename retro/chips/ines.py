"""iNES and NES 2.0 cartridge images (.nes): a 16-byte header, PRG ROM, CHR ROM. Only what the probes need.

iNES (nesdev wiki "INES"): bytes 0-3 "NES" $1A; byte 4 PRG ROM size in 16 KiB units; byte 5 CHR
ROM size in 8 KiB units (0 = the board has CHR RAM); byte 6 bit 0 nametable arrangement (0:
horizontal mirroring, CIRAM A10 = PPU A11; 1: vertical mirroring, CIRAM A10 = PPU A10), bit 1
battery, bit 2 a 512-byte trainer between the header and PRG ROM (loaded at $7000), bit 3
four-screen, bits 4-7 mapper low nibble; byte 7 bits 4-7 mapper high nibble; bytes 8-15 zero.
Mapper 0 (NROM) holds 16 or 32 KiB of PRG at $8000-$FFFF (16 KiB mirrored) and 8 KiB of CHR.

NES 2.0 (nesdev wiki "NES 2.0"), told apart by byte 7 bits 2-3 = %10: byte 7 bits 0-1 console type
(0 NES/Famicom, 1 Vs. System, 2 PlayChoice-10, 3 extended: byte 13 says which); byte 8 bits 0-3
mapper bits 8-11, bits 4-7 submapper; byte 9 bits 0-3 / 4-7 the PRG / CHR ROM size's high bits
($F: byte 4 / 5 is EEEEEEMM, 2^E x (2 MM + 1) bytes); byte 10 PRG-RAM (bits 0-3) and PRG-NVRAM
(bits 4-7) and byte 11 CHR-RAM and CHR-NVRAM, each a shift count (0 none, else 64 << n bytes);
byte 12 bits 0-1 CPU/PPU timing (0 RP2C02 NTSC, 1 RP2C07 PAL, 2 multiple-region, 3 UA6538
"Dendy"); byte 14 bits 0-1 the number of miscellaneous ROMs after CHR ROM; byte 15 bits 0-5 the
default expansion device (0 unspecified, 1 standard controllers).
`unmodelled` names each header field that promises hardware retro's NES does not have.
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.errors import InputError

INES_MAGIC = b"NES\x1a"
HEADER_SIZE = 16
PRG_BANK_SIZE = 0x4000
CHR_BANK_SIZE = 0x2000
TRAINER_SIZE = 512
FLAG6_VERTICAL_MIRRORING = 0x01
FLAG6_TRAINER = 0x04
FLAG6_FOUR_SCREEN = 0x08
MAPPER_NIBBLE_SHIFT = 4
NROM = 0
NROM_PRG_SIZES = (PRG_BANK_SIZE, 2 * PRG_BANK_SIZE)
HEADER_MIRRORING = {"horizontal": 0, "vertical": FLAG6_VERTICAL_MIRRORING}

NES2_ID_MASK, NES2_ID = 0x0C, 0x08  # byte 7 bits 2-3
SIZE_EXPONENT_NIBBLE = 0x0F  # byte 9: the size byte is in exponent-multiplier form
RAM_SHIFT_BASE = 64  # a RAM size is 64 << shift count bytes (0: none)
CONSOLE_TYPES = ("NES/Famicom", "Vs. System", "PlayChoice-10", "an extended console type")
TIMINGS = ("ntsc", "pal", "multiple-region", "dendy")  # RP2C02, RP2C07, both, UA6538
EXPANSION_CONTROLLERS = (0, 1)  # byte 15: unspecified, standard NES/Famicom controllers
# what retro's NES has: 8 KiB of RAM at $6000-$7FFF (the bus is RAM there) and an 8 KiB pattern
# space the program may write like CHR RAM (retro.chips.ppu.device)
PRG_RAM_MODELLED = 0x2000
CHR_SPACE = 0x2000


@dataclass(frozen=True)
class InesHeader:
    prg_size: int
    chr_size: int
    mirroring: str
    mapper: int
    trainer: bool = False
    nes2: bool = False
    # NES 2.0 only (0 in an iNES header)
    submapper: int = 0
    console_type: int = 0
    prg_ram: int = 0    # bytes, volatile and non-volatile together
    chr_ram: int = 0
    timing: str = "ntsc"
    misc_roms: int = 0
    expansion_device: int = 0

    @property
    def prg_start(self) -> int:
        """Where PRG ROM starts in the file: after the header and the trainer."""
        return HEADER_SIZE + (TRAINER_SIZE if self.trainer else 0)


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


def _rom_size(low: int, high: int, unit: int) -> int:
    if high == SIZE_EXPONENT_NIBBLE:
        return (1 << (low >> 2)) * ((low & 3) * 2 + 1)
    return ((high << 8) | low) * unit


def _ram_size(shift: int) -> int:
    return RAM_SHIFT_BASE << shift if shift else 0


def parse_header(data: bytes, source: str = "iNES image") -> InesHeader:
    if len(data) < HEADER_SIZE or data[:4] != INES_MAGIC:
        raise InputError(f"{source}: not an iNES image (no 'NES\\x1a' header)")
    flags6, flags7 = data[6], data[7]
    mirroring = "four-screen" if flags6 & FLAG6_FOUR_SCREEN else (
        "vertical" if flags6 & FLAG6_VERTICAL_MIRRORING else "horizontal")
    mapper = (flags6 >> MAPPER_NIBBLE_SHIFT) | (flags7 & 0xF0)
    trainer = bool(flags6 & FLAG6_TRAINER)
    if flags7 & NES2_ID_MASK != NES2_ID:
        return InesHeader(prg_size=data[4] * PRG_BANK_SIZE, chr_size=data[5] * CHR_BANK_SIZE, mirroring=mirroring,
                          mapper=mapper, trainer=trainer)
    return InesHeader(
        prg_size=_rom_size(data[4], data[9] & 0x0F, PRG_BANK_SIZE),
        chr_size=_rom_size(data[5], data[9] >> 4, CHR_BANK_SIZE),
        mirroring=mirroring, mapper=mapper | (data[8] & 0x0F) << 8, trainer=trainer, nes2=True,
        submapper=data[8] >> 4, console_type=flags7 & 0x03,
        prg_ram=_ram_size(data[10] & 0x0F) + _ram_size(data[10] >> 4),
        chr_ram=_ram_size(data[11] & 0x0F) + _ram_size(data[11] >> 4),
        timing=TIMINGS[data[12] & 0x03], misc_roms=data[14] & 0x03, expansion_device=data[15] & 0x3F)


def unmodelled(header: InesHeader) -> list[tuple[str, str]]:
    """(header field, what it promises) for each piece of cartridge or console hardware the header
    asks for that retro's NES (2A03, PPU, 2 KiB RAM, NROM) does not have; empty when it runs as is."""
    found = []
    if header.trainer:
        found.append(("byte 6 bit 2 (trainer)", f"a {TRAINER_SIZE}-byte trainer to be loaded at $7000, "
                                                "which is not loaded"))
    if header.mirroring == "four-screen":
        found.append(("byte 6 bit 3 (four-screen)", "four-screen nametable RAM, which is not modelled"))
    if not header.nes2:
        return found
    if header.console_type:
        found.append(("byte 7 (console type)", f"{CONSOLE_TYPES[header.console_type]}, not a NES/Famicom"))
    if header.submapper:
        found.append(("byte 8 (submapper)", f"submapper {header.submapper} of mapper {header.mapper}, "
                                            "which is not modelled"))
    if header.prg_ram > PRG_RAM_MODELLED:
        found.append(("byte 10 (PRG-RAM size)", f"{header.prg_ram} bytes of PRG-RAM, more than the "
                                                f"{PRG_RAM_MODELLED} at $6000-$7FFF"))
    if header.chr_size + header.chr_ram > CHR_SPACE:
        found.append(("byte 11 (CHR-RAM size)", f"{header.chr_ram} bytes of CHR-RAM beside {header.chr_size} of "
                                                f"CHR ROM, more than the PPU's {CHR_SPACE}-byte pattern space"))
    if header.timing == "dendy":
        found.append(("byte 12 (CPU/PPU timing)", "the UA6538 'Dendy' timing, which is not modelled (NTSC and PAL are)"))
    if header.misc_roms:
        found.append(("byte 14 (miscellaneous ROMs)", f"{header.misc_roms} miscellaneous ROM(s), which are not modelled"))
    if header.expansion_device not in EXPANSION_CONTROLLERS:
        found.append(("byte 15 (default expansion device)", f"expansion device ${header.expansion_device:02X}, "
                                                            "which is not modelled"))
    return found


def nrom_prg(data: bytes, source: str = "iNES image") -> tuple[InesHeader, bytes]:
    """An NROM image's header and the 32 KiB the CPU sees at $8000-$FFFF (a 16 KiB PRG ROM twice):
    the one reading of an NROM cartridge's PRG ROM, for programs and for cartridges. InputError
    naming `source` for another mapper, hardware the header promises that is not modelled, a PRG
    size NROM does not have, or a file shorter than its header says."""
    header = parse_header(data, source)
    if header.mapper != NROM:
        raise InputError(f"{source}: iNES mapper {header.mapper} is not supported; only mapper 0 (NROM) is")
    problems = unmodelled(header)
    if problems:
        field, promise = problems[0]
        raise InputError(f"{source}: {'NES 2.0' if header.nes2 else 'iNES'} header {field}: {promise}")
    if header.prg_size not in NROM_PRG_SIZES:
        raise InputError(f"{source}: NROM needs 16 or 32 KiB of PRG ROM, the header says {header.prg_size} bytes")
    start = header.prg_start
    if len(data) < start + header.prg_size + header.chr_size:
        raise InputError(f"{source}: truncated: the header promises {header.prg_size} bytes of PRG ROM and "
                         f"{header.chr_size} of CHR ROM, the file has {max(0, len(data) - start)} after the header")
    prg = data[start:start + header.prg_size]
    return header, bytes(prg * (2 * PRG_BANK_SIZE // len(prg)))  # 16 KiB is mirrored at $8000 and $C000
