"""CharPad .ctm projects: every read version and colouring method against samples written from the
manuals' field tables (ctm_samples.py), the refused versions as one line, the project in a VIC
scene (its colour RAM decides multicolour characters, so $D01F), and its materials as the
property table of the `tile` routine."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from retro.chips.vic.model import frame_collisions
from retro.errors import InputError
from retro.loaders.gfx_charpad import material_table, read_ctm, screen_codes
from retro.scenes import load_scene
from ctm_samples import BASE_SCREEN, COLOURINGS, WRITERS, Level, level_for, screen_lo_hi, v3, v4, v5, v6, v7, v8

CASES = [(version, colouring) for version, colourings in COLOURINGS.items() for colouring in colourings]


def expected_window(level: Level, colouring: str, col: int = 0, row: int = 0):
    codes, colours, covered = [], [], []
    for r in range(row, row + 25):
        for c in range(col, col + 40):
            cell = level.screen_cell(c, r)
            covered.append(cell is not None)
            codes.append(cell[0] if cell else 0)
            colours.append(level.expected_colour(c, r, colouring) if cell else 0)
    return codes, colours, covered


@pytest.mark.parametrize("version, colouring", CASES)
def test_every_version_and_colouring(version, colouring):
    level = level_for(version)
    project = read_ctm(WRITERS[version](level, colouring), f"v{version}.ctm")
    assert (project.version, project.colouring, project.mode) == (version, colouring, "hires")
    assert project.charset()[:32] == bytes(sum(level.chars, []))
    assert project.charset()[32:] == bytes(2048 - 32)
    # version 1 has no materials; version 3 has them per tile cell only; the others give each char its
    # material (v4: from the char attributes, not the cell attributes, which the sample sets to 3)
    if version == 3:
        with pytest.raises(InputError, match=r"^v3.ctm: CHAR_ATTRIBS: a version 3 project keeps its materials per "
                                             r"tile cell"):
            project.material_table("v3.ctm")
        assert project.cell_materials[:, 0, 0].tolist() == [3, 4, 5]  # 3 + the tile number, every cell
    else:
        materials = [0, 0, 0, 0] if version == 1 else level.materials
        assert project.material_table() == bytes(materials) + bytes(252)
    codes, colours, covered = project.window(0, 0)
    want_codes, want_colours, want_covered = expected_window(level, colouring)
    assert codes.tolist() == want_codes
    assert colours.tolist() == want_colours
    assert covered.tolist() == want_covered


@pytest.mark.parametrize("version", [5, 6, 7, 8, 9, 82])
def test_projects_without_a_tile_set_map_characters(version):
    level = Level(tiles_on=False, map_w=45, map_h=30)
    project = read_ctm(WRITERS[version](level, "per-char"), "chars.ctm")
    assert project.tiles is None
    codes, colours, covered = project.window(3, 2)
    want_codes, want_colours, _ = expected_window(level, "per-char", 3, 2)
    assert codes.tolist() == want_codes and colours.tolist() == want_colours and covered.all()


@pytest.mark.parametrize("writer, mode", [(v3, "multicolor"), (v5, "multicolor"), (v6, "multicolor"),
                                          (v7, "multicolor"), (v8, "multicolor")])
def test_multicolour_flag(writer, mode):
    assert read_ctm(writer(Level(multicolor=True), "global"), "mc.ctm").mode == mode


def test_v7_display_modes():
    assert read_ctm(v7(Level(), "global", mode=2), "ecm.ctm").mode == "ecm"
    with pytest.raises(InputError, match=r"^ecm.ctm: DISPLAY_MODE: display mode 3 is not 0"):
        read_ctm(v7(Level(), "global", mode=3), "ecm.ctm")


def test_window_offset_and_edges():
    level = Level()  # 21 x 13 tiles of 2 x 2: 42 x 26 cells
    project = read_ctm(v6(level, "per-char"), "l.ctm")
    codes, _, covered = project.window(2, 1)
    want_codes, _, want_covered = expected_window(level, "per-char", 2, 1)
    assert codes.tolist() == want_codes and covered.tolist() == want_covered
    assert covered.sum() == 40 * 25  # 42 - 2 columns, 26 - 1 rows: all covered
    codes, _, covered = project.window(10, 10)
    assert covered.sum() == 32 * 16  # 42 - 10 columns, 26 - 10 rows
    with pytest.raises(InputError, match=r"^l.ctm: the map is 42 x 26 screen cells: no cell at column 42, row 0$"):
        project.window(42, 0, "l.ctm")


def truncated(raw: bytes, cut: int) -> bytes:
    return raw[:len(raw) - cut]


@pytest.mark.parametrize("raw, message", [
    (b"CTM\x0a" + bytes(40), "VERSION: CharPad format version 10 is not read"),
    (b"CTM\x53" + bytes(40), "VERSION: CharPad format version 83 is not read"),
    (b"CTM\x00", "VERSION: CharPad format version 0 is not read"),
    (b"CTM\x08" + bytes(40), "CHARDAT block marker: expected $DA $B0 at byte 14, found $00 $00"),
    (b"CTM\x09" + bytes(40), "CHARDAT block marker: expected $DA $B0 at byte 19, found $00 $00"),
    (b"CTM\x52" + bytes(8), "BASE_COLOURS: needs 3 bytes from byte 11, the file ends at byte 12"),
    (b"CTM\x09\x00\x00\x00\x01\x02", "FLEXIGRID: needs 5 bytes from byte 7, the file ends at byte 9"),
    (b"CTM\x08\x05" + bytes(20), "DISP_MODE: display mode 5 is not one of 0 (hires), 1 (multicolor), 2 (ecm), "
                                 "3 (bitmap-hires), 4 (bitmap-multicolor)"),
    (v8(Level(), "global", mode="bitmap-multicolor", prototype=True),
     "DISP_MODE: a bitmap-multicolor project in the CharPad 2.8 preview layout of version 8 is not read"),
    (v8(Level(), "per-char", mode="bitmap-multicolor").split(b"t2\0")[0] + b"t2", "TILENAMES: a tile name from byte"),
    # header 14, chars 2 + 2 + 32, materials 2 + 4, colours marker 2: 4 entries of 2 bytes from byte 58
    (v8(Level(tiles_on=False), "per-char", mode="bitmap-hires")[:63],
     "CHARCOLRS: needs 8 bytes from byte 58, the file ends at byte 63"),
    (v8(Level(), "global") + b"\0", "file size: the data ends at byte"),
    (v8(Level(tiles_on=False), "per-tile"), "COLR_METH: per-tile colouring in a project without a tile set"),
    (v3(Level(), "global", charex=1), "CHAREX: the character set is saved expanded"),
    (truncated(v3(Level(), "per-tile"), 21 * 13 + 1), "TILE_COLOURS: needs 3 bytes from byte"),
    (b"CTX\x05", "ID_STR: not a CharPad project"),
    (b"CTM", "VERSION: needs 1 bytes from byte 3, the file ends at byte 3"),
    (v4(Level(), "global", charex=1), "CHAREX: the character set is saved expanded"),
    (v5(Level(), "global", charex=True), "FLAGS: the character set is saved expanded"),
    (truncated(v5(Level(), "global"), 1), "MAP_DATA: needs 546 bytes from byte"),
    (truncated(v6(Level(), "global"), 552 + 5), "TILENAMES: a tile name from byte"),
    (v6(Level(), "global") + b"\0", "file size: the data ends at byte"),
    (v6(Level(), "global").replace(b"\xda\xb1", b"\xda\xb7", 1), "CHARATTS block marker: expected $DA $B1 at byte"),
    (b"CTM\x06" + bytes([0, 0, 0, 0, 5, 0]), "COLR_METH: colouring method 5 is not one of 0 (global)"),
    (v5(Level(tiles_on=False), "per-tile"), "COLR_METH: per-tile colouring in a project without a tile set"),
])
def test_bad_files_are_one_line(raw, message):
    with pytest.raises(InputError) as info:
        read_ctm(raw, "bad.ctm")
    text = str(info.value)
    assert text.startswith("bad.ctm: ") and message in text and "\n" not in text


def test_map_naming_a_missing_tile_or_a_code_past_255():
    level = Level()
    raw = bytearray(v6(level, "global"))
    raw[-2 * 21 * 13:-2 * 21 * 13 + 2] = (7).to_bytes(2, "little")  # map entry (0, 0): tile 7 of 3
    with pytest.raises(InputError, match=r"^m.ctm: map cell \(column 0, row 0\) names tile 7, the project has 3$"):
        read_ctm(bytes(raw), "m.ctm").window(0, 0, "m.ctm")
    chars = Level(tiles_on=False, map_w=40, map_h=25)
    raw = bytearray(v6(chars, "global"))
    raw[-2 * 40 * 25 + 2 * 41:-2 * 40 * 25 + 2 * 42] = (300).to_bytes(2, "little")  # cell (1, 1)
    with pytest.raises(InputError, match=r"shows character 300: a screen holds codes 0-255$"):
        read_ctm(bytes(raw), "m.ctm").window(0, 0, "m.ctm")


# ---- in a VIC scene -------------------------------------------------------------------------------

TWO_PIXELS = ["##" + "." * 22] * 8 + ["." * 24] * 13  # pixels 0 and 1 of rows 0-7: one text row


def scene_text(ctm: str, x: int, y: int, d016: int, extra: str = "") -> str:
    return f"""chip = "vic-ii"
