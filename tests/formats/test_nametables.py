"""NES .nam nametables (nesdev wiki "PPU nametables", "PPU attribute tables"): 960 tile numbers,
32 x 30 row by row, then the 64-byte attribute table (8 x 8 bytes, each covering 4 x 4 tiles:
bits 1-0 top left, 3-2 top right, 5-4 bottom left, 7-6 bottom right). Samples are built from that
layout; a scene using one gives the sprite-zero hit the tiles, and with a Y scroll of 240 the
attribute bytes, put there."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

from retro.chips.ppu.hit import sprite_zero_hit
from retro.errors import InputError
from retro.loaders.gfx_nametable import nametable_from_bytes, nametables_from_bytes, palette_at
from retro.scenes import load_scene

SOLID = 3  # the scene's CHR tile 3 is solid


def nam(tiles: dict[tuple[int, int], int] | None = None, attributes: dict[int, int] | None = None) -> bytes:
    table = bytearray(1024)
    for (col, row), tile in (tiles or {}).items():
        table[row * 32 + col] = tile
    for index, value in (attributes or {}).items():
        table[960 + index] = value
    return bytes(table)


def test_tiles_and_attributes_are_split():
    loaded = nametable_from_bytes(nam({(16, 15): 7, (31, 29): 9}, {0: 0xE4, 63: 0x55}), "t.nam")
    assert loaded.tiles[15 * 32 + 16] == 7 and loaded.tiles[959] == 9 and len(loaded.tiles) == 960
    assert loaded.attributes[0] == 0xE4 and loaded.attributes[63] == 0x55 and len(loaded.attributes) == 64


@pytest.mark.parametrize("col, row, palette", [
    # attribute byte 0 = %11 10 01 00 covers tiles 0-3 x 0-3
    (0, 0, 0), (1, 1, 0), (2, 0, 1), (3, 1, 1), (0, 2, 2), (1, 3, 2), (2, 2, 3), (3, 3, 3),
    # byte 9 (row 1 of the 8 x 8 table, column 1) covers tiles 4-7 x 4-7; %01 01 01 01 -> palette 1
    (4, 4, 1), (7, 7, 1), (8, 4, 0),
    # byte 63 covers tiles 28-31 x 28-29 (the bottom half of its 4 x 4 block is off the screen)
    (28, 28, 2), (31, 29, 2),
])
def test_palette_of_a_tile(col, row, palette):
    attributes = bytearray(64)
    attributes[0], attributes[9], attributes[63] = 0b11100100, 0b01010101, 0b10101010
    assert palette_at(bytes(attributes), col, row) == palette


@pytest.mark.parametrize("size", [0, 959, 961, 1023, 1025, 1984, 3072, 5120, 8192])
def test_other_sizes_are_one_line(size):
    for read in (nametable_from_bytes, nametables_from_bytes):
        with pytest.raises(InputError, match=rf"^t.nam: file size: {size} bytes: a nametable file is 1024 bytes .*, "
                                             r"960 \(tile numbers only\), or 2 or 4 nametables of 1024 bytes$"):
            read(bytes(size), "t.nam")


def test_960_bytes_are_the_tiles_without_attributes():
    raw = nam({(16, 15): 7, (31, 29): 9}, {0: 0xE4})[:960]
    loaded = nametable_from_bytes(raw, "t.nam")
    assert loaded.tiles[15 * 32 + 16] == 7 and loaded.tiles[959] == 9 and len(loaded.tiles) == 960
    assert loaded.attributes == bytes(64) and not loaded.has_attributes
    assert nametable_from_bytes(nam(), "t.nam").has_attributes


@pytest.mark.parametrize("count", [2, 4])
def test_several_nametables_in_ppu_order(count):
    # nametable n has tile n + 1 at (n, n) and attribute byte n = $10 + n
    raw = b"".join(nam({(n, n): n + 1}, {n: 0x10 + n}) for n in range(count))
    tables = nametables_from_bytes(raw, "t.nam")
    assert len(tables) == count
    for n, table in enumerate(tables):
        assert table.tiles[n * 32 + n] == n + 1 and sum(1 for t in table.tiles if t) == 1
        assert table.attributes[n] == 0x10 + n and sum(1 for a in table.attributes if a) == 1
    addresses = ", ".join(f"${a:04X}" for a in (0x2000, 0x2400, 0x2800, 0x2C00)[:count])
    with pytest.raises(InputError, match=rf"^t.nam: file size: {1024 * count} bytes hold {count} nametables "
                                         rf"\({re.escape(addresses)}\): a \[\[nametable\]\] file is one nametable"):
        nametable_from_bytes(raw, "t.nam")


SCENE = """chip = "nes"
[ppu]
ctrl = 0x00
mask = 0x1e
scroll_y = {scroll_y}
[[oam]]
y = {y}
tile = 3
x = 128
[chr]
tiles = {{ "0:3" = ["33333333", "33333333", "33333333", "33333333", "33333333", "33333333", "33333333", "33333333"] }}
[[nametable]]
index = 0
{table}
"""


def hit(tmp_path, content: bytes, y: int, scroll_y: int = 0, table: str = 'file = "screen.nam"'):
    (tmp_path / "screen.nam").write_bytes(content)
    (tmp_path / "s.toml").write_text(SCENE.format(y=y, scroll_y=scroll_y, table=table))
    return sprite_zero_hit(load_scene(tmp_path / "s.toml").ppu_state())


def test_tiles_from_the_file_decide_the_hit(tmp_path):
    # sprite 0 at Y 119 is drawn on lines 120-127; tile (16, 15) is lines 120-127, x 128-135
    result = hit(tmp_path, nam({(16, 15): SOLID}), y=119)
    assert (result.hit, result.line, result.x) == (True, 120, 128)
    assert not hit(tmp_path, nam({(17, 15): SOLID}), y=119).hit  # x 136-143: beside the sprite


def test_a_960_byte_file_in_a_scene(tmp_path):
    result = hit(tmp_path, nam({(16, 15): SOLID})[:960], y=119)
    assert (result.hit, result.line, result.x) == (True, 120, 128)
    # no attribute table: at Y scroll 240 the attribute row shows tile 0 (empty) under the sprite
    assert not hit(tmp_path, nam({(16, 15): SOLID}, {16: SOLID})[:960], y=0, scroll_y=240).hit


def test_cells_go_on_top_of_the_file(tmp_path):
    result = hit(tmp_path, nam(), y=119, table='file = "screen.nam"\ncells = [{ col = 16, row = 15, tile = 3 }]')
    assert (result.hit, result.line, result.x) == (True, 120, 128)


def test_attribute_bytes_from_the_file_show_at_y_scroll_240(tmp_path):
    # scroll Y 240: screen lines 0-7 show nametable row 30, the first 32 attribute bytes, as tile
    # numbers; attribute byte 16 is column 16 (x 128-135). Sprite 0 at Y 0 is drawn on lines 1-8.
    result = hit(tmp_path, nam(attributes={16: SOLID}), y=0, scroll_y=240)
    assert (result.hit, result.line, result.x) == (True, 1, 128)
    # the same tiles with the attribute byte elsewhere: nothing under the sprite
    assert not hit(tmp_path, nam(attributes={17: SOLID}), y=0, scroll_y=240).hit


@pytest.mark.parametrize("content, table, field, message", [
    (bytes(1000), 'file = "screen.nam"', "nametable[0].file", "'screen.nam': file size: 1000 bytes"),
    (nam(), 'file = "screen.nam"\nfill = 3', "nametable[0].fill", "give fill or file, not both"),
    (nam(), 'file = "missing.nam"', "nametable[0].file", "nametable file 'missing.nam' not found"),
    (nam(), "file = 3", "nametable[0].file", "expected a file name, got 3"),
    (nam() * 2, 'file = "screen.nam"', "nametable[0].part",
     "'screen.nam' holds 2 nametables (0: $2000, 1: $2400); say which with part = 0-1"),
    (nam() * 4, 'file = "screen.nam"\npart = 4', "nametable[0].part", "4 is out of range 0..3"),
    (nam(), 'file = "screen.nam"\npart = 1', "nametable[0].part", "1 is out of range 0..0"),
    (nam(), "part = 0", "nametable[0].part", "part picks a nametable of a file: give file too"),
])
def test_scene_errors_are_one_line(tmp_path, content, table, field, message):
    with pytest.raises(InputError) as info:
        hit(tmp_path, content, y=119, table=table)
    text = str(info.value)
    assert f"s.toml: {field}: " in text and message in text and "\n" not in text, text


def test_cli(tmp_path):
    (tmp_path / "screen.nam").write_bytes(nam({(16, 15): SOLID}))
    (tmp_path / "s.toml").write_text(SCENE.format(y=119, scroll_y=0, table='file = "screen.nam"'))
    done = subprocess.run([sys.executable, "-m", "retro", "nes", str(tmp_path / "s.toml"), "--json"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["dots_after_vblank"] == (21 + 120) * 341 + 128
    (tmp_path / "screen.nam").write_bytes(bytes(5))
    done = subprocess.run([sys.executable, "-m", "retro", "nes", str(tmp_path / "s.toml")], capture_output=True, text=True)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "nametable[0].file" in done.stderr


@pytest.mark.parametrize("count", [2, 4])
def test_part_picks_one_nametable_of_a_file_of_several(tmp_path, count):
    # only table 1 has the solid tile under sprite 0 (tile (16, 15): lines 120-127, x 128-135)
    content = b"".join(nam({(16, 15): SOLID}) if n == 1 else nam({(2, 2): SOLID}) for n in range(count))
    for part in range(count):
        result = hit(tmp_path, content, y=119, table=f'file = "screen.nam"\npart = {part}')
        assert result.hit == (part == 1), part
    assert hit(tmp_path, content, y=119, table='file = "screen.nam"\npart = 1').line == 120
