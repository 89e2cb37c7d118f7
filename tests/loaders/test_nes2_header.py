"""NES 2.0 headers (nesdev wiki "NES 2.0"): sizes read from bytes 4, 5 and 9 (both notations), and
every field that promises hardware retro's NES does not have refused by name, in one line."""

from __future__ import annotations

import pytest

from retro.chips.ines import nrom_image, parse_header, unmodelled
from retro.chips.ppu.constants import CHR_SIZE
from retro.errors import InputError
from retro.loaders import load_program
from retro.loaders.gfx_chr import chr_from_bytes

PRG = bytes(range(256)) * 64  # 16 KiB
CHR = bytes([0x5A]) * 0x2000


def nes2(image: bytes, **bytes_at: int) -> bytes:
    """The image with byte 7 marked NES 2.0 and the given header bytes (b7=..., b8=...) set."""
    data = bytearray(image)
    data[7] = (data[7] & 0xF3) | 0x08
    for name, value in bytes_at.items():
        index = int(name[1:])
        data[index] = value | (0x08 if index == 7 else 0)
    return bytes(data)


def test_a_plain_nes2_nrom_image_loads_like_its_ines_twin(tmp_path):
    path = tmp_path / "plain.nes"
    path.write_bytes(nes2(nrom_image(PRG, CHR, "vertical"), b12=1))  # PAL timing is modelled (a scene's video)
    header = parse_header(path.read_bytes())
    assert (header.nes2, header.mapper, header.prg_size, header.chr_size, header.timing) == (
        True, 0, 0x4000, 0x2000, "pal")
    assert load_program(path).code == PRG * 2


def test_sizes_in_exponent_multiplier_form():
    # byte 9 nibble $F: byte 4 = EEEEEEMM -> 2^E * (2*MM + 1); 0x38 = E 14, MM 0 -> 16 KiB
    header = parse_header(nes2(nrom_image(PRG, CHR, "vertical"), b4=0x38, b9=0x0F))
    assert header.prg_size == 0x4000
    header = parse_header(nes2(nrom_image(PRG, CHR, "vertical"), b4=0x01, b9=0x01))  # MSB nibble 1: 257 banks
    assert header.prg_size == 257 * 0x4000
    header = parse_header(nes2(nrom_image(PRG, CHR, "vertical"), b5=0x05, b9=0xF0))  # E 1, MM 1: 2 * 3 bytes
    assert header.chr_size == 6


def test_chr_found_after_a_nes2_prg_size():
    image = nes2(nrom_image(PRG * 2, CHR, "vertical"), b4=0x3C, b9=0x0F)  # E 15, MM 0: 32 KiB
    assert chr_from_bytes(image, "g.nes") == CHR[:CHR_SIZE]


@pytest.mark.parametrize("field, value, needle", [
    ("b7", 0x01, r"byte 7 \(console type\): Vs\. System, not a NES/Famicom"),
    ("b7", 0x02, r"byte 7 \(console type\): PlayChoice-10"),
    ("b7", 0x03, r"byte 7 \(console type\): an extended console type"),
    ("b8", 0x10, r"byte 8 \(submapper\): submapper 1 of mapper 0"),
    ("b10", 0x08, r"byte 10 \(PRG-RAM size\): 16384 bytes of PRG-RAM"),
    ("b10", 0x77, r"byte 10 \(PRG-RAM size\): 16384 bytes"),  # 8 KiB volatile + 8 KiB battery-backed
    ("b11", 0x07, r"byte 11 \(CHR-RAM size\): 8192 bytes of CHR-RAM beside 8192 of CHR ROM"),
    ("b12", 0x03, r"byte 12 \(CPU/PPU timing\): the UA6538 'Dendy' timing"),
    ("b14", 0x01, r"byte 14 \(miscellaneous ROMs\): 1 miscellaneous ROM"),
    ("b15", 0x08, r"byte 15 \(default expansion device\): expansion device \$08"),
    ("b8", 0x01, r"iNES mapper 256 is not supported"),
])
def test_unmodelled_hardware_is_refused_by_field(tmp_path, field, value, needle):
    path = tmp_path / "x.nes"
    path.write_bytes(nes2(nrom_image(PRG, CHR, "vertical"), **{field: value}))
    with pytest.raises(InputError, match=f"^{path}: (NES 2.0 header )?{needle}") as error:
        load_program(path)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("field, value", [("b10", 0x07), ("b10", 0x70), ("b12", 0x02), ("b15", 0x01), ("b13", 0xFF)])
def test_hardware_retro_has_is_accepted(field, value):
    # 8 KiB of PRG-RAM or battery RAM at $6000, multiple-region timing, standard controllers;
    # byte 13 means nothing for a NES/Famicom console type
    assert unmodelled(parse_header(nes2(nrom_image(PRG, CHR, "vertical"), **{field: value}))) == []


@pytest.mark.parametrize("flags6, needle", [(0x04, r"byte 6 bit 2 \(trainer\)"), (0x08, r"byte 6 bit 3 \(four-screen\)")])
def test_ines_trainer_and_four_screen_are_refused_for_programs(tmp_path, flags6, needle):
    image = bytearray(nrom_image(PRG, CHR, "horizontal"))
    image[6] |= flags6
    if flags6 == 0x04:
        image[16:16] = bytes(512)
    path = tmp_path / "t.nes"
    path.write_bytes(bytes(image))
    with pytest.raises(InputError, match=f"^{path}: iNES header {needle}"):
        load_program(path)
