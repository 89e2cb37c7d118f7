"""SpritePad .spd readers (1.x, 2.0 beta): samples built byte by byte from the documented layouts
(see retro/loaders/gfx_spritepad.py), expected pixels and attributes worked by hand. SpritePad Pro,
Spritemate and PNG sheets: test_sprite_editor_files.py."""

from __future__ import annotations

import subprocess
import sys

import pytest

from retro.errors import InputError
from retro.loaders.gfx_spritepad import parse_spd, read_spd
from retro.sprites import format_rows, read_spr

# Sprite A: top row "########" then 8 clear then "#......#"; every other row empty.
SPRITE_A = bytes([0xFF, 0x00, 0x81]) + bytes(60)
# Sprite B: bottom row all set.
SPRITE_B = bytes(60) + bytes([0xFF, 0xFF, 0xFF])
ROW_A = "########" + "." * 8 + "#......#"


def v1_file() -> bytes:
    # background 6 (blue), multicolours 2 (red) and 7 (yellow); A: colour 1, hires; B: colour 5, multicolour
    return bytes([6, 2, 7]) + SPRITE_A + bytes([0x01]) + SPRITE_B + bytes([0x85])


def beta_file() -> bytes:
    # "SPD", version 1, 2 sprites (stored as 1), 1 animation (stored as 0), colours 0, 11, 12
    header = b"SPD" + bytes([1, 1, 0, 0, 11, 12])
    animation = bytes([0, 1, 5, 0])  # start, end, timer, flags: present in real files, not read
    return header + SPRITE_A + bytes([0x1E]) + SPRITE_B + bytes([0x93]) + animation


def test_v1_sprites_attributes_and_shared_colours():
    spd = parse_spd(v1_file())
    assert spd.version == "1"
    assert (spd.background, spd.multicolor1, spd.multicolor2) == (6, 2, 7)
    a, b = spd.sprites
    assert format_rows(a.data)[0] == ROW_A and set(format_rows(a.data)[1]) == {"."}
    assert (a.colour, a.multicolor, a.overlay) == (1, False, False)
    assert format_rows(b.data, multicolor=True)[20] == "333333333333"
    assert (b.colour, b.multicolor) == (5, True)


def test_beta_version_1_with_overlay_flag():
    spd = parse_spd(beta_file())
    assert spd.version == "2.0 beta"
    assert (spd.background, spd.multicolor1, spd.multicolor2) == (0, 11, 12)
    a, b = spd.sprites
    assert (a.colour, a.multicolor, a.overlay) == (14, False, True)
    assert (b.colour, b.multicolor, b.overlay) == (3, True, True)
    assert b.data == SPRITE_B


@pytest.mark.parametrize("make", [v1_file, beta_file])
def test_read_spr_detects_spritepad_by_content(tmp_path, make):
    path = tmp_path / "any_name.bin"  # the extension does not matter
    path.write_bytes(make())
    assert read_spr(path, 0) == SPRITE_A
    assert read_spr(path, 1) == SPRITE_B
    with pytest.raises(InputError, match="frame: 2 is outside 0..1"):
        read_spr(path, 2)
    assert read_spd(path).sprites[1].data == SPRITE_B


def test_raw_spr_still_raw(tmp_path):
    path = tmp_path / "raw.spr"
    path.write_bytes(SPRITE_A + b"\0" + SPRITE_B + b"\0")
    assert read_spr(path, 1) == SPRITE_B


@pytest.mark.parametrize("raw, message", [
    (b"SPD" + bytes([6]) + bytes(100), "format version 6 is not supported"),
    (b"SPD" + bytes([3]) + bytes(100), "header says 0 sprites"),
    (b"SPD" + bytes([2, 0, 2, 0]) + bytes(9) + bytes(64), "says 2 sprites \\(144 bytes\\), file has 80 bytes"),
    (b"SPD" + bytes([2, 0, 1]) + bytes(5), "SpritePad 2.x preview version 2 header is 11 bytes, needs 16"),
    (b"SPD" + bytes([1, 3, 0, 0, 0, 0]) + bytes(64), "says 4 sprites"),
    (b"SPD\x01", "header is 4 bytes"),
    (bytes(70), "3 \\+ 64n bytes"),
])
def test_bad_spritepad_files_one_line(raw, message):
    with pytest.raises(InputError, match=message):
        parse_spd(raw, "x.spd")


def test_scene_uses_spritepad_file_and_cli_errors_cleanly(tmp_path):
    (tmp_path / "s.spd").write_bytes(beta_file())
    (tmp_path / "bad.spd").write_bytes(b"SPD" + bytes([6]) + bytes(80))
    scene = """chip = "vic-ii"

[[sprite]]
index = 0
x = 100
y = 100
file = "{f}"

[[sprite]]
index = 1
x = 100
y = 80
file = "{f}"
frame = 1
"""
    (tmp_path / "good.toml").write_text(scene.format(f="s.spd"))
    (tmp_path / "bad.toml").write_text(scene.format(f="bad.spd"))
    good = subprocess.run([sys.executable, "-m", "retro", "vic", str(tmp_path / "good.toml"), "--json"],
                          capture_output=True, text=True)
    assert good.returncode == 0, good.stderr
    # sprite 1's bottom row (y 80 + 20 = 100) meets sprite 0's top row at y 100: pixels
    # x 100-107, 116 and 123 (A's ten set bits) are under B's full row, so 10 pixels collide
    import json
    report = json.loads(good.stdout)
    assert report["pairs"][0]["pixels"] == 10
    bad = subprocess.run([sys.executable, "-m", "retro", "vic", str(tmp_path / "bad.toml")],
                         capture_output=True, text=True)
    assert bad.returncode == 2
    assert len(bad.stderr.strip().splitlines()) == 1 and "version 6" in bad.stderr


def test_huge_png_refused_from_its_header(tmp_path):
    """A PNG header claiming 9000x9000 with no pixel data: the size error comes before any decoding
    (decoding would fail differently, with 'not a readable PNG image')."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", 9000, 9000, 8, 6, 0, 0, 0)  # RGBA, 8 bits
    path = tmp_path / "huge.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IEND", b""))
    from retro.sprites import read_png
    with pytest.raises(InputError, match="is 24x21 pixels or a sheet of them .*got 9000x9000"):
        read_png(path)
