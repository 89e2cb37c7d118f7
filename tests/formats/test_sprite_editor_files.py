"""SpritePad Pro (.spd versions 4 and 5), Spritemate (.spm) and PNG sprite sheets.

Every sample is built here from the format's documented layout (the sources are named in
retro/loaders/gfx_spritepad.py, gfx_spritemate.py, gfx_png_sprites.py), not by inverting the readers;
the expected sprite bytes are worked out by hand from the VIC-II's bit layout: 3 bytes a row, most
significant bit leftmost, multicolour pairs 01 = $D025, 10 = the sprite's colour, 11 = $D026.
"""

from __future__ import annotations

import json
import struct
import subprocess
import sys
import zlib

import pytest
from PIL import Image

from retro.errors import InputError
from retro.loaders.gfx_png_sprites import SpriteColours, read_png_sheet
from retro.loaders.gfx_spritemate import parse_spm
from retro.loaders.gfx_spritepad import parse_spd
from retro.chips.palettes import PALETTES
from retro.sprites import read_png, read_spr, read_sprite, read_sprite_frames

PEPTO = PALETTES["c64-pepto"]
COLODORE = PALETTES["c64-colodore"]
CLEAR = (0, 0, 0, 0)

# Sprite A: top row "########", 8 clear, "#......#"; B: bottom row all set (as in test_sprite_files.py).
SPRITE_A = bytes([0xFF, 0x00, 0x81]) + bytes(60)
SPRITE_B = bytes(60) + bytes([0xFF, 0xFF, 0xFF])


def one_line(exc: pytest.ExceptionInfo, *parts: str) -> str:
    text = str(exc.value)
    assert "\n" not in text, text
    for part in parts:
        assert part in text, text
    return text


# ---- SpritePad Pro -------------------------------------------------------------------------------

def pro_header(version: int, count: int, *, flags: int = 0, tiles: int = 0, anims: int = 0, tile_anims: int = 0,
               tile_w: int = 0, tile_h: int = 0, colours=(6, 2, 7), overlay: int = 1, tile_overlay: int = 1) -> bytes:
    """The 20-byte Pro header: "SPD", version, flags, sprite count (16-bit LE), tile count, sprite and
    tile animation counts, tile width and height, background, multicolour 1 and 2, sprite and tile
    overlay distances (16-bit signed LE)."""
    header = (b"SPD" + bytes([version, flags]) + struct.pack("<HH", count, tiles)
              + bytes([anims, tile_anims, tile_w, tile_h]) + bytes(colours) + struct.pack("<hh", overlay, tile_overlay))
    assert len(header) == 0x14
    return header


def test_spritepad_pro_version_5_with_tiles_and_animations_after_the_sprites():
    # A: colour 1, hires; B: colour 5, multicolour, overlay ($95, the attribute real Pro files carry)
    tiles = struct.pack("<HH", 0, 1)  # one tile of 2x1 sprites: sprite indices, 16-bit
    animations = bytes([0, 1, 5, 0x80])  # present in real files after the tiles; not read
    raw = (pro_header(5, 2, flags=0x03, tiles=1, anims=1, tile_w=2, tile_h=1, colours=(9, 0, 1), overlay=1)
           + SPRITE_A + bytes([0x01]) + SPRITE_B + bytes([0x95]) + tiles + animations)
    spd = parse_spd(raw, "pro5.spd")
    assert spd.version == "Pro 5"
    assert (spd.background, spd.multicolor1, spd.multicolor2, spd.overlay_distance) == (9, 0, 1, 1)
    a, b = spd.sprites
    assert (a.data, a.colour, a.multicolor, a.overlay) == (SPRITE_A, 1, False, False)
    assert (b.data, b.colour, b.multicolor, b.overlay, b.attribute) == (SPRITE_B, 5, True, True, 0x95)


