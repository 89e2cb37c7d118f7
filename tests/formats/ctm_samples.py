"""CharPad .ctm sample files written field by field from the format tables in CharPad's manuals
(CharPad 2.3 User Manual: versions 1-5; CharPad 2.6 User Manual: version 6) and, for version 7's
12-byte header and versions 8, 82 and 9 (and the CharPad 2.8 preview layout of version 8), the
readers named in retro/loaders/gfx_charpad.py (c64lib, Oscar64, C64Studio). Nothing here calls the
reader: the expected screen, colours and materials are worked out by plain loops over the same
level description.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

BLANK, SOLID, LEFT_PAIR, WIDE = [0] * 8, [0xFF] * 8, [0x40] * 8, [0xC0] * 8


@dataclass
class Level:
    """A small level: chars, per-char materials and colours, a tile set, tile and cell colours, a map."""

    tile_h: int = 2
    tile_w: int = 2
    tiles_on: bool = True
    multicolor: bool = False
    background: int = 6
    mc1: int = 11
    mc2: int = 12
    char_colour: int = 14  # the global colour
    chars: list = field(default_factory=lambda: [BLANK, SOLID, LEFT_PAIR, WIDE])
    materials: list = field(default_factory=lambda: [0, 1, 2, 15])
    char_colours: list = field(default_factory=lambda: [0, 1, 9, 5])
    tile_colours: list = field(default_factory=lambda: [0, 3, 10])
    map_w: int = 21   # in map entries (tiles, or chars without tiles)
    map_h: int = 13

    def tiles(self) -> list[list[list[int]]]:
        """Three tiles: blank; chars 1, 2, 3, 1 repeating; all char 2."""
        pattern = [1, 2, 3]
        t1 = [[pattern[(r * self.tile_w + c) % 3] for c in range(self.tile_w)] for r in range(self.tile_h)]
        return [[[0] * self.tile_w for _ in range(self.tile_h)], t1, [[2] * self.tile_w for _ in range(self.tile_h)]]

    def cell_colours(self) -> list[list[list[int]]]:
        """Per-tile-cell colours: 7, 8, 9, ... through each tile's cells (tile 0 all 0)."""
        out = [[[0] * self.tile_w for _ in range(self.tile_h)]]
        for t in (1, 2):
            out.append([[(7 + t + r * self.tile_w + c) % 16 for c in range(self.tile_w)] for r in range(self.tile_h)])
        return out

    def map(self) -> list[list[int]]:
        grid = [[0] * self.map_w for _ in range(self.map_h)]
        if self.tiles_on:
            grid[2][3] = 1
            grid[5][10] = 2
            grid[0][0] = 1
        else:
            grid[4][6], grid[4][7], grid[5][6] = 1, 2, 3
            grid[10][20] = 2
            grid[0][0] = 3
        return grid

    # ---- the expected screen, by hand ----------------------------------------------------------

    def screen_cell(self, col: int, row: int) -> tuple[int, int, int] | None:
        """(code, tile number or None, the cell's (r, c) in its tile) at screen cell (col, row)."""
        th, tw = (self.tile_h, self.tile_w) if self.tiles_on else (1, 1)
        if row >= self.map_h * th or col >= self.map_w * tw:
            return None
        entry = self.map()[row // th][col // tw]
        if not self.tiles_on:
            return entry, None, (0, 0)
        return self.tiles()[entry][row % th][col % tw], entry, (row % th, col % tw)

    def expected_colour(self, col: int, row: int, colouring: str) -> int:
        code, tile, (r, c) = self.screen_cell(col, row)
        if colouring == "global":
            return self.char_colour
        if colouring == "per-char":
            return self.char_colours[code]
        if colouring == "per-tile":
            return self.tile_colours[tile]
        return self.cell_colours()[tile][r][c]


COLOURING = {"global": 0, "per-tile": 1, "per-char": 2, "per-tile-cell": 2}


def _u16(*values: int) -> bytes:
    return struct.pack(f"<{len(values)}H", *values)


def _flat(grid) -> list[int]:
    return [v for row in grid for v in row]


def _tile_bytes(level: Level, width: int) -> bytes:
    codes = [v for tile in level.tiles() for v in _flat(tile)]
    return bytes(codes) if width == 1 else _u16(*codes)


def _colours(level: Level) -> bytes:
    return bytes([level.background, level.mc1, level.mc2, level.char_colour])


def v1(level: Level, colouring: str) -> bytes:
    """CharPad 1.0: 20-byte header; 4x4 tiles of 8-bit codes; cell colours before tile colours."""
    assert (level.tile_h, level.tile_w) == (4, 4) and level.tiles_on
    header = (b"CTM" + bytes([1]) + _colours(level) + bytes([COLOURING[colouring], int(level.multicolor)])
              + _u16(level.map_w, level.map_h) + bytes([len(level.chars) - 1, len(level.tiles()) - 1]) + bytes(4))
    data = bytes(_flat(level.chars)) + _tile_bytes(level, 1)
    if colouring == "per-tile-cell":
        data += bytes(v for tile in level.cell_colours() for v in _flat(tile))
    if colouring == "per-tile":
        data += bytes(level.tile_colours)
    return header + data + bytes(_flat(level.map()))


def v2(level: Level, colouring: str) -> bytes:
    """CharPad 1.7: 20-byte header; 9 bytes a char (the 9th its material); square tiles, 16-bit."""
    assert level.tile_h == level.tile_w and level.tiles_on
    header = (b"CTM" + bytes([2]) + _colours(level) + bytes([COLOURING[colouring], int(level.multicolor)])
              + _u16(level.map_w, level.map_h, len(level.chars) - 1) + bytes([len(level.tiles()) - 1, level.tile_w])
              + bytes(2))
    data = b"".join(bytes(glyph + [material]) for glyph, material in zip(level.chars, level.materials))
    data += _tile_bytes(level, 2)
    if colouring == "per-tile":
        data += bytes(level.tile_colours)
    if colouring == "per-tile-cell":
        data += bytes(v for tile in level.cell_colours() for v in _flat(tile))
    return header + data + bytes(_flat(level.map()))


def v4(level: Level, colouring: str, charex: int = 0) -> bytes:
    """CharPad 1.8 Rev 3: 24-byte header; char attributes and tile-cell attributes, MMMMCCCC."""
    header = (b"CTM" + bytes([4]) + _colours(level) + bytes([COLOURING[colouring], int(level.multicolor)])
              + _u16(len(level.chars) - 1) + bytes([len(level.tiles()) - 1, level.tile_w, level.tile_h])
              + _u16(level.map_w, level.map_h) + bytes([charex]) + bytes(4))
    data = bytes(_flat(level.chars)) + bytes(m << 4 for m in level.materials) + _tile_bytes(level, 2)
    data += bytes((0x30 | c) for tile in level.cell_colours() for c in _flat(tile))  # material 3 in every cell
    if colouring == "per-tile":
        data += bytes(level.tile_colours)
    return header + data + bytes(_flat(level.map()))


def v3(level: Level, colouring: str, charex: int = 0) -> bytes:
    """CharPad 1.8 before Rev 3: 20-byte header; square tiles; tile-cell attributes MMMMCCCC (material
    3 + tile number in every cell of a tile); no char attributes; an 8-bit map."""
    assert level.tile_h == level.tile_w and level.tiles_on
    header = (b"CTM" + bytes([3]) + _colours(level) + bytes([COLOURING[colouring], int(level.multicolor)])
              + _u16(level.map_w, level.map_h, len(level.chars) - 1) + bytes([len(level.tiles()) - 1, level.tile_w])
              + bytes([charex, 0]))
    data = bytes(_flat(level.chars)) + _tile_bytes(level, 2)
    data += bytes(((3 + t) << 4) | c for t, tile in enumerate(level.cell_colours()) for c in _flat(tile))
    if colouring == "per-tile":
        data += bytes(level.tile_colours)
    return header + data + bytes(_flat(level.map()))


# versions 8, 82, 9: display modes and what a colour entry holds
MODE_BYTES = {"hires": 0, "multicolor": 1, "ecm": 2, "bitmap-hires": 3, "bitmap-multicolor": 4}
BASE_SCREEN = (7, 8)  # the global screen-matrix low and high nybble in the samples


def screen_lo_hi(kind: str, index: int) -> tuple[int, int]:
    """The sample's screen-matrix colours (low, high nybble) of char or tile `index`."""
    return ((index + 3) % 16, (index + 5) % 16) if kind == "char" else ((index + 11) % 16, (index + 2) % 16)


def _entry(mode: str, colour: int, lo: int, hi: int, prototype: bool) -> bytes:
    """One colour entry: text modes the colour matrix; bitmap hires screen low, high; bitmap
    multicolour colour matrix, screen low, high; the preview layout 4 bytes, colour matrix last."""
    if prototype:
        return bytes([12, 13, 14, colour])
    return {"bitmap-hires": bytes([lo, hi]), "bitmap-multicolor": bytes([colour, lo, hi])}.get(mode, bytes([colour]))


def v8(level: Level, colouring: str, version: int = 8, mode: str | None = None, prototype: bool = False,
       flexigrid: bytes = b"\x28\x00\x19\x00\x00") -> bytes:
    """CharPad 2.8+ / Pro: display mode, colouring, flags (b0 TILESYS); version 9 the flexigrid
    (width, height 16-bit, configuration); screen colour, multicolour 1, 2, background 4, base colours
    (colour matrix, screen low, high; the preview layout a 4th, the colour matrix); then blocks: chars,
    materials (a byte a char), [char colours], [tiles, [tile colours], tags, names], map."""
    mode = mode or ("multicolor" if level.multicolor else "hires")
    header = bytes([MODE_BYTES[mode], COLOURING[colouring], 1 if level.tiles_on else 0])
    if version == 9:
        header += flexigrid
    header += bytes([level.background, level.mc1, level.mc2, 4])
    header += bytes([9, 10, 11, level.char_colour]) if prototype else bytes([level.char_colour, *BASE_SCREEN])
    blocks = [_u16(len(level.chars) - 1) + bytes(_flat(level.chars)), bytes(level.materials)]
    if colouring == "per-char":
        blocks.append(b"".join(_entry(mode, c, *screen_lo_hi("char", i), prototype)
                               for i, c in enumerate(level.char_colours)))
    if level.tiles_on:
        tiles = level.tiles()
        blocks.append(_u16(len(tiles) - 1) + bytes([level.tile_w, level.tile_h]) + _tile_bytes(level, 2))
        if colouring == "per-tile":
            blocks.append(b"".join(_entry(mode, c, *screen_lo_hi("tile", i), prototype)
                                   for i, c in enumerate(level.tile_colours)))
        blocks.append(bytes(range(len(tiles))))
        blocks.append(b"".join(f"t{i}".encode() + b"\0" for i in range(len(tiles))))
    blocks.append(_u16(level.map_w, level.map_h) + _u16(*_flat(level.map())))
    body = b"".join(bytes([0xDA, 0xB0 + n]) + block for n, block in enumerate(blocks))
    return b"CTM" + bytes([version]) + header + body


def _attributes(level: Level, colouring: str) -> bytes:
    """MMMMCCCC per char; [CP26]: colours only stored with per-character colouring."""
    return bytes(m << 4 | (c if colouring == "per-char" else 0) for m, c in zip(level.materials, level.char_colours))


def v5(level: Level, colouring: str, charex: bool = False) -> bytes:
    """CharPad 2.0-2.3: 20-byte header with FLAGS (b0 TILESYS, b1 CHAREX, b2 MCMODE); 16-bit map."""
    flags = (1 if level.tiles_on else 0) | (2 if charex else 0) | (4 if level.multicolor else 0)
    tiles = level.tiles() if level.tiles_on else [[[0]]]
    header = (b"CTM" + bytes([5]) + _colours(level) + bytes([COLOURING[colouring], flags])
              + _u16(len(level.chars) - 1, len(tiles) - 1) + bytes([len(tiles[0][0]), len(tiles[0])])
              + _u16(level.map_w, level.map_h))
    data = bytes(_flat(level.chars)) + _attributes(level, colouring)
    if level.tiles_on and not charex:
        data += _tile_bytes(level, 2)
    if level.tiles_on and colouring == "per-tile":
        data += bytes(level.tile_colours)
    return header + data + _u16(*_flat(level.map()))


def _blocks(level: Level, colouring: str) -> bytes:
    """Versions 6 and 7: blocks, each behind $DA $B0+n."""
    blocks = [_u16(len(level.chars) - 1) + bytes(_flat(level.chars)), _attributes(level, colouring)]
    if level.tiles_on:
        tiles = level.tiles()
        blocks.append(_u16(len(tiles) - 1) + bytes([level.tile_w, level.tile_h]) + _tile_bytes(level, 2))
        if colouring == "per-tile":
            blocks.append(bytes(level.tile_colours))
        blocks.append(bytes(range(len(tiles))))  # tile tags
        blocks.append(b"".join(f"tile{i}".encode() + b"\0" for i in range(len(tiles))))  # names
    blocks.append(_u16(level.map_w, level.map_h) + _u16(*_flat(level.map())))
    return b"".join(bytes([0xDA, 0xB0 + n]) + block for n, block in enumerate(blocks))


def v6(level: Level, colouring: str) -> bytes:
    """CharPad 2.6: 10-byte header, FLAGS b0 MCMODE, b1 TILESYS."""
    flags = (1 if level.multicolor else 0) | (2 if level.tiles_on else 0)
    return b"CTM" + bytes([6]) + _colours(level) + bytes([COLOURING[colouring], flags]) + _blocks(level, colouring)


def v7(level: Level, colouring: str, mode: int | None = None) -> bytes:
    """CharPad 2.7: 12-byte header: screen colour, multicolour 1, 2, background 4, char colour,
    colouring method, display mode (0 hires, 1 multicolour, 2 ECM), flags (b0 TILESYS)."""
    mode = (1 if level.multicolor else 0) if mode is None else mode
    header = bytes([level.background, level.mc1, level.mc2, 0, level.char_colour, COLOURING[colouring], mode,
                    1 if level.tiles_on else 0])
    return b"CTM" + bytes([7]) + header + _blocks(level, colouring)


WRITERS = {1: v1, 2: v2, 3: v3, 4: v4, 5: v5, 6: v6, 7: v7, 8: v8, 9: lambda level, c: v8(level, c, 9),
           82: lambda level, c: v8(level, c, 82)}
OLD, NEW = ("global", "per-tile", "per-tile-cell"), ("global", "per-tile", "per-char")
COLOURINGS = {1: OLD, 2: OLD, 3: OLD, 4: OLD, 5: NEW, 6: NEW, 7: NEW, 8: NEW, 9: NEW, 82: NEW}


def level_for(version: int, **kw) -> Level:
    return Level(tile_h=4, tile_w=4, **kw) if version == 1 else Level(**kw)
