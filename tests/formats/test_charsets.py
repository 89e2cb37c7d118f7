"""Charset files, raw and .64c (2-byte load address + 8 bytes per glyph), through a VIC scene:
a sprite over a character drawn from the file sets $D01F only if the glyph was read in place."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from retro.errors import InputError
from retro.loaders.gfx_charset import charset_from_bytes

SOLID = bytes([0xFF] * 8)
ROWS = repr(["#" + "." * 23] + ["." * 24] * 20).replace("'", '"')  # one pixel at the top left


def test_raw_and_64c_give_the_same_glyphs():
    glyphs = bytes(range(16))  # two characters
    expected = glyphs + bytes(2048 - 16)
    assert charset_from_bytes(glyphs, "a.bin") == expected
    assert charset_from_bytes(b"\x00\x30" + glyphs, "a.64c") == expected  # loads at $3000
    full = bytes(i & 0xFF for i in range(2048))
    assert charset_from_bytes(b"\x00\x38" + full, "full.64c") == full


@pytest.mark.parametrize("size", [0, 2, 5, 2 + 8 * 257, 8 * 257])
def test_bad_charset_lengths(size):
    with pytest.raises(InputError, match=f"{size} bytes: a charset is 8 bytes per character"):
        charset_from_bytes(bytes(size), "c.64c")


SCENE = """chip = "vic-ii"
[registers]
"$d011" = 0x1b        # YSCROLL 3: text row 0 is lines 51-58
"$d016" = 0xc8        # 40 columns, XSCROLL 0: column 0 is x 24-31
[[sprite]]
index = 0
x = 24
y = 51
rows = {rows}
[memory]
screen = {{ fill = 32, cells = [{{ col = 0, row = 0, value = 1 }}] }}
charset = {{ file = "{name}" }}
"""


@pytest.mark.parametrize("name, content, background_hit", [
    # character 1 solid: the sprite's pixel at the window's top-left corner sits on it
    ("chars.64c", b"\x00\x30" + bytes(8) + SOLID, True),
    ("chars.bin", bytes(8) + SOLID, True),
    # character 1's top row is $30 (pixels 2-3 only): the sprite's one pixel (column 0) misses it
    ("shifted.bin", b"\x00\x30" + bytes(6) + b"\x30" + bytes(7), False),
])
def test_charset_file_in_a_scene(tmp_path, name, content, background_hit):
    (tmp_path / name).write_bytes(content)
    (tmp_path / "s.toml").write_text(SCENE.format(name=name, rows=ROWS))
    done = subprocess.run([sys.executable, "-m", "retro", "vic", str(tmp_path / "s.toml"), "--json"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert (report["d01f"] & 1 == 1) is background_hit, report


def test_bad_charset_file_is_one_line(tmp_path):
    (tmp_path / "c.64c").write_bytes(bytes(13))
    (tmp_path / "s.toml").write_text(SCENE.format(name="c.64c", rows=ROWS))
    done = subprocess.run([sys.executable, "-m", "retro", "vic", str(tmp_path / "s.toml")],
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1 and "memory.charset.file" in done.stderr