def test_spritepad_pro_version_4_header_and_a_negative_overlay_distance():
    raw = pro_header(4, 3, colours=(0x1B, 0x0C, 0x0F), overlay=-1) + b"".join(
        bytes([i + 1]) + bytes(62) + bytes([0x80 | i]) for i in range(3))
    spd = parse_spd(raw, "pro4.spd")
    assert spd.version == "Pro 4"
    assert (spd.background, spd.multicolor1, spd.multicolor2) == (11, 12, 15)  # colour bytes read as nibbles
    assert spd.overlay_distance == -1
    assert [s.data[0] for s in spd.sprites] == [1, 2, 3]
    assert [(s.colour, s.multicolor) for s in spd.sprites] == [(0, True), (1, True), (2, True)]


def preview_header(version: int, count: int, *, flags: int = 0, tiles: int = 0, anim_bytes: bytes = b"\0\0",
                   tile_w: int = 0, tile_h: int = 0, colours=(6, 2, 7)) -> bytes:
    """The 16-byte header of the SpritePad 2.x previews (GoDot's notes for version 2, Oscar64 and
    C64Studio for version 3): "SPD", version, flags, sprite count (16-bit LE, not minus one), tile count,
    2 bytes of animation counts, tile width and height, background, multicolour 1 and 2."""
    header = (b"SPD" + bytes([version, flags]) + struct.pack("<HH", count, tiles) + anim_bytes
              + bytes([tile_w, tile_h]) + bytes(colours))
    assert len(header) == 0x10
    return header


@pytest.mark.parametrize("version", [2, 3])
def test_spritepad_preview_versions_2_and_3(tmp_path, version):
    tiles = struct.pack("<HH", 1, 0)  # one tile of 2x1 sprites, after the blocks; not read
    raw = (preview_header(version, 2, flags=0x01, tiles=1, tile_w=2, tile_h=1, colours=(0x1B, 0, 1))
           + SPRITE_A + bytes([0x01]) + SPRITE_B + bytes([0x95]) + tiles)
    spd = parse_spd(raw, "prev.spd")
    assert spd.version == f"2.x preview {version}"
    assert (spd.background, spd.multicolor1, spd.multicolor2, spd.overlay_distance) == (11, 0, 1, 1)
    a, b = spd.sprites
    assert (a.data, a.colour, a.multicolor, a.overlay) == (SPRITE_A, 1, False, False)
    assert (b.data, b.colour, b.multicolor, b.overlay) == (SPRITE_B, 5, True, True)
    # 300 sprites: the count is 16-bit; read by content whatever the name
    path = tmp_path / "many.bin"
    path.write_bytes(preview_header(version, 300) + b"".join(struct.pack("<H", i) + bytes(61) + b"\x81"
                                                               for i in range(300)))
    frames = read_sprite_frames(path)
    assert len(frames) == 300 and frames[299].data[:2] == struct.pack("<H", 299) and frames[0].multicolor


def test_spritepad_preview_in_a_scene(tmp_path):
    (tmp_path / "p.spd").write_bytes(preview_header(3, 2) + SPRITE_A + b"\x01" + SPRITE_B + b"\x01")
    (tmp_path / "s.toml").write_text('chip = "vic-ii"\n[[sprite]]\nindex = 0\nx = 100\ny = 100\nfile = "p.spd"\n'
                                     'frame = 1\n')
    from retro.scenes import load_scene
    scene = load_scene(tmp_path / "s.toml")
    assert bytes(scene.sprites[0].data) == SPRITE_B


def test_spritepad_preview_cut_anywhere_is_one_line():
    raw = preview_header(2, 2) + SPRITE_A + b"\x01" + SPRITE_B + b"\x01"
    for n in range(4, len(raw)):
        with pytest.raises(InputError) as exc:
            parse_spd(raw[:n], "cut.spd")
        one_line(exc, "cut.spd: ")


def test_spritepad_pro_counts_past_255_sprites(tmp_path):
    count = 300
    blocks = b"".join(struct.pack("<H", i) + bytes(61) + bytes([0x01]) for i in range(count))
    path = tmp_path / "many.bin"  # not named .spd: read by content
    path.write_bytes(pro_header(5, count) + blocks)
    assert read_spr(path, 299)[:2] == struct.pack("<H", 299)
    with pytest.raises(InputError) as exc:
        read_spr(path, 300)
    one_line(exc, str(path), "frame: 300 is outside 0..299", "SpritePad")


