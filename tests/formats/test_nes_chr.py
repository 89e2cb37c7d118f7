"""NES pattern data from .chr (4 and 8 KiB) and .nes files; samples built from the nesdev wiki's
iNES layout and the 2bpp tile format (plane 0 bytes 0-7, plane 1 bytes 8-15)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from retro.errors import InputError
from retro.loaders.gfx_chr import chr_from_bytes

SOLID_TILE = bytes([0xFF] * 16)   # both planes set: colour 3 in all 64 pixels
CHR_8K = bytes(range(256)) * 32


def ines(prg_banks: int, chr_rom: bytes, trainer: bool) -> bytes:
    header = b"NES\x1a" + bytes([prg_banks, len(chr_rom) // 8192, 0x04 if trainer else 0, 0]) + bytes(8)
    return header + (b"\x77" * 512 if trainer else b"") + b"\xea" * (prg_banks * 16384) + chr_rom


def test_eight_kib_as_is():
    assert chr_from_bytes(CHR_8K, "a.chr") == CHR_8K


@pytest.mark.parametrize("table", [0, 1])
def test_four_kib_placed_in_one_table(table):
    data = chr_from_bytes(CHR_8K[:4096], "a.chr", table)
    assert data[table * 4096:(table + 1) * 4096] == CHR_8K[:4096]
    assert data[(1 - table) * 4096:(2 - table) * 4096] == bytes(4096)


@pytest.mark.parametrize("prg_banks, trainer", [(1, False), (2, False), (1, True)])
def test_chr_from_nes_after_header_trainer_and_prg(prg_banks, trainer):
    assert chr_from_bytes(ines(prg_banks, CHR_8K, trainer), "g.nes") == CHR_8K


@pytest.mark.parametrize("raw, message", [
    (bytes(5000), "5000 bytes: a CHR file is 4 KiB"),
    (ines(1, b"", False), "CHR RAM"),
    (ines(1, CHR_8K, False)[:-1], "CHR ROM starts at byte 16400, the file ends at 24591"),
])
def test_bad_chr_one_line(raw, message):
    with pytest.raises(InputError, match=message):
        chr_from_bytes(raw, "x.chr")


SCENE = """chip = "nes"
[ppu]
ctrl = 0x08        # sprites from $1000, background from $0000
[[oam]]
y = 99
tile = 0
x = 100
[chr]
file = "sprite_table.chr"
{table}
tiles = {{ "0:0" = ["33333333", "33333333", "33333333", "33333333", "33333333", "33333333", "33333333", "33333333"] }}
"""


@pytest.mark.parametrize("table_line, hit", [("table = 1", True), ("", False)])
def test_four_kib_file_in_a_scene(tmp_path, table_line, hit):
    # Background: tile 0 of table 0 solid everywhere. Sprite 0 is tile 0 of table 1, solid only if
    # the 4 KiB file went to table 1: then the hit is at its top-left pixel, line y + 1 = 100, x 100.
    (tmp_path / "sprite_table.chr").write_bytes(SOLID_TILE + bytes(4096 - 16))
    (tmp_path / "s.toml").write_text(SCENE.format(table=table_line))
    done = subprocess.run([sys.executable, "-m", "retro", "nes", str(tmp_path / "s.toml"), "--json"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["hit"] is hit
    if hit:
        assert (report["line"], report["x"]) == (100, 100)


def test_table_without_file_is_an_error(tmp_path):
    (tmp_path / "s.toml").write_text('chip = "nes"\n[[oam]]\ny = 1\ntile = 0\nx = 1\n[chr]\ntable = 1\n')
    done = subprocess.run([sys.executable, "-m", "retro", "nes", str(tmp_path / "s.toml")],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "chr.table" in done.stderr and len(done.stderr.strip().splitlines()) == 1