[registers]
"$d011" = 0x1b    # YSCROLL 3: text row r is lines 51 + 8r ..
"$d016" = {d016:#x}    # XSCROLL 0: column c is X 24 + 8c ..
[[sprite]]
index = 0
x = {x}
y = {y}
rows = {json.dumps(TWO_PIXELS)}
[memory]
{extra}charpad = {ctm}
"""


def background_xs(scene) -> set[int]:
    return set(frame_collisions(scene.state).sb_pixels[1].tolist())


@pytest.mark.parametrize("colouring, multicolour, xs", [
    # char 2 ($40 rows: pixel 1; in multicolour the pair `01`) at screen cell (6, 5) of tile 1 at map (3, 2):
    # per-char colour 9 has bit 3 set, so with MCM it is a multicolour char and `01` is background
    ("per-char", False, {24 + 8 * 7 + 1}),
    ("per-char", True, set()),
    # the global colour 14 also has bit 3; 3 (per tile: tile 1 has colour 3) has not: hires, pixel 1
    ("global", True, set()),
    ("per-tile", True, {24 + 8 * 7 + 1}),
])
def test_project_in_a_scene(tmp_path, colouring, multicolour, xs):
    level = Level()
    (tmp_path / "level.ctm").write_bytes(v6(level, colouring))
    # tile 1 at map (3, 2) covers cells 6-7, 4-5: cell (7, 4) is char 2 ([[1, 2], [3, 1]])
    assert level.screen_cell(7, 4)[0] == 2
    x, y = 24 + 8 * 7, 51 + 8 * 4 - 1  # sprite row 0 on line y + 1 = the char's first line
    (tmp_path / "s.toml").write_text(scene_text('"level.ctm"', x, y, 0xD8 if multicolour else 0xC8))
    scene = load_scene(tmp_path / "s.toml")
    assert background_xs(scene) == xs


def test_scene_window_and_screen_cells_on_top(tmp_path):
    level = Level()
    (tmp_path / "level.ctm").write_bytes(v6(level, "per-char"))
    # the window from map cell (6, 4) on: char 1 (solid) at (6, 4) becomes screen cell (0, 0)
    text = scene_text('{ file = "level.ctm", col = 6, row = 4 }', 24, 50, 0xC8,
                      extra="screen = { cells = [{ col = 1, row = 0, value = 1 }] }\n")
    (tmp_path / "s.toml").write_text(text)
    scene = load_scene(tmp_path / "s.toml")
    # (6, 4) is char 1, the cell on top puts 1 over (7, 4)'s char 2, (8, 4) is in tile 0 (char 0)
    assert scene.state.memory.screen[:3].tolist() == [1, 1, 0]
    assert scene.state.memory.color[:3].tolist() == [1, 9, 0]  # per-char colours of chars 1, 2 (file), 0
    assert background_xs(scene) == {24, 25}  # the solid char at screen cell (0, 0)


def run_vic(path, *args):
    return subprocess.run([sys.executable, "-m", "retro", "vic", str(path), *args], capture_output=True, text=True)


def test_cli_reads_the_project_and_refuses_a_bad_one_in_one_line(tmp_path):
    (tmp_path / "level.ctm").write_bytes(v7(Level(), "per-char"))
    (tmp_path / "s.toml").write_text(scene_text('"level.ctm"', 24 + 8 * 7, 51 + 8 * 4 - 1, 0xC8))
    done = run_vic(tmp_path / "s.toml", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["d01f"] == 1
    (tmp_path / "level.ctm").write_bytes(b"CTM\x0a" + bytes(30))
    done = run_vic(tmp_path / "s.toml")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "s.toml: memory.charpad: 'level.ctm': VERSION: CharPad format version 10 is not read" in done.stderr


@pytest.mark.parametrize("memory, field, message", [
    ('charpad = "level.ctm"\ncharset = { file = "level.ctm" }', "memory.charset.file",
     "memory.charpad gives the charset already"),
    ('charpad = "level.ctm"\nscreen = { file = "level.ctm" }', "memory.screen.file", "memory.charpad gives the screen"),
    ('charpad = "level.ctm"\nkoala = "level.ctm"', "memory.koala", "memory.charpad gives the screen already"),
    ('charpad = "other.bin"', "memory.charpad", "'other.bin': ID_STR: not a CharPad project"),
    ('charpad = { col = 1 }', "memory.charpad.file", "missing"),
    ('charpad = { file = "level.ctm", row = 26 }', "memory.charpad.row",
     "'level.ctm': the map is 42 x 26 screen cells: row 26 is past its edge"),
    ('charpad = { file = "level.ctm", col = -1 }', "memory.charpad.col", "out of range"),
    ('charpad = { file = "level.ctm", size = 2 }', "memory.charpad.size", "unknown key"),
    ('bitmap = { file = "level.ctm" }', "memory.bitmap.file", "a CharPad project has no bitmap"),
])
def test_scene_errors_name_the_field(tmp_path, memory, field, message):
    (tmp_path / "level.ctm").write_bytes(v6(Level(), "global"))
    (tmp_path / "other.bin").write_bytes(bytes(1000))
    (tmp_path / "s.toml").write_text(f'chip = "vic-ii"\n[memory]\n{memory}\n')
    with pytest.raises(InputError) as info:
        load_scene(tmp_path / "s.toml")
    text = str(info.value)
    assert f"s.toml: {field}: " in text and message in text and "\n" not in text, text


def test_screen_colour_and_charset_files_may_each_be_a_project(tmp_path):
    level = Level()
    (tmp_path / "level.ctm").write_bytes(v5(level, "per-tile"))
    (tmp_path / "s.toml").write_text('chip = "vic-ii"\n[memory]\ncharset = { file = "level.ctm" }\n'
                                     'screen = { fill = 32, file = "level.ctm" }\ncolor = { file = "level.ctm" }\n')
    memory = load_scene(tmp_path / "s.toml").state.memory
    codes, colours, covered = expected_window(level, "per-tile")
    assert memory.screen.tolist() == [c if ok else 32 for c, ok in zip(codes, covered)]  # row 24: the fill
    assert memory.color.tolist() == colours
    assert memory.charset[:32].tobytes() == bytes(sum(level.chars, []))


# ---- materials for routine specs --------------------------------------------------------------------

REFS = '''from pathlib import Path
from retro.loaders.gfx_charpad import material_table, screen_codes
LEVEL = Path(__file__).parent / "level.ctm"

def props():
    return material_table(LEVEL)

def screen():
    return screen_codes(LEVEL, col=0, row=0)
'''


def test_materials_as_the_tile_routines_property_table(tmp_path):
    from retro.paths import ASM_DIR
    from retro.routines.runner import RoutineRunner
    from retro.testing import check, spec_from_dict

    level = Level()
    (tmp_path / "level.ctm").write_bytes(v4(level, "global"))
    (tmp_path / "refs.py").write_text(REFS)
    assert material_table(tmp_path / "level.ctm") == bytes(level.materials) + bytes(252)
    assert screen_codes(tmp_path / "level.ctm") == bytes(expected_window(level, "global")[0])
    spec = spec_from_dict({
        "program": {"file": str(ASM_DIR / "tile.s"), "entry": "tile"},
        "inputs": {"x": "X", "xh": "C", "y": "Y"},
        "outputs": {"property": "A"},
        "memory": {"screen": {"at": "$0400", "generator": "refs.py:screen"},
                   "props": {"at": "tile_props", "generator": "refs.py:props"}},
        "reference": {"function": "retro.routines.reference:tile"},
        "cases": {"random": 300},
    }, base=tmp_path)
    assert check(spec).mismatches == 0
    runner = RoutineRunner(spec)
    # sprite coordinates: cell column (x - 24) / 8, row (y - 50) / 8; tile 1 at map (3, 2) holds chars
    # 1, 2 / 3, 1 in cells (6, 4), (7, 4) / (6, 5), (7, 5); tile 2 at map (10, 5) is all char 2
    for col, row, material in [(6, 4, 1), (7, 4, 2), (6, 5, 15), (7, 5, 1), (21, 11, 2), (5, 4, 0)]:
        outputs, _ = runner.run((24 + 8 * col + 3, 0, 50 + 8 * row + 5))
        assert outputs == (material,), (col, row)


# ---- versions 8, 82, 9: the preview layout, bitmap display modes, hostile bytes ----------------------

@pytest.mark.parametrize("colouring", ["global", "per-tile", "per-char"])
@pytest.mark.parametrize("multicolor", [False, True])
def test_v8_preview_layout_is_told_by_its_first_block_marker(colouring, multicolor):
    """The CharPad 2.8 preview layout: a 4th base colour (the char colour; the sample puts 9, 10, 11 in
    the other three) and 4-byte colour entries, the colour-matrix byte last (the sample's first three
    are 12, 13, 14)."""
    level = Level(multicolor=multicolor)
    project = read_ctm(v8(level, colouring, prototype=True), "p.ctm")
    assert project.layout == "prototype" and project.char_colour == level.char_colour
    codes, colours, covered = project.window(0, 0)
    want_codes, want_colours, _ = expected_window(level, colouring)
    assert codes.tolist() == want_codes and colours.tolist() == want_colours
    assert project.material_table() == bytes(level.materials) + bytes(252)
    assert read_ctm(v8(level, colouring), "r.ctm").layout == ""


def test_v9_flexigrid_is_skipped_and_v82_reads_as_8():
    level = Level()
    for raw in (v8(level, "per-char", 9, flexigrid=b"\xff\xff\xff\xff\xda"), v8(level, "per-char", 82)):
        project = read_ctm(raw, "x.ctm")
        assert (project.background, project.multicolor1, project.multicolor2, project.char_colour) == (6, 11, 12, 14)
        assert project.window(0, 0)[1].tolist() == expected_window(level, "per-char")[1]


def expected_bitmap(level: Level, colouring: str, mode: str):
    """(bitmap, screen bytes, colour nibbles) of the 40 x 25 window at (0, 0), by hand."""
    bitmap, screen, colours = [], [], []
    for r in range(25):
        for c in range(40):
            cell = level.screen_cell(c, r)
            code, tile, _ = cell if cell else (0, None, None)
            bitmap.append(level.chars[code] if cell else [0] * 8)
            if colouring == "per-char":
                lo, hi = screen_lo_hi("char", code)
            elif colouring == "per-tile":
                lo, hi = screen_lo_hi("tile", tile)
            else:
                lo, hi = BASE_SCREEN
            colour = level.expected_colour(c, r, colouring) if mode == "bitmap-multicolor" or colouring == "global" else 0
            screen.append(hi << 4 | lo if cell else 0)
            colours.append(colour if cell else 0)
    return [b for cell in bitmap for b in cell], screen, colours


@pytest.mark.parametrize("colouring", ["global", "per-tile", "per-char"])
@pytest.mark.parametrize("mode", ["bitmap-hires", "bitmap-multicolor"])
def test_bitmap_display_modes_give_bitmap_screen_and_colour(mode, colouring):
    from retro.loaders.gfx_screen import vic_parts

    level = Level()  # 42 x 26 cells: the window at (0, 0) is covered
    raw = v8(level, colouring, mode=mode)
    project = read_ctm(raw, "bm.ctm")
    assert project.mode == mode and project.bitmap_mode
    bitmap, screen, colours, covered = project.bitmap_window(0, 0, "bm.ctm")
    want_bitmap, want_screen, want_colours = expected_bitmap(level, colouring, mode)
    assert bitmap.tolist() == want_bitmap
    assert screen.tolist() == want_screen
    assert colours.tolist() == want_colours and covered.all()
    parts = vic_parts(raw, "bm.ctm", ("bitmap", "screen", "color"))
    assert parts["bitmap"].values.tolist() == want_bitmap and parts["screen"].values.tolist() == want_screen
    with pytest.raises(InputError, match=r"^bm.ctm: a CharPad project in display mode .* has no charset"):
        vic_parts(raw, "bm.ctm", ("charset",))


def test_bitmap_mode_takes_characters_past_255():
    level = Level(tiles_on=False, map_w=40, map_h=25, chars=[[i % 256] * 8 for i in range(300)],
                  materials=[0] * 300, char_colours=[1] * 300)
    raw = bytearray(v8(level, "global", mode="bitmap-multicolor"))
    raw[-2000:-1998] = (299).to_bytes(2, "little")  # map cell (0, 0): char 299
    bitmap, *_ = read_ctm(bytes(raw), "b.ctm").bitmap_window()
    assert bitmap[:8].tolist() == [299 % 256] * 8
    raw[-2000:-1998] = (300).to_bytes(2, "little")
    with pytest.raises(InputError, match=r"^b.ctm: screen cell \(column 0, row 0\) shows character 300, the project has 300$"):
        read_ctm(bytes(raw), "b.ctm").bitmap_window(0, 0, "b.ctm")


def test_bitmap_project_in_a_scene_through_the_part_files(tmp_path):
    level = Level()
    (tmp_path / "bm.ctm").write_bytes(v8(level, "per-char", mode="bitmap-multicolor"))
    files = 'bitmap = { file = "bm.ctm" }\nscreen = { file = "bm.ctm" }\ncolor = { file = "bm.ctm" }\n'
    (tmp_path / "s.toml").write_text(f'chip = "vic-ii"\n[memory]\n{files}')
    memory = load_scene(tmp_path / "s.toml").state.memory
    want_bitmap, want_screen, want_colours = expected_bitmap(level, "per-char", "bitmap-multicolor")
    assert memory.screen.tolist() == want_screen and memory.color.tolist() == want_colours
    (tmp_path / "s.toml").write_text('chip = "vic-ii"\n[memory]\ncharpad = "bm.ctm"\n')
    with pytest.raises(InputError, match="has no charset"):
        load_scene(tmp_path / "s.toml")


SAMPLES = [v3(Level(), "per-tile"), v8(Level(), "per-char", mode="bitmap-multicolor"),
           v8(Level(), "per-tile", 9), v8(Level(multicolor=True), "per-char", prototype=True)]


@pytest.mark.parametrize("sample", range(len(SAMPLES)))
def test_every_cut_and_many_flipped_bytes_are_one_line(sample):
    import random

    raw = SAMPLES[sample]
    rng = random.Random(sample)
    variants = [raw[:n] for n in range(len(raw))]
    for _ in range(300):
        bad = bytearray(raw)
        for _ in range(rng.randint(1, 4)):
            bad[rng.randrange(4, len(bad))] = rng.randrange(256)
        variants.append(bytes(bad))
    for bad in variants:
        try:
            project = read_ctm(bad, "f.ctm")
            if project.bitmap_mode:
                project.bitmap_window(0, 0, "f.ctm")
            else:
                project.window(0, 0, "f.ctm")
        except InputError as exc:
            assert str(exc).startswith("f.ctm: ") and "\n" not in str(exc)