@pytest.mark.parametrize("raw, message", [
    (pro_header(5, 2) + bytes(64), "says 2 sprites (148 bytes), file has 84 bytes"),
    (pro_header(5, 0), "says 0 sprites"),
    (pro_header(4, 1)[:12], "SpritePad Pro header is 12 bytes, needs 20"),
    (b"SPD" + bytes([9]) + bytes(80), "format version 9 is not supported"),
])
def test_bad_spritepad_pro_files_one_line(tmp_path, raw, message):
    path = tmp_path / "bad.spd"
    path.write_bytes(raw)
    with pytest.raises(InputError) as exc:
        read_spr(path)
    one_line(exc, str(path), message)


# ---- Spritemate ----------------------------------------------------------------------------------

def grid(fill=0):
    return [[fill] * 24 for _ in range(21)]


def spritemate_text(doc: dict) -> str:
    """As Spritemate's Save.ts writes it: compact JSON, then line breaks after "]," and around "[[" "]]"."""
    text = json.dumps(doc, separators=(",", ":"))
    return text.replace("],", "],\n").replace("[[", "[\n[").replace("]]", "]\n]")


def spritemate_pixels(legacy: bool):
    """Hires sprite: row 0 pens 1 at x 0 and 7, 2 at x 8, 3 at x 23 -> bytes 81 80 01.
    Multicolour sprite: even columns of row 0 pens 1, 2, 3, 0 -> pairs 10 01 11 00 = $9C; row 1 has
    pen 3 in every odd column only (ignored: zero); row 20 pen 3 in every even column -> ff ff ff."""
    hires = grid()
    hires[0][0], hires[0][7], hires[0][8], hires[0][23] = 1, 1, 2, 3
    multi = grid()
    multi[0][0:8] = [1, 1, 2, 2, 3, 3, 0, 0]
    multi[1] = [0, 3] * 12
    multi[20] = [3, 0] * 12
    if legacy:
        names = ("t", "i", "m1", "m2")
        hires = [[names[p] for p in row] for row in hires]
        multi = [[names[p] for p in row] for row in multi]
    return hires, multi


HIRES_BYTES = bytes([0x81, 0x80, 0x01]) + bytes(60)
MULTI_BYTES = bytes([0x9C, 0, 0]) + bytes(57) + bytes([0xFF, 0xFF, 0xFF])


def spritemate_legacy() -> str:
    """Before Spritemate's 2018-05-26 format change: pens and colour keys t, i, m1, m2; no version."""
    hires, multi = spritemate_pixels(legacy=True)
    return spritemate_text({"colors": {"t": 11, "m1": 7, "m2": 10}, "sprites": [
        {"color": 1, "multicolor": False, "double_x": False, "double_y": False, "overlay": False, "pixels": hires},
        {"color": 13, "multicolor": True, "double_x": True, "double_y": False, "overlay": True, "pixels": multi}],
        "current_sprite": 0, "pen": "i"})


def spritemate_numbered() -> str:
    """Numbered pens and colour keys "0", "2", "3", no version, no overlay key (as examples/bruce-lee.spm)."""
    hires, multi = spritemate_pixels(legacy=False)
    return spritemate_text({"colors": {"0": 11, "2": 7, "3": 10}, "sprites": [
        {"color": 1, "multicolor": False, "double_x": False, "double_y": False, "pixels": hires},
        {"color": 13, "multicolor": True, "double_x": True, "double_y": False, "pixels": multi}],
        "current_sprite": 1, "pen": 1})


