"""Koala pictures and raw screen / colour RAM files in VIC scenes. Samples follow the Koala layout
(load address $6000, 8000 bytes of bitmap, 1000 of screen RAM, 1000 of colour RAM, 1 background
byte: 10003 bytes) and plain memory dumps (1000 or 1024 bytes, optionally behind a load address)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from retro.chips.vic.model import frame_collisions
from retro.errors import InputError
from retro.loaders.gfx_koala import koala_from_bytes
from retro.scenes import load_scene

PAIR_10, PAIR_01 = 0x80, 0x40  # the left pixel pair of a multicolour byte: `10` (foreground), `01` (background)
TWO_PIXELS = ["##" + "." * 22] * 8 + ["." * 24] * 13


def koala(load: bytes | None = b"\x00\x60", padding: bytes = b"") -> bytes:
    bitmap = bytearray(8000)
    for col, pattern in ((10, PAIR_10), (12, PAIR_01)):  # cells (10, 5) and (12, 5), all 8 rows
        start = (5 * 40 + col) * 8
        bitmap[start:start + 8] = bytes([pattern]) * 8
    screen = bytes((i * 7) & 0xFF for i in range(1000))
    colour = bytes(0xF0 | (i % 16) for i in range(1000))  # high nibbles as a real dump may hold them
    return (load or b"") + bytes(bitmap) + screen + colour + bytes([0x0B]) + padding


@pytest.mark.parametrize("raw, load", [
    (koala(), 0x6000),
    (koala(None), None),
    (koala(b"\x00\x44", b"\0" * 7), 0x4400),
    (koala(b"\x00\x60", b"\xff" * 254), 0x6000),
    (koala(b"\x00\x20"), 0x2000),  # 10003 bytes: the layout decides, whatever the load address
])
def test_koala_parts(raw, load):
    picture = koala_from_bytes(raw, "p.kla")
    assert picture.load_address == load
    assert picture.bitmap[(5 * 40 + 10) * 8] == PAIR_10 and picture.bitmap.sum() == 8 * (PAIR_10 + PAIR_01)
    assert picture.screen.tolist() == [(i * 7) & 0xFF for i in range(1000)]
    assert picture.colour.tolist() == [i % 16 for i in range(1000)]
    assert picture.background == 0x0B


@pytest.mark.parametrize("raw", [bytes(10002), koala(b"\x00\x20", b"\0"), koala(b"\x00\x60", bytes(255))])
def test_not_a_koala_picture_is_one_line(raw):
    with pytest.raises(InputError) as info:
        koala_from_bytes(raw, "p.kla")
    assert str(info.value).startswith(f"p.kla: file size: {len(raw)} bytes: a Koala picture is 10003 bytes")
    assert str(info.value).endswith("or a compressed (GG) picture of fewer than 10001 bytes")


# ---- compressed (GG) pictures: $FE value count, anything else itself, to 10001 bytes ---------------------

def gg(data: bytes, load: bytes = b"\x00\x60") -> bytes:
    """Pack data the GG way, runs of 4 or more (and every $FE) as $FE value count."""
    out, i = bytearray(load), 0
    while i < len(data):
        run = 1
        while i + run < len(data) and data[i + run] == data[i] and run < 255:
            run += 1
        if run >= 4 or data[i] == 0xFE:
            out += bytes([0xFE, data[i], run])
        else:
            out += data[i:i + run]
        i += run
    return bytes(out)


def test_gg_picture_unpacks_to_the_koala_layout():
    plain = koala(None)
    packed = gg(plain)
    assert len(packed) < 10001 and 0xFE in packed[2:]
    picture = koala_from_bytes(packed, "p.gg")
    reference = koala_from_bytes(plain, "p.kla")
    assert picture.load_address == 0x6000
    for part in ("bitmap", "screen", "colour"):
        assert getattr(picture, part).tolist() == getattr(reference, part).tolist()
    assert picture.background == 0x0B


def test_gg_runs_by_hand():
    # 7999 zeros as runs of 255 and one of 94, one $FE value kept by a run of 1, count 0 writing nothing,
    # then screen 1000 x $12, colour 1000 x $F3, background 6; a run past the end is cut
    runs = b"".join(b"\xfe\x00\xff" for _ in range(31)) + b"\xfe\x00\x5e" + b"\xfe\x77\x00" + b"\xfe\xfe\x01"
    screen = b"".join(b"\xfe\x12\xfa" for _ in range(4)) + b"\xfe\x12\x00"  # 4 x 250
    colour = b"\xfe\xf3\xff" * 3 + b"\xfe\xf3\xeb" + b"\xfe\x06\x09"  # 765 + 235, then 9 cut to 1
    picture = koala_from_bytes(b"\x00\x60" + runs + screen + colour, "h.gg")
    assert picture.bitmap[:7999].tolist() == [0] * 7999 and picture.bitmap[7999] == 0xFE
    assert picture.screen.tolist() == [0x12] * 1000 and picture.colour.tolist() == [3] * 1000
    assert picture.background == 6


@pytest.mark.parametrize("raw, message", [
    (bytes(9000), "file size: 9000 bytes: not a Koala picture (10003 bytes, or 10001 without the load address), "
                  "and as a compressed (GG) picture it unpacks to 8998 of 10001 bytes"),
    (b"\x00\x60\xfe\x00\xff\xfe\x00", "GG run at byte 5: needs 3 bytes ($FE, value, count), the file ends at byte 7"),
    (b"\x00", "file size: 1 bytes: not a Koala picture"),
    (gg(koala(None)) + bytes(255), "as a compressed (GG) picture it is whole at byte"),
])
def test_bad_gg_pictures_are_one_line(raw, message):
    with pytest.raises(InputError) as info:
        koala_from_bytes(raw, "p.gg")
    assert str(info.value).startswith("p.gg: ") and message in str(info.value) and "\n" not in str(info.value)


def test_gg_picture_by_content_and_in_a_scene(tmp_path):
    from retro.loaders.gfx_koala import looks_like_koala

    packed = gg(koala(None))
    assert looks_like_koala(packed) and not looks_like_koala(gg(koala(None), b"\x00\x20"))
    assert not looks_like_koala(packed[:-1]) and not looks_like_koala(packed + b"\0")
    (tmp_path / "pic.gg").write_bytes(packed)
    for memory in ('koala = "pic.gg"', 'bitmap = { file = "pic.gg" }'):
        (tmp_path / "s.toml").write_text(BITMAP_SCENE.format(x=24 + 80, y=51 + 8 * 5 - 1, rows=json.dumps(TWO_PIXELS),
                                                             memory=memory))
        scene = load_scene(tmp_path / "s.toml")
        assert set(frame_collisions(scene.state).sb_pixels[1].tolist()) == {104, 105}


BITMAP_SCENE = """chip = "vic-ii"
[registers]
"$d011" = 0x3b    # bitmap mode, screen on, YSCROLL 3: cell row r is lines 51 + 8r ..
"$d016" = 0xd8    # multicolour, XSCROLL 0: cell column c is X 24 + 8c ..
[[sprite]]
index = 0
x = {x}
y = {y}
rows = {rows}
[memory]
{memory}
"""


@pytest.mark.parametrize("memory", ['koala = "pic.kla"', 'koala = { file = "pic.kla" }',
                                    'bitmap = { file = "pic.kla" }'])
@pytest.mark.parametrize("col, xs", [(10, {104, 105}), (12, set())])
def test_koala_bitmap_in_a_scene(tmp_path, memory, col, xs):
    (tmp_path / "pic.kla").write_bytes(koala())
    (tmp_path / "s.toml").write_text(BITMAP_SCENE.format(x=24 + 8 * col, y=51 + 8 * 5 - 1, rows=json.dumps(TWO_PIXELS),
                                                         memory=memory))
    scene = load_scene(tmp_path / "s.toml")
    assert set(frame_collisions(scene.state).sb_pixels[1].tolist()) == xs
    if memory.startswith("koala"):
        assert scene.state.memory.screen.tolist() == [(i * 7) & 0xFF for i in range(1000)]
        assert scene.state.memory.color.tolist() == [i % 16 for i in range(1000)]
    else:
        assert not scene.state.memory.screen.any()


def test_koala_through_the_cli(tmp_path):
    (tmp_path / "pic.kla").write_bytes(koala())
    (tmp_path / "s.toml").write_text(BITMAP_SCENE.format(x=104, y=90, rows=json.dumps(TWO_PIXELS),
                                                         memory='koala = "pic.kla"'))
    done = subprocess.run([sys.executable, "-m", "retro", "vic", str(tmp_path / "s.toml"), "--json"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["d01f"] == 1
    (tmp_path / "pic.kla").write_bytes(koala()[:-1])
    done = subprocess.run([sys.executable, "-m", "retro", "vic", str(tmp_path / "s.toml")], capture_output=True, text=True)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "s.toml: memory.koala: 'pic.kla': file size: 10002 bytes" in done.stderr


# ---- raw screen and colour RAM ----------------------------------------------------------------------

TEXT_SCENE = """chip = "vic-ii"
[registers]
"$d011" = 0x1b
"$d016" = 0xd8    # multicolour text: colour RAM bit 3 makes a character multicolour
[[sprite]]
index = 0
x = {x}
y = 90
rows = {rows}
[memory]
charset = {{ "1" = [0x40, 0x40, 0x40, 0x40, 0x40, 0x40, 0x40, 0x40] }}
screen = {{ file = "screen.bin" }}
color = {{ file = "colour.bin" }}
"""


def dump(values: list[int], size: int, load: bool) -> bytes:
    data = bytes(values) + bytes(size - len(values))
    return (b"\x00\x04" if load else b"") + data


@pytest.mark.parametrize("size", [1000, 1024])
@pytest.mark.parametrize("load", [False, True])
def test_raw_screen_and_colour_ram(tmp_path, size, load):
    # row 5: char 1 in columns 10 and 12; colour 0xF1 in column 10 (low nibble 1: hires, pixel 1 is set),
    # 0x09 in column 12 (bit 3: multicolour, so the pair `01` is background)
    screen = [0] * 1000
    colour = [0] * 1000
    screen[5 * 40 + 10] = screen[5 * 40 + 12] = 1
    colour[5 * 40 + 10], colour[5 * 40 + 12] = 0xF1, 0x09
    (tmp_path / "screen.bin").write_bytes(dump(screen, size, load))
    (tmp_path / "colour.bin").write_bytes(dump(colour, size, load))
    hits = {}
    for col in (10, 12):
        (tmp_path / "s.toml").write_text(TEXT_SCENE.format(x=24 + 8 * col, rows=json.dumps(TWO_PIXELS)))
        scene = load_scene(tmp_path / "s.toml")
        assert scene.state.memory.color[5 * 40 + 10] == 1  # the low nibble only
        hits[col] = set(frame_collisions(scene.state).sb_pixels[1].tolist())
    assert hits == {10: {24 + 80 + 1}, 12: set()}


@pytest.mark.parametrize("name, size, field, message", [
    ("screen.bin", 999, "memory.screen.file", "'screen.bin': 999 bytes: a screen RAM file is 1000 or 1024 bytes"),
    ("colour.bin", 1025, "memory.color.file", "'colour.bin': 1025 bytes: a colour RAM file is 1000 or 1024 bytes"),
])
def test_bad_dump_sizes_are_one_line(tmp_path, name, size, field, message):
    (tmp_path / "screen.bin").write_bytes(bytes(1000))
    (tmp_path / "colour.bin").write_bytes(bytes(1000))
    (tmp_path / name).write_bytes(bytes(size))
    (tmp_path / "s.toml").write_text(TEXT_SCENE.format(x=100, rows=json.dumps(TWO_PIXELS)))
    with pytest.raises(InputError) as info:
        load_scene(tmp_path / "s.toml")
    assert f"s.toml: {field}: {message}" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("memory, field, message", [
    ('koala = "pic.kla"\nbitmap = { file = "pic.kla" }', "memory.bitmap.file", "memory.koala gives the bitmap already"),
    ('koala = "pic.kla"\ncolor = { file = "pic.kla" }', "memory.color.file", "memory.koala gives the color already"),
    ('koala = { file = "pic.kla", col = 1 }', "memory.koala.col", "unknown key"),
    ('charset = { file = "pic.kla" }', "memory.charset.file", "'pic.kla': a Koala picture has no charset"),
    ('bitmap = { file = "short.bin" }', "memory.bitmap.file", "'short.bin': 7999 bytes: a bitmap file is 8000 bytes"),
    ('koala = "short.bin"', "memory.koala", "'short.bin': file size: 7999 bytes"),
])
def test_koala_scene_errors(tmp_path, memory, field, message):
    (tmp_path / "pic.kla").write_bytes(koala())
    (tmp_path / "short.bin").write_bytes(bytes(7999))
    (tmp_path / "s.toml").write_text(f'chip = "vic-ii"\n[memory]\n{memory}\n')
    with pytest.raises(InputError) as info:
        load_scene(tmp_path / "s.toml")
    assert f"s.toml: {field}: {message}" in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_bitmap_with_a_load_address_and_cells_on_top(tmp_path):
    bitmap = np.zeros(8000, np.uint8)
    bitmap[:8] = 0xAA
    (tmp_path / "b.bin").write_bytes(b"\x00\x20" + bitmap.tobytes())
    (tmp_path / "s.toml").write_text('chip = "vic-ii"\n[memory]\nbitmap = { file = "b.bin", cells = '
                                     '[{ col = 1, row = 0, bytes = [1, 2, 3, 4, 5, 6, 7, 8] }] }\n')
    memory = load_scene(tmp_path / "s.toml").state.memory
    assert memory.bitmap[:16].tolist() == [0xAA] * 8 + [1, 2, 3, 4, 5, 6, 7, 8]
