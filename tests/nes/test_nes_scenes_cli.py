"""NES scene files and `retro nes`: the format, one-line errors naming file and field, JSON keys."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from retro.cli import main
from retro.errors import InputError
from retro.scenes import load_scene

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "nes_sprite0.toml"

SCENE = """chip = "nes"
video = "ntsc"
[ppu]
ctrl = 0x00
mask = 0x1e
scroll_x = 0
scroll_y = 0
mirroring = "horizontal"
[[oam]]
y = 119
tile = 3
attr = 0x00
x = 128
[chr]
tiles = { "0:3" = ["33333333", "33333333", "33333333", "33333333", "33333333", "33333333", "33333333", "33333333"] }
[[nametable]]
index = 0
fill = 0
cells = [{ col = 16, row = 15, tile = 3 }]
"""


def write(tmp_path: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def run_cli(*args: str, capsys) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_issue_scene_json(tmp_path, capsys):
    code, out, err = run_cli("nes", str(write(tmp_path, SCENE)), "--json", capsys=capsys)
    assert code == 0 and err == ""
    data = json.loads(out)
    # Sprite at Y 119 -> line 120, x 128, both solid tiles: (21 + 120) * 341 + 128 = 48209.
    # NTSC: 3 PPU dots a CPU cycle, so 48209 / 3 = 16069.6667 CPU cycles after the vblank flag.
    assert data == {"hit": True, "line": 120, "dot": 129, "x": 128, "dots_after_vblank": 48209,
                    "cpu_cycles_after_vblank": 16069.6667,
                    "sprite_overflow": {"set": False, "line": None, "dot": None, "dots_after_vblank": None,
                                        "sprites_on_line": None}}
    assert list(data) == ["hit", "line", "dot", "x", "dots_after_vblank", "cpu_cycles_after_vblank", "sprite_overflow"]


def test_no_hit_json_has_nulls(tmp_path, capsys):
    code, out, _ = run_cli("nes", str(write(tmp_path, SCENE.replace("mask = 0x1e", "mask = 0x0e"))), "--json",
                           capsys=capsys)
    assert code == 0
    data = json.loads(out)
    assert data == {"hit": False, "line": None, "dot": None, "x": None, "dots_after_vblank": None,
                    "cpu_cycles_after_vblank": None, "sprite_overflow": data["sprite_overflow"]}
    assert data["sprite_overflow"]["set"] is False


def test_tile_as_16_chr_bytes_equals_rows(tmp_path):
    rows = write(tmp_path, SCENE.replace('"33333333", "33333333", "33333333", "33333333", "33333333", '
                                         '"33333333", "33333333", "33333333"', '"3.1.2...", ' + '"........", ' * 7)[:-0 or None])
    as_bytes = write(tmp_path, SCENE.replace('["33333333", "33333333", "33333333", "33333333", "33333333", '
                                             '"33333333", "33333333", "33333333"]',
                                             '[0xA0, 0, 0, 0, 0, 0, 0, 0, 0x88, 0, 0, 0, 0, 0, 0, 0]'), "b.toml")
    # Row "3.1.2..." : value 3 at col 0 (both planes), 1 at col 2 (plane 0), 2 at col 4 (plane 1):
    # plane 0 = %10100000 = $A0, plane 1 = %10001000 = $88.
    assert load_scene(rows).chr[0x30:0x40] == load_scene(as_bytes).chr[0x30:0x40]
    assert load_scene(as_bytes).chr[0x30] == 0xA0 and load_scene(as_bytes).chr[0x38] == 0x88


def test_chr_file_relative_to_scene(tmp_path, monkeypatch):
    folder = tmp_path / "scenes"
    folder.mkdir()
    data = bytearray(8192)
    data[0x30:0x40] = b"\xff" * 16
    (folder / "game.chr").write_bytes(bytes(data))
    text = SCENE.replace('tiles = { "0:3" = ["33333333", "33333333", "33333333", "33333333", "33333333", '
                         '"33333333", "33333333", "33333333"] }', 'file = "game.chr"')
    path = write(folder, text)
    monkeypatch.chdir(tmp_path)
    assert load_scene(path).chr == bytes(data)


@pytest.mark.parametrize("edit, field", [
    (("[ppu]", "[ppu]\nscrol_x = 1"), "ppu.scrol_x: unknown key"),
    (("video = \"ntsc\"", "video = \"ntsc\"\ncolour = 1"), "colour: unknown key"),
    (("attr = 0x00", "attr = 0x00\nflip = 1"), "oam[0].flip: unknown key"),
    (("mask = 0x1e", "mask = 256"), "ppu.mask"),
    (("x = 128", "x = -1"), "oam[0].x"),
    (('"0:3" = ["33333333", ', '"0:3" = ["3333333", '), 'chr.tiles."0:3"[0]'),
    (('"0:3" = ["33333333", ', '"0:3" = ["3333333x", '), 'chr.tiles."0:3"[0]'),
    (('"0:3"', '"2:3"'), 'chr.tiles."2:3" table'),
    (("index = 0", "index = 4"), "nametable[0].index"),
    (("row = 15", "row = 30"), "nametable[0].cells[0].row"),
    (("mirroring = \"horizontal\"", "mirroring = \"diagonal\""), "ppu.mirroring"),
    (("video = \"ntsc\"", "video = \"secam\""), "video"),
    (('tiles = { "0:3"', 'tiles = { "0:03" = [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0], "0:3"'),
     'chr.tiles."0:3": the same tile as "0:03"'),  # one tile, two spellings: the last would win
])
def test_bad_scene_one_line_error_names_file_and_field(tmp_path, capsys, edit, field):
    path = write(tmp_path, SCENE.replace(*edit))
    code, out, err = run_cli("nes", str(path), capsys=capsys)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and str(path) in err and field in err, err


def test_chr_file_must_be_4_or_8_kib(tmp_path):
    (tmp_path / "short.chr").write_bytes(bytes(4000))
    text = SCENE.replace('tiles = { "0:3"', 'file = "short.chr"\ntiles = { "0:3"')
    with pytest.raises(InputError, match=r"scene.toml: chr.file: .*4000 bytes: a CHR file is 4 KiB"):
        load_scene(write(tmp_path, text))


def test_missing_or_unreadable_chr_file_names_the_scene_and_field(tmp_path):
    for name in ("nope.chr", "."):  # a file that is not there, and a directory
        text = SCENE.replace('tiles = { "0:3"', f'file = "{name}"\ntiles = {{ "0:3"')
        with pytest.raises(InputError, match=r"scene.toml: chr.file: "):
            load_scene(write(tmp_path, text))


def test_two_nametables_on_the_same_memory_are_refused(tmp_path):
    text = SCENE + "[[nametable]]\nindex = 1\nfill = 2\n"      # horizontal: $2400 is $2000
    with pytest.raises(InputError, match=r"nametable\[1\].index: nametable 1 is the same memory as nametable 0"):
        load_scene(write(tmp_path, text))


def test_missing_oam_and_bad_scale(tmp_path, capsys):
    text = SCENE.split("[[oam]]")[0] + "[chr]" + SCENE.split("[chr]")[1]
    code, _, err = run_cli("nes", str(write(tmp_path, text)), capsys=capsys)
    assert code == 2 and "oam: missing" in err
    code, _, err = run_cli("nes", str(write(tmp_path, SCENE)), "--scale", "0", capsys=capsys)
    assert code == 2 and "--scale" in err


def test_cli_subprocess_no_traceback(tmp_path):
    path = write(tmp_path, SCENE.replace("x = 128", "x = 300"))
    done = subprocess.run([sys.executable, "-m", "retro", "nes", str(path)], capture_output=True, text=True)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1


def test_png_written_at_scale(tmp_path, capsys):
    from PIL import Image
    out = tmp_path / "hit.png"
    code, text, _ = run_cli("nes", str(EXAMPLE), "--png", str(out), "--scale", "3", capsys=capsys)
    assert code == 0 and "sprite-zero hit" in text
    image = Image.open(out)
    assert image.width > 256 * 3 and image.height > 240 * 3


def test_example_scene_prediction(capsys):
    code, out, _ = run_cli("nes", str(EXAMPLE), "--json", capsys=capsys)
    data = json.loads(out)
    assert code == 0 and data["hit"] is True


def test_retro_run_with_scene_polls_the_hit(tmp_path, capsys):
    source = write(tmp_path, ".org $c000\nwait: bit $2002\n bvc wait\n rts\n", "poll.s")
    code, out, err = run_cli("run", str(source), "--entry", "wait", "--scene", str(write(tmp_path, SCENE)), "--json",
                             capsys=capsys)
    assert code == 0, err
    cycles = json.loads(out)["cycles"]
    # The routine starts at machine cycle 0 = PPU frame 0 line 0 dot 0, rendering already on.
    # Hit dot: line 120, dot 129 -> absolute dot 120 * 341 + 129 = 41049 -> first cycle 13683.
    # The reading BIT's last cycle is cycles - 6 (RTS) - 2 (BVC not taken) - 1.
    read = cycles - 9
    assert 0 <= read - 13683 <= 6