def spritemate_current() -> str:
    """The current layout (SpriteTypes.ts): version, filename, sprite names, animation settings."""
    hires, multi = spritemate_pixels(legacy=False)
    animation = {"startSprite": 0, "endSprite": 1, "fps": 10, "mode": "restart", "doubleX": False, "doubleY": False}
    return spritemate_text({"version": "26.01.04", "filename": "ship", "colors": {"0": 11, "2": 7, "3": 10},
                            "sprites": [
                                {"name": "hull", "color": 1, "multicolor": False, "double_x": False,
                                 "double_y": False, "overlay": False, "pixels": hires, "animation": animation},
                                {"name": "flame", "color": 13, "multicolor": True, "double_x": True,
                                 "double_y": False, "overlay": True, "pixels": multi}],
                            "current_sprite": 0, "pen": 1, "animation": animation})


@pytest.mark.parametrize("make, version, overlay, names", [
    (spritemate_legacy, "legacy", True, ("sprite1", "sprite2")),
    (spritemate_numbered, "unversioned", False, ("sprite1", "sprite2")),
    (spritemate_current, "26.01.04", True, ("hull", "flame")),
])
def test_spritemate_each_generation(make, version, overlay, names):
    spm = parse_spm(make().encode(), "ship.spm")
    assert spm.version == version
    assert (spm.background, spm.multicolor1, spm.multicolor2) == (11, 7, 10)
    hires, multi = spm.sprites
    assert (hires.data, hires.colour, hires.multicolor, hires.expand_x) == (HIRES_BYTES, 1, False, False)
    assert (multi.data, multi.colour, multi.multicolor, multi.expand_x) == (MULTI_BYTES, 13, True, True)
    assert multi.overlay is overlay
    assert (hires.name, multi.name) == names


def test_spritemate_read_by_content_whatever_the_name(tmp_path):
    path = tmp_path / "ship.txt"
    path.write_text(spritemate_current())
    assert read_spr(path, 1) == MULTI_BYTES
    frames = read_sprite_frames(path)
    assert [(f.multicolor, f.colour, f.name) for f in frames] == [(False, 1, "hull"), (True, 13, "flame")]


@pytest.mark.parametrize("text, message", [
    ("{\"colors\": {", "not a Spritemate file: JSON error at line 1"),
    ("[" * 100000 + "]" * 100000, "not a Spritemate file"),
    (json.dumps({"colors": {"0": 0, "2": 1, "3": 2}, "sprites": [{"color": 1, "pixels": grid()[:20]}]}),
     "sprites[0].pixels: expected 21 rows of 24 pens, got 20"),
    (json.dumps({"colors": {"0": 0, "2": 1, "3": 2},
                 "sprites": [{"color": 1, "pixels": [[0] * 24] * 3 + [[0] * 4 + [5] + [0] * 19] + [[0] * 24] * 17}]}),
     "sprites[0].pixels[3][4]: 5 is not a pen"),
    (json.dumps({"colors": {"0": 0, "2": 16, "3": 2}, "sprites": [{"color": 1, "pixels": grid()}]}),
     "colors.2: 16 is not a C64 colour"),
    (json.dumps({"colors": {"0": 0, "2": 1, "3": 2}, "sprites": [{"pixels": grid()}]}), "sprites[0].color: missing"),
    (json.dumps({"colors": {"0": 0, "2": 1, "3": 2}, "sprites": []}), "sprites: expected a list of at least one"),
    (json.dumps({"colors": {"0": 0, "2": 1, "3": 2}, "sprites": [{}] * 4097}), "4097 sprites, at most 4096"),
    # numbers Python would choke on (int() of 4,300+ digits) or JSON does not have: one line, with where
    ('{"colors": {"0": 0, "2": 1, "3": ' + "9" * 5000 + '}, "sprites": []}',
     "not a Spritemate file: line 1 column 34: 3: a number of 5000 characters (at most 80 are read)"),
    ('{"colors": {"0": 0, "2": 1, "3": 2},\n "sprites": [{"color": -' + "7" * 5000 + '}]}',
     "line 2 column 24: color: a number of 5001 characters"),
    ('{"colors": {"0": 0, "2": 1, "3": 1.' + "5" * 5000 + '}, "sprites": []}', "line 1 column 34: 3: a number of 5002"),
    ('{"colors": {"0": NaN, "2": 1, "3": 2}, "sprites": []}', "line 1 column 18: 0: NaN is not a JSON number"),
    ('{"colors": {"0": 0, "2": -Infinity, "3": 2}, "sprites": []}', "line 1 column 26: 2: -Infinity is not a JSON number"),
])
def test_bad_spritemate_files_one_line(tmp_path, text, message):
    path = tmp_path / "bad.spm"
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        read_spr(path)
    one_line(exc, str(path), message)


