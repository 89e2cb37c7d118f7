"""`retro vic`: JSON output, human output, PNG, and one-line errors (exit 2) for bad scenes."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

from retro.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOOD_SPRITE = 'index = 0\nx = 100\ny = 100\ndata = "' + "ff " * 63 + '"\n'


def write_scene(tmp_path: Path, body: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text('chip = "vic-ii"\nvideo = "pal"\n' + body)
    return path


def test_json_output_has_the_exact_keys(capsys):
    assert main(["vic", str(ROOT / "examples" / "vic_text_collision.toml"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {"d01e", "d01f", "d019", "first", "pairs", "background"}
    assert set(out["first"]) == {"d01e", "d01f"}
    # by hand (see the scene's comments): the ship's pixel at X 107 meets glyph 1's row 0 (%00011000,
    # pixel 3 of column 10 at X 104) on line 48+3+8*5 = 91; sprites 0 and 2 hit text, nothing overlaps.
    assert out["d01e"] == 0 and out["d01f"] == 0b101
    assert out["first"] == {"d01e": None, "d01f": {"line": 91, "x": 107}}
    assert out["d019"] == 0x70 | 0x02 | 0x01  # sprite-background + raster (compare line 0), nothing enabled


def test_human_output_and_png(tmp_path, capsys):
    png = tmp_path / "out.png"
    assert main(["vic", str(ROOT / "examples" / "vic_two_balls.toml"), "--png", str(png), "--scale", "1"]) == 0
    text = capsys.readouterr().out
    assert "$D01E = $0F %00001111" in text and "0+1" in text and "2+3" in text
    image = Image.open(png)
    assert image.width > 504 and image.height > 312  # full frame at x1 plus the zoom panel and legend


def test_frames_option(capsys):
    assert main(["vic", str(ROOT / "examples" / "vic_two_balls.toml"), "--frames", "3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["d01e"] == 0x0F


@pytest.mark.parametrize("body, field", [
    ("bogus = 1\n", "bogus"),
    ("[[sprite]]\n" + GOOD_SPRITE.replace("index = 0", "index = 8"), "sprite[0].index"),
    ("[[sprite]]\n" + GOOD_SPRITE.replace("x = 100", "x = 512"), "sprite[0].x"),
    ("[[sprite]]\n" + GOOD_SPRITE.replace("y = 100", "y = 256"), "sprite[0].y"),
    ("[[sprite]]\n" + GOOD_SPRITE.replace("ff " * 63, "ff " * 62), "sprite[0].data"),
    ("[[sprite]]\nindex = 0\nrows = [" + ", ".join(['"' + "#" * 23 + '"'] * 21) + "]\n", "sprite[0].rows[0]"),
    ("[[sprite]]\nindex = 0\nmulticolor = true\nrows = [" + ", ".join(['"' + "#" * 24 + '"'] * 21) + "]\n",
     "sprite[0].rows[0]"),
    ("[[sprite]]\nindex = 0\nfile = \"missing.spr\"\n", "sprite[0].file"),
    ("[[sprite]]\nindex = 0\ncolour = 1\n" + 'data = "' + "00" * 63 + '"\n', "sprite[0].colour"),
    ("[registers]\n\"$d040\" = 1\n", "registers.$d040"),
    ("[registers]\n\"$d01e\" = 1\n", "registers.$d01e"),
    ("[registers]\n\"$d011\" = 1\n\"d011\" = 2\n", "registers.d011"),  # one register, two spellings
    ("[memory]\ncharset = { \"1\" = [1, 1, 1, 1, 1, 1, 1, 1], \"$01\" = [2, 2, 2, 2, 2, 2, 2, 2] }\n",
     "memory.charset.$01: the same character code as '1'"),
    ("[memory]\nscreen = { fill = 1, cells = [{ col = 40, row = 0, value = 1 }] }\n", "memory.screen.cells[0].col"),
    ("[memory]\ncharset = { \"1\" = [1, 2, 3] }\n", "memory.charset.1"),
    ("video = \"secam\"\n".replace("video", "bad"), "bad"),
])
def test_bad_scene_is_one_line_naming_file_and_field(tmp_path, capsys, body, field):
    path = write_scene(tmp_path, body)
    assert main(["vic", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(path) in err and field in err


def test_png_of_the_wrong_size(tmp_path, capsys):
    Image.new("RGB", (20, 21)).save(tmp_path / "small.png")
    path = write_scene(tmp_path, "[[sprite]]\nindex = 0\nfile = \"small.png\"\n")
    assert main(["vic", str(path)]) == 2
    err = capsys.readouterr().err
    assert "sprite[0]" in err and "24x21" in err and "20x21" in err and err.count("\n") == 1


def test_sprite_file_resolves_relative_to_the_scene(tmp_path, capsys):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "ball.spr").write_bytes((ROOT / "sprites" / "ball.spr").read_bytes())
    path = write_scene(tmp_path, '[[sprite]]\nindex = 0\nfile = "sub/ball.spr"\n'
                       '[[sprite]]\nindex = 1\nx = 10\nfile = "sub/ball.spr"\n')
    assert main(["vic", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["d01e"] == 0b11


def test_bad_scale_exit_2(capsys):
    assert main(["vic", str(ROOT / "examples" / "vic_two_balls.toml"), "--scale", "0"]) == 2
    assert "--scale" in capsys.readouterr().err


def test_console_script_without_traceback(tmp_path):
    path = write_scene(tmp_path, "[[sprite]]\nindex = 9\n")
    proc = subprocess.run([sys.executable, "-m", "retro", "vic", str(path)], capture_output=True, text=True)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr


@pytest.mark.parametrize("video, cycles_per_line", [("pal", 63), ("ntsc", 65)])
def test_run_with_a_scene_attaches_the_vic(tmp_path, capsys, video, cycles_per_line):
    """`retro run --scene`: a delay loop, then LDA $D012. The run starts at raster line 0, cycle 1,
    and LDA abs reads in its 4th cycle. By the MOS cycle table (LDX #/LDY # 2, DEX/DEY 2, BNE 3 taken,
    2 not) the read happens 2 + outer * (2 + (5 * inner - 1) + 2 + 3) - 1 + 3 cycles in: 2016 here,
    line 32 on PAL (63 cycles a line) but line 31 on NTSC (65)."""
    outer, inner = 2, 200
    source = tmp_path / "raster.s"
    source.write_text(f".org $c000\nstart: ldy #{outer}\nouter: ldx #{inner}\ninner: dex\n bne inner\n"
                      " dey\n bne outer\n lda $d012\n rts\n")
    scene = tmp_path / "scene.toml"
    scene.write_text(f'chip = "vic-ii"\nvideo = "{video}"\n')
    assert main(["run", str(source), "--entry", "start", "--scene", str(scene), "--json"]) == 0
    read_at = 2 + outer * (2 + (5 * inner - 1) + 2 + 3) - 1 + 3
    assert json.loads(capsys.readouterr().out)["a"] == read_at // cycles_per_line


def test_pairs_and_background_answers(tmp_path, capsys):
    # two full 24 x 21 sprites at X 100 and 110, Y 100: shown on lines 101-121 (a sprite's first row
    # is on line Y + 1), they share X 110-123 on each: 14 x 21 = 294 places
    body = ('[registers]\n"$d015" = 3\n'
            '[[sprite]]\nindex = 0\nx = 100\ny = 100\nrows = [' + ", ".join(['"' + "#" * 24 + '"'] * 21) + ']\n'
            '[[sprite]]\nindex = 1\nx = 110\ny = 100\nrows = [' + ", ".join(['"' + "#" * 24 + '"'] * 21) + ']\n')
    path = tmp_path / "pair.toml"
    path.write_text('chip = "vic-ii"\nvideo = "pal"\n' + body)
    assert main(["vic", str(path), "--json", "--pixels"]) == 0
    out = json.loads(capsys.readouterr().out)
    (pair,) = out["pairs"]
    assert pair["sprites"] == [0, 1] and pair["pixels"] == 14 * 21
    assert pair["box"] == {"line_min": 101, "line_max": 121, "x_min": 110, "x_max": 123}
    assert len(pair["at"]) == 294 and pair["at"][0] == [101, 110] and pair["at"][-1] == [121, 123]
    assert out["background"] == []
    assert main(["vic", str(path)]) == 0
    assert "0+1 (294 px, lines 101-121, X 110-123)" in capsys.readouterr().out


def test_frames_move_sprites_by_their_velocity(tmp_path, capsys):
    # sprite 0's top row (X 100-123) moves 4 pixels right a frame towards sprite 1's (X 160-183), both
    # on line 101: frame f covers 100 + 4f .. 123 + 4f, so they meet from frame 10 (X 140-163) on,
    # first at X 160; read once a frame (clearing), $D01E is $03 in frames 10-19 and 0 before
    top_row = ", ".join(['"' + "#" * 24 + '"'] + ['"' + "." * 24 + '"'] * 20)
    path = tmp_path / "move.toml"
    path.write_text('chip = "vic-ii"\nvideo = "pal"\n'
                    f'[[sprite]]\nindex = 0\nx = 100\ny = 100\nvelocity = [4, 0]\nrows = [{top_row}]\n'
                    f'[[sprite]]\nindex = 1\nx = 160\ny = 100\nrows = [{top_row}]\n')
    assert main(["vic", str(path), "--frames", "20", "--json"]) == 0
    frames = json.loads(capsys.readouterr().out)["frames"]
    assert [f["frame"] for f in frames if f["d01e"]] == list(range(10, 20))
    assert all(f["d01e"] == 0b11 for f in frames[10:]) and frames[9]["d01e"] == 0
    assert frames[10]["first"]["d01e"] == {"line": 101, "x": 160} and frames[10]["pairs"] == [[0, 1]]
    bad = tmp_path / "bad.toml"
    bad.write_text(path.read_text().replace("velocity = [4, 0]", "velocity = 4"))
    assert main(["vic", str(bad), "--frames", "2"]) == 2
    assert "sprite[0].velocity: expected [dx, dy]" in capsys.readouterr().err


def test_the_image_zooms_on_each_colliding_pair():
    from retro.render.vic_image import _zoom_sets
    from retro.scenes.vic import load

    scene = load(ROOT / "examples" / "vic_two_balls.toml")
    from retro.chips.vic.model import frame_collisions

    collisions = frame_collisions(scene.state)
    assert [title for title, _, _ in _zoom_sets(scene.state, collisions)] == ["sprites 0+1", "sprites 2+3"]