# ---- PNG sprites and sheets ----------------------------------------------------------------------

def picture(width: int, height: int, fill=CLEAR) -> Image.Image:
    return Image.new("RGBA", (width, height), fill)


def opaque(rgb) -> tuple[int, int, int, int]:
    return (*rgb, 255)


def save(image: Image.Image, path):
    image.save(path)
    return path


def test_png_hires_sheet_frames_left_to_right_then_down(tmp_path):
    """48x42: four sprites; sprite k has one white pixel at x = k of its top row -> byte 0 = $80 >> k."""
    image = picture(48, 42)
    for k, (left, top) in enumerate([(0, 0), (24, 0), (0, 21), (24, 21)]):
        image.putpixel((left + k, top), opaque(PEPTO[1]))
    path = save(image, tmp_path / "sheet.png")
    for k in range(4):
        assert read_png(path, frame=k) == bytes([0x80 >> k]) + bytes(62)
    with pytest.raises(InputError) as exc:
        read_png(path, frame=4)
    one_line(exc, str(path), "frame: 4 is outside 0..3")


def test_png_hires_background_is_the_scenes_d021(tmp_path):
    """A picture on the editor's background colour (Spritemate's default, dark grey 11): with $D021 = 11
    only the white pixel is set; read as if on black, every dark grey pixel would be set."""
    image = picture(24, 21, opaque(COLODORE[11]))
    image.putpixel((0, 0), opaque(COLODORE[1]))
    path = save(image, tmp_path / "grey.png")
    assert read_png(path, colours=SpriteColours(background=11)) == bytes([0x80]) + bytes(62)
    assert read_png(path) == bytes([0xFF] * 63)


def multicolour_row(image: Image.Image, palette, cell_pixel: int):
    """Row 0: $D025 red (2), sprite colour green (5), $D026 yellow (7), then black, on dark grey (11)
    -> pairs 01 10 11 00 = $6C."""
    for i, colour in enumerate((2, 5, 7, 0)):
        for dx in range(cell_pixel):
            image.putpixel((i * cell_pixel + dx, 0), opaque(palette[colour]))
    image.putpixel((0, 1), CLEAR)  # transparent: 00 too


SCENE_COLOURS = SpriteColours(background=11, multicolor1=2, colour=5, multicolor2=7)
MC_EXPECTED = bytes([0x6C]) + bytes(62)


@pytest.mark.parametrize("palette", [PEPTO, COLODORE])
def test_png_multicolour_in_the_sprites_own_colours(tmp_path, palette):
    image = picture(24, 21, opaque(palette[11]))
    multicolour_row(image, palette, 2)
    path = save(image, tmp_path / "mc_real.png")
    assert read_png(path, multicolor=True, colours=SCENE_COLOURS) == MC_EXPECTED
    sheet = read_png_sheet(path.read_bytes(), str(path), True, SCENE_COLOURS)
    assert sheet.palette == ("c64-pepto" if palette is PEPTO else "c64-colodore")  # found by exact colours


def test_png_multicolour_12_wide_and_a_sheet_of_them(tmp_path):
    image = picture(12, 21, opaque(PEPTO[11]))
    multicolour_row(image, PEPTO, 1)
    path = save(image, tmp_path / "narrow.png")
    assert read_png(path, multicolor=True, colours=SCENE_COLOURS) == MC_EXPECTED
    # 48 wide with pairs that differ: four 12-wide sprites; sprite 1 starts with one red pixel
    sheet = picture(48, 21)
    sheet.putpixel((12, 0), opaque(PEPTO[2]))
    path = save(sheet, tmp_path / "four.png")
    frames = read_png_sheet(path.read_bytes(), str(path), True, SCENE_COLOURS)
    assert frames.cell_width == 12 and len(frames.frames) == 4
    assert frames.frames[1] == bytes([0x40]) + bytes(62)


def test_png_scene_reads_a_sheet_frame_in_its_colours(tmp_path):
    """The scene's registers give the colours: sprite 0 is frame 1 of a two-sprite multicolour sheet."""
    from retro.scenes.vic import load

    image = picture(48, 21, opaque(COLODORE[11]))
    for i, colour in enumerate((2, 5, 7, 0)):
        for dx in range(2):
            image.putpixel((24 + 2 * i + dx, 0), opaque(COLODORE[colour]))
    save(image, tmp_path / "sheet.png")
    (tmp_path / "s.toml").write_text('chip = "vic-ii"\n[registers]\n"$d021" = 11\n"$d025" = 2\n"$d026" = 7\n'
                                     '[[sprite]]\nindex = 0\nmulticolor = true\ncolor = 5\nfile = "sheet.png"\n'
                                     'frame = 1\npalette = "c64-colodore"\n')
    assert load(tmp_path / "s.toml").sprites[0].data == MC_EXPECTED


@pytest.mark.parametrize("draw, message", [
    # a colour half way between Pepto's red (2) and orange (8): no nearest colour
    (lambda im: im.putpixel((5, 7), (108, 67, 40, 255)), "pixel (5, 7): colour #6c4328 is about as near C64 colour"),
    (lambda im: im.putpixel((3, 4), (255, 255, 255, 128)), "pixel (3, 4) is partly transparent (alpha 128)"),
    (lambda im: im.putpixel((9, 2), opaque(PEPTO[3])), "pixel (9, 2) is C64 colour 3 (cyan), none of this sprite's"),
    (lambda im: im.putpixel((2, 6), opaque(PEPTO[2])), "pixels (2, 6) and (3, 6) differ"),
])
def test_bad_png_pixels_one_line_naming_the_pixel(tmp_path, draw, message):
    image = picture(24, 21, opaque(PEPTO[11]))
    draw(image)
    path = save(image, tmp_path / "bad.png")
    with pytest.raises(InputError) as exc:
        read_png(path, multicolor=True, colours=SCENE_COLOURS)
    one_line(exc, str(path), message)


def test_png_palette_choice_matters(tmp_path):
    """Pepto's light blue (14) read through Colodore is about as near Colodore's light blue as its purple
    (56.2 and 56.7 apart): refused, naming the pixel; read through Pepto (chosen, or found) it is 14."""
    image = picture(24, 21)
    image.putpixel((4, 0), opaque(PEPTO[14]))
    image.putpixel((5, 0), opaque(PEPTO[14]))
    path = save(image, tmp_path / "mc_pepto.png")
    with pytest.raises(InputError) as exc:
        read_png(path, multicolor=True, palette="c64-colodore")
    one_line(exc, "pixel (4, 0)", "light blue", "purple", "c64-colodore")
    expected = bytes([0b00000100]) + bytes(62)  # third pair 01: light blue is $D025's preview colour
    assert read_png(path, multicolor=True) == expected
    assert read_png(path, multicolor=True, palette="c64-pepto") == expected
    with pytest.raises(InputError, match="not a C64 palette"):
        read_png(path, palette="nes")


def png_header_only(width: int, height: int) -> bytes:
    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + chunk(b"IEND", b""))


@pytest.mark.parametrize("size, multicolor, message", [
    ((25, 21), False, "a sprite PNG is 24x21 pixels or a sheet of them (multiples of 24x21), got 25x21"),
    ((12, 21), False, "got 12x21"),
    ((18, 21), True, "or multiples of 12x21 for multicolour), got 18x21"),
    ((24 * 40, 21 * 30), False, "holds up to 1200 sprites; at most 1024 are read"),
])
def test_png_sizes_checked_from_the_header(tmp_path, size, multicolor, message):
    path = tmp_path / "size.png"
    path.write_bytes(png_header_only(*size))  # no pixel data: a size error comes before decoding
    with pytest.raises(InputError) as exc:
        read_png(path, multicolor=multicolor)
    one_line(exc, str(path), message)


def test_png_read_by_content_whatever_the_name(tmp_path):
    image = picture(24, 21)
    image.putpixel((23, 20), opaque(PEPTO[1]))
    path = save(image, tmp_path / "one.png").rename(tmp_path / "one.dat")
    assert read_sprite(path) == bytes(62) + bytes([0x01])


def test_palette_goes_with_png_only(tmp_path):
    path = tmp_path / "a.spr"
    path.write_bytes(SPRITE_A + b"\0")
    with pytest.raises(InputError) as exc:
        read_sprite(path, palette="c64-pepto")
    one_line(exc, str(path), "only a PNG's colours go through a palette")


# ---- through the commands ------------------------------------------------------------------------

def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "retro", *args], capture_output=True, text=True)


def test_scene_with_pro_spritemate_and_png_sheet_and_bad_frames(tmp_path):
    """Sprite 0 from a Pro 5 file (A, top row), sprite 1 from Spritemate (B-like bottom row in the
    multicolour sprite: row 20 all set), sprite 2 from a PNG sheet frame: each collides as its bytes say."""
    (tmp_path / "pro.spd").write_bytes(pro_header(5, 2) + SPRITE_A + bytes([1]) + SPRITE_B + bytes([1]))
    (tmp_path / "mate.spm").write_text(spritemate_current())
    sheet = picture(48, 21)
    for x in range(24):
        sheet.putpixel((24 + x, 0), opaque(PEPTO[1]))  # frame 1: top row set
    save(sheet, tmp_path / "sheet.png")
    scene = ('chip = "vic-ii"\n'
             '[[sprite]]\nindex = 0\nx = 100\ny = 100\nfile = "pro.spd"\n'
             '[[sprite]]\nindex = 1\nx = 100\ny = 80\nmulticolor = true\nfile = "mate.spm"\nframe = 1\n'
             '[[sprite]]\nindex = 2\nx = 200\ny = 100\nfile = "sheet.png"\nframe = {frame}\n')
    (tmp_path / "good.toml").write_text(scene.format(frame=1))
    good = run("vic", str(tmp_path / "good.toml"), "--json")
    assert good.returncode == 0, good.stderr
    pairs = {tuple(p["sprites"]): p["pixels"] for p in json.loads(good.stdout)["pairs"]}
    # sprite 1's row 20 (y 100) is all set; sprite 0's top row has 10 set pixels at y 100
    assert pairs == {(0, 1): 10}
    (tmp_path / "bad.toml").write_text(scene.format(frame=2))
    bad = run("vic", str(tmp_path / "bad.toml"))
    assert bad.returncode == 2
    assert bad.stderr.count("\n") == 1 and "sprite[2]" in bad.stderr and "frame: 2 is outside 0..1" in bad.stderr


def test_chart_sprites_reads_the_new_formats(tmp_path):
    from retro.analysis.study.sprites_io import load_sprite_files

    (tmp_path / "pro.spd").write_bytes(pro_header(5, 2) + SPRITE_A + bytes([0x01]) + SPRITE_B + bytes([0x81]))
    (tmp_path / "mate.spm").write_text(spritemate_current())
    sheet = picture(48, 21)
    sheet.putpixel((0, 0), opaque(PEPTO[1]))
    sheet.putpixel((30, 5), opaque(PEPTO[1]))
    save(sheet, tmp_path / "sheet.png")
    shapes = load_sprite_files([str(tmp_path / n) for n in ("pro.spd", "mate.spm", "sheet.png")])
    assert [(s.name, s.multicolor) for s in shapes] == [("pro.0", False), ("pro.1", True), ("mate.0", False),
                                                        ("mate.1", True), ("sheet.0", False), ("sheet.1", False)]
    assert shapes[5].data == bytes([0] * 15 + [0x02]) + bytes(47)  # x 30 = bit 1 of byte 0 of row 5
