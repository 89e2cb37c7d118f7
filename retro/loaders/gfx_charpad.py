"""CharPad projects (.ctm): charset, map, colours and the per-character material nibble.

Sources, read for the layouts only:
- [CP23] CharPad 2.3 User Manual, Subchrist Software 2019, "CTM File Format" versions 1-5.
- [CP26] CharPad 2.6 User Manual, Subchrist Software 2020, "CTM File Format, Version 6".
- [C64LIB] c64lib's gradle-retro-assembler-plugin, processors/charpad (CTM6Processor,
  CTM7Processor, BlockBasedCTMProcessor; commit 79d5c0e): the v6 map and tile-name blocks, which
  [CP26] cuts short, and the v7 header. The version 5, 6 and 7 layouts were checked against the
  .ctm files CharPad wrote in that repository's test resources (hires and multicolour, global,
  per-tile and per-char colouring, with and without tiles): each parses to its last byte, and the
  three versions of a project give the same charset, materials, map and colours.

Every version starts with "CTM" and a version byte; 16-bit values are little-endian; tiles and the
map run left to right, top to bottom.

- 1 (CharPad 1.0): 20-byte header; chars of 8 bytes; 4x4 tiles of 8-bit codes; cell colours
  (per-tile-cell colouring) or tile colours (per-tile); an 8-bit map of tiles; no materials [CP23].
- 2 (CharPad 1.7): 20-byte header; chars of 9 bytes, the 9th the material; square tiles of 16-bit
  codes; tile colours or cell colours; an 8-bit map of tiles [CP23].
- 3 (CharPad 1.8 before Rev 3): 20-byte header (map size, chars, tiles, square tile size, CHAREX);
  chars; tiles (16-bit); tile-cell attributes MMMMCCCC; tile colours; an 8-bit map [CP23]. Its
  materials belong to tile cells, not characters: `cell_materials` holds them and `material_table`
  refuses the project with one line (CharPad itself derives per-character attributes only from
  version 4 on).
- 4 (CharPad 1.8 Rev 3): 24-byte header; chars; char attributes MMMMCCCC; tiles (16-bit); tile-cell
  attributes MMMMCCCC; tile colours; an 8-bit map of tiles [CP23].
- 5 (CharPad 2.0-2.3): 20-byte header with flags (b0 tile system, b1 CHAREX, b2 multicolour); chars;
  char attributes; tiles when the tile system is on; tile colours; a 16-bit map [CP23].
- 6 (CharPad 2.6): 10-byte header (flags b0 multicolour, b1 tile system), then blocks, each behind
  the marker $DA, $B0+n: chars, char attributes, [tiles, tile colours, tile tags, tile names], map
  [CP26, C64LIB].
- 7 (CharPad 2.7): 12-byte header (screen colour, multicolour 1 and 2, background 4, char colour,
  colouring method, display mode, flags b0 tile system), blocks as in version 6 [C64LIB].
- 8, 9 and 82 (CharPad 2.8 and later, CharPad Pro; 82 is what some CharPad 3.0x builds write for
  8.2): header with display mode (0 hires, 1 multicolour, 2 ECM, 3 bitmap hires, 4 bitmap
  multicolour), colouring method, flags (b0 tile system), in version 9 the flexigrid width, height
  (16-bit) and configuration byte, then the screen colour, multicolour 1, 2, background 4 and the
  three base cell colours (colour matrix, screen matrix low and high nybble). Blocks as in version 6,
  but block 1 holds one material byte a character, and the colours move into their own blocks: char
  colours (per-char colouring, block 2) and tile colours (per-tile colouring, after the tiles), each
  entry 1 byte in the text modes (colour matrix), 2 in bitmap hires (screen low, high) and 3 in
  bitmap multicolour (colour matrix, screen low, high) [C64LIB CTM8Processor, CTM9Processor;
  OSCAR64 Preprocessor.cpp CTMHeader8/CTMHeader9, ReadCharPad; C64STUDIO CharpadProject.cs
  LoadVersion8, which quotes the block notes]. Checked against 27 .ctm files of version 8 and 82
  written by CharPad in drmortalwombat's public game repositories (OscarTutorials, bunkerdigger,
  zombies, MetalMayhem, shalldom, minotrace) and c64lib's 6 release-layout version 8 files: each
  parses to its last byte, and c64lib's projects saved as versions 5 to 8 give the same charset,
  map, materials, screen and colours. No version 9 file was found: version 9 rests on c64lib's and
  Oscar64's readers, which agree on its header.
- 8, prototype layout (CharPad 2.8 preview builds): a 4th base colour in the header (the block marker
  at byte 15, not 14) and 4 bytes a colour entry, the colour-RAM colour the 4th [C64LIB, its
  `ctm8PrototypeCompatibility`]; told from the release layout by where the first block marker is.
  Checked against c64lib's 6 prototype files, which match their version 7 and release version 8
  saves. Read in the text modes only: no bitmap-mode prototype file was seen.

Refused with one line: any other version, and a version 3, 4 or 5 file whose charset is "expanded"
(CHAREX): its tile data is absent and the rule that replaces it is in notes [CP23] cuts short.

[C64STUDIO] GeorgRottensteiner/C64Studio, Common/Formats/CharpadProject.cs. [OSCAR64]
drmortalwombat/oscar64, oscar64/Preprocessor.cpp.

The material is the high nibble of a character's attribute byte (the 9th byte of a character in
version 2, the low nibble of its material byte from version 8 on), 0-15; `material_table` gives it
per character code, the property table the `tile` and `tile_box` routines index by screen code
(docs/specs.md, "CharPad materials").
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from retro.chips.vic.constants import CHAR_HEIGHT, CHARSET_BYTES, COLOR_MASK, TEXT_COLUMNS, TEXT_ROWS
from retro.errors import InputError
from retro.fileio import read_bytes

MAGIC = b"CTM"
BLOCK_MARK = 0xDA
BLOCK_BASE = 0xB0
CODES = 256  # screen codes
NIBBLE = 4
MODES = {0: "hires", 1: "multicolor", 2: "ecm"}  # v7 display mode byte
V8_MODES = {**MODES, 3: "bitmap-hires", 4: "bitmap-multicolor"}  # v8, v9 display mode byte
BITMAP_MODES = ("bitmap-hires", "bitmap-multicolor")
OLD_COLOURING = {0: "global", 1: "per-tile", 2: "per-tile-cell"}  # versions 1-4
NEW_COLOURING = {0: "global", 1: "per-tile", 2: "per-char"}  # versions 5-7
V5_TILESYS, V5_CHAREX, V5_MCMODE = 0x01, 0x02, 0x04
V6_MCMODE, V6_TILESYS = 0x01, 0x02
V7_TILESYS = 0x01
V8_TILESYS = 0x01
V1_TILE_SIZE = 4
V82 = 82  # written by some CharPad 3.0x builds for format 8.2: the version 8 release layout
READ_VERSIONS = (1, 2, 3, 4, 5, 6, 7, 8, 9, V82)
V8_HEADER = 14  # "CTM", version, mode, colouring, flags, 4 colours, 3 base colours
V8_PROTO_HEADER = 15  # ... and a 4th base colour
V9_FLEXIGRID = 5  # width, height (16-bit), configuration byte
# colour entry layout from version 8 on: (bytes an entry, index of the colour-matrix byte or None,
# index of the screen low nybble, of the high nybble)
ENTRY = {"hires": (1, 0, None, None), "multicolor": (1, 0, None, None), "ecm": (1, 0, None, None),
         "bitmap-hires": (2, None, 0, 1), "bitmap-multicolor": (3, 0, 1, 2)}
PROTO_ENTRY = (4, 3, None, None)  # prototype layout, text modes
SCREEN_NIBBLE = 4


@dataclass(frozen=True, eq=False)
class CharpadProject:
    """A CharPad project as plain data. Codes and tile numbers are 16-bit (CharPad allows more than
    256 characters); `window` gives what a 40 x 25 screen shows of the map."""

    version: int
    mode: str                      # "hires", "multicolor" or "ecm"
    colouring: str                 # "global", "per-tile", "per-char" or "per-tile-cell"
    background: int                # screen colour ($D021)
    multicolor1: int               # $D022
    multicolor2: int               # $D023
    char_colour: int               # the global char colour (colour RAM)
    chars: np.ndarray              # (n, 8) uint8 glyph rows
    materials: np.ndarray          # (n,) uint8 0-15
    char_colours: np.ndarray | None  # (n,) colour nibbles, per-char colouring
    tiles: np.ndarray | None       # (t, h, w) uint16 char codes; None: the map holds char codes
    tile_colours: np.ndarray | None  # (t,) per-tile colouring
    cell_colours: np.ndarray | None  # (t, h, w) per-tile-cell colouring (versions 1-4)
    map: np.ndarray                # (rows, columns) uint16: tile numbers, or char codes without tiles
    cell_materials: np.ndarray | None = None  # (t, h, w) version 3: materials per tile cell
    screen_colour: int = 0         # bitmap modes: the global screen-RAM byte (high, low nybble)
    char_screen: np.ndarray | None = None  # (n,) bitmap modes, per-char colouring: screen-RAM bytes
    tile_screen: np.ndarray | None = None  # (t,) bitmap modes, per-tile colouring: screen-RAM bytes
    layout: str = ""               # "prototype" for the CharPad 2.8 preview layout of version 8

    @property
    def bitmap_mode(self) -> bool:
        return self.mode in BITMAP_MODES

    @property
    def cell_size(self) -> tuple[int, int]:
        """Screen cells per map entry: (height, width) of a tile, (1, 1) without tiles."""
        return (1, 1) if self.tiles is None else self.tiles.shape[1:]

    @property
    def size(self) -> tuple[int, int]:
        """The map in screen cells: (rows, columns)."""
        h, w = self.cell_size
        return self.map.shape[0] * h, self.map.shape[1] * w

    def charset(self) -> bytes:
        """The first 256 characters as 2048 bytes (codes beyond the project's count are zero)."""
        glyphs = self.chars[:CODES].tobytes()
        return glyphs.ljust(CHARSET_BYTES, b"\0")

    def material_table(self, name: str = "CharPad file") -> bytes:
        """256 bytes: the material (0-15) of each screen code; codes the project lacks are 0."""
        if self.materials is None:
            raise InputError(f"{name}: CHAR_ATTRIBS: a version {self.version} project keeps its materials per tile "
                             f"cell (CELL_ATTRIBS), not per character; save it in CharPad 1.8 Rev 3 or later")
        return self.materials[:CODES].tobytes().ljust(CODES, b"\0")

    def _cells(self, col: int, row: int, name: str):
        """The 40 x 25 screen cells from map cell (col, row): (codes, map entries, row and column in the
        tile, covered), each (25, 40); codes are not limited to 0-255 here."""
        rows, cols = self.size
        if not (0 <= col < cols and 0 <= row < rows):
            raise InputError(f"{name}: the map is {cols} x {rows} screen cells: "
                             f"no cell at column {col}, row {row}")
        r = np.arange(row, row + TEXT_ROWS)[:, None].repeat(TEXT_COLUMNS, 1)
        c = np.arange(col, col + TEXT_COLUMNS)[None, :].repeat(TEXT_ROWS, 0)
        covered = (r < rows) & (c < cols)
        r, c = np.where(covered, r, 0), np.where(covered, c, 0)
        h, w = self.cell_size
        entry = self.map[r // h, c // w].astype(np.int64)
        if self.tiles is None:
            codes = entry
        else:
            bad = covered & (entry >= len(self.tiles))
            if bad.any():
                y, x = np.argwhere(bad)[0]
                raise InputError(f"{name}: map cell (column {(col + x) // w}, row {(row + y) // h}) names tile "
                                 f"{entry[y, x]}, the project has {len(self.tiles)}")
            codes = self.tiles[entry, r % h, c % w].astype(np.int64)
        return codes, entry, r % h, c % w, covered

    def window(self, col: int = 0, row: int = 0, name: str = "map") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The 40 x 25 screen cells from map cell (col, row) on (in screen cells):
        (screen codes, colour nibbles, covered), each (1000,); cells past the map's right or bottom
        edge are not covered (code and colour 0)."""
        codes, entry, tr, tc, covered = self._cells(col, row, name)
        bad = covered & (codes >= CODES)
        if bad.any():
            y, x = np.argwhere(bad)[0]
            raise InputError(f"{name}: screen cell (column {col + x}, row {row + y}) shows character {codes[y, x]}: "
                             f"a screen holds codes 0-255")
        colours = self._colours(codes, entry, tr, tc) & COLOR_MASK
        codes = np.where(covered, codes, 0)
        colours = np.where(covered, colours, 0)
        return codes.astype(np.uint8).ravel(), colours.astype(np.uint8).ravel(), covered.ravel()

    def bitmap_window(self, col: int = 0, row: int = 0, name: str = "map") -> tuple[np.ndarray, np.ndarray,
                                                                                     np.ndarray, np.ndarray]:
        """A bitmap-mode project's 40 x 25 cells from map cell (col, row): (bitmap (8000,), screen-RAM
        bytes (1000,), colour nibbles (1000,), covered (1000,)). Each cell's 8 bytes are its
        character's rows, in the bitmap's cell order; cells past the map's edge are 0."""
        codes, entry, tr, tc, covered = self._cells(col, row, name)
        bad = covered & (codes >= len(self.chars))
        if bad.any():
            y, x = np.argwhere(bad)[0]
            raise InputError(f"{name}: screen cell (column {col + x}, row {row + y}) shows character {codes[y, x]}, "
                             f"the project has {len(self.chars)}")
        codes = np.where(covered, codes, 0)
        bitmap = np.where(covered.ravel()[:, None], self.chars[codes.ravel()], 0).astype(np.uint8).ravel()
        colours = np.where(covered, self._colours(codes, entry, tr, tc) & COLOR_MASK, 0)
        screen = np.where(covered, self._screen(codes, entry), 0)
        return bitmap, screen.astype(np.uint8).ravel(), colours.astype(np.uint8).ravel(), covered.ravel()

    def _screen(self, codes: np.ndarray, entry: np.ndarray) -> np.ndarray:
        if self.colouring == "per-char" and self.char_screen is not None:
            table = np.zeros(max(CODES, len(self.char_screen)), np.int64)
            table[:len(self.char_screen)] = self.char_screen
            return table[codes]
        if self.colouring == "per-tile" and self.tile_screen is not None:
            return self.tile_screen[entry].astype(np.int64)
        return np.full(codes.shape, self.screen_colour, np.int64)

    def _colours(self, codes: np.ndarray, entry: np.ndarray, tr: np.ndarray, tc: np.ndarray) -> np.ndarray:
        if self.colouring == "per-char":
            table = np.zeros(max(CODES, len(self.char_colours), int(codes.max()) + 1), np.int64)
            table[:len(self.char_colours)] = self.char_colours
            return table[codes]
        if self.colouring == "per-tile":
            if self.tile_colours is None:  # bitmap hires: no colour-matrix byte in the entries
                return np.zeros(codes.shape, np.int64)
            return self.tile_colours[entry].astype(np.int64)
        if self.colouring == "per-tile-cell":
            return self.cell_colours[entry, tr, tc].astype(np.int64)
        return np.full(codes.shape, self.char_colour, np.int64)


class _Reader:
    """Walks the file; every shortfall is one line naming the file and the field."""

    def __init__(self, raw: bytes, name: str):
        self.raw, self.name, self.at = raw, name, 0

    def fail(self, field: str, message: str) -> InputError:
        return InputError(f"{self.name}: {field}: {message}")

    def take(self, size: int, field: str) -> bytes:
        if self.at + size > len(self.raw):
            raise self.fail(field, f"needs {size} bytes from byte {self.at}, the file ends at byte {len(self.raw)}")
        data = self.raw[self.at:self.at + size]
        self.at += size
        return data

    def byte(self, field: str) -> int:
        return self.take(1, field)[0]

    def word(self, field: str) -> int:
        low, high = self.take(2, field)
        return low | high << 8

    def array(self, count: int, width: int, field: str) -> np.ndarray:
        """count values of width bytes (1 or 2, little-endian)."""
        data = np.frombuffer(self.take(count * width, field), dtype=np.uint8 if width == 1 else "<u2")
        return data.astype(np.uint16)

    def block(self, number: int, field: str) -> None:
        mark = self.take(2, f"{field} block marker")
        if mark != bytes([BLOCK_MARK, BLOCK_BASE + number]):
            raise self.fail(f"{field} block marker", f"expected ${BLOCK_MARK:02X} ${BLOCK_BASE + number:02X} at byte "
                                                     f"{self.at - 2}, found ${mark[0]:02X} ${mark[1]:02X}")

    def end(self) -> None:
        if self.at != len(self.raw):
            raise self.fail("file size", f"the data ends at byte {self.at}, the file has {len(self.raw)} bytes")


def looks_like_ctm(raw: bytes) -> bool:
    return raw.startswith(MAGIC)


def read_ctm(raw: bytes, name: str = "CharPad file") -> CharpadProject:
    """A .ctm file's bytes -> CharpadProject (versions 1, 2, 4, 5, 6, 7)."""
    if not raw.startswith(MAGIC):
        raise InputError(f"{name}: ID_STR: not a CharPad project (it does not start with \"CTM\")")
    r = _Reader(raw, name)
    r.take(3, "ID_STR")
    version = r.byte("VERSION")
    if version not in READ_VERSIONS:
        raise InputError(f"{name}: VERSION: CharPad format version {version} is not read (read: versions "
                         f"{', '.join(map(str, READ_VERSIONS))}; no description of other versions was found)")
    project = {1: _v1, 2: _v2, 3: _v3, 4: _v4, 5: _v5, 6: _v6, 7: _v6, 8: _v8, 9: _v8, V82: _v8}[version](r, version)
    r.end()
    return project


def _colouring(r: _Reader, table: dict, field: str = "COLR_METH") -> str:
    value = r.byte(field)
    if value not in table:
        raise r.fail(field, f"colouring method {value} is not one of {', '.join(f'{k} ({v})' for k, v in table.items())}")
    return table[value]


def _colours(r: _Reader) -> tuple[int, int, int, int]:
    return tuple(b & COLOR_MASK for b in r.take(4, "COLOURS"))


def _chars(r: _Reader, count: int, field: str = "CHAR_DATA") -> np.ndarray:
    return r.array(count * CHAR_HEIGHT, 1, field).astype(np.uint8).reshape(count, CHAR_HEIGHT)


def _tiles(r: _Reader, count: int, h: int, w: int, width: int, field: str = "TILE_DATA") -> np.ndarray:
    if not (h and w):
        raise r.fail("TILE_WID/TILE_HEI", f"a tile of {w} x {h} cells")
    return r.array(count * h * w, width, field).reshape(count, h, w)


def _tile_block(r: _Reader, blocks) -> np.ndarray:
    """The TILEDAT block of versions 7-9: tile count, width and height, then 16-bit char numbers."""
    r.block(next(blocks), "TILEDAT")
    n_tiles = r.word("TILECNT") + 1
    tile_w, tile_h = r.byte("TILEWID"), r.byte("TILEHEI")
    return _tiles(r, n_tiles, tile_h, tile_w, 2, "TILEDAT")


def _tile_tags_and_names(r: _Reader, blocks, n_tiles: int) -> None:
    """The TILETAGS and TILENAMES blocks of versions 7-9: read past (nothing collides by them)."""
    r.block(next(blocks), "TILETAGS")
    r.take(n_tiles, "TILETAGS")
    r.block(next(blocks), "TILENAMES")
    _names(r, n_tiles)


def _map(r: _Reader, w: int, h: int, width: int, field: str = "MAP_DATA") -> np.ndarray:
    return r.array(w * h, width, field).reshape(h, w)


def _project(version, mode, colouring, colours, chars, materials, char_colours=None, tiles=None, tile_colours=None,
             cell_colours=None, map_=None, **more) -> CharpadProject:
    background, mc1, mc2, char_colour = colours
    return CharpadProject(version, mode, colouring, background, mc1, mc2, char_colour, chars,
                          None if materials is None else materials.astype(np.uint8), char_colours, tiles,
                          tile_colours, cell_colours, map_, **more)


def _nibbles(attributes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """MMMMCCCC attribute bytes -> (materials, colours)."""
    return (attributes >> NIBBLE).astype(np.uint8), (attributes & COLOR_MASK).astype(np.uint8)


def _v1(r: _Reader, version: int) -> CharpadProject:
    """[CP23] version 1: header 20 bytes, 4x4 tiles, no materials."""
    colours = _colours(r)
    colouring = _colouring(r, OLD_COLOURING)
    mode = "multicolor" if r.byte("MCMODE") == 1 else "hires"
    map_w, map_h = r.word("MAP_WID"), r.word("MAP_HEI")
    n_chars, n_tiles = r.byte("NUM_CHARS") + 1, r.byte("NUM_TILES") + 1
    r.take(4, "RESERVED")
    chars = _chars(r, n_chars)
    tiles = _tiles(r, n_tiles, V1_TILE_SIZE, V1_TILE_SIZE, 1)
    cells = r.array(n_tiles * V1_TILE_SIZE ** 2, 1, "CELL_COLOURS").reshape(tiles.shape) \
        if colouring == "per-tile-cell" else None
    tile_colours = r.array(n_tiles, 1, "TILE_COLOURS") if colouring == "per-tile" else None
    return _project(version, mode, colouring, colours, chars, np.zeros(n_chars), None, tiles, tile_colours, cells,
                    _map(r, map_w, map_h, 1))


def _square_tile_header(r: _Reader) -> tuple:
    """[CP23] the header fields versions 2 and 3 share, up to the tile size: (colours, colouring,
    mode, map width, map height, chars, tiles, tile size)."""
    colours = _colours(r)
    colouring = _colouring(r, OLD_COLOURING)
    mode = "multicolor" if r.byte("MCMODE") == 1 else "hires"
    map_w, map_h = r.word("MAP_WID"), r.word("MAP_HEI")
    n_chars, n_tiles = r.word("NUM_CHARS") + 1, r.byte("NUM_TILES") + 1
    return colours, colouring, mode, map_w, map_h, n_chars, n_tiles, r.byte("TILE_SZ")


def _v2(r: _Reader, version: int) -> CharpadProject:
    """[CP23] version 2: header 20 bytes, chars of 9 bytes (the 9th the material), square tiles."""
    colours, colouring, mode, map_w, map_h, n_chars, n_tiles, size = _square_tile_header(r)
    r.take(2, "RESERVED")
    data = r.array(n_chars * (CHAR_HEIGHT + 1), 1, "CHAR_DATA").astype(np.uint8).reshape(n_chars, CHAR_HEIGHT + 1)
    tiles = _tiles(r, n_tiles, size, size, 2)
    tile_colours = r.array(n_tiles, 1, "TILE_COLOURS") if colouring == "per-tile" else None
    cells = r.array(n_tiles * size * size, 1, "CELL_COLOURS").reshape(tiles.shape) \
        if colouring == "per-tile-cell" else None
    return _project(version, mode, colouring, colours, data[:, :CHAR_HEIGHT].copy(), data[:, CHAR_HEIGHT] & COLOR_MASK,
                    None, tiles, tile_colours, cells, _map(r, map_w, map_h, 1))


def _v3(r: _Reader, version: int) -> CharpadProject:
    """[CP23] version 3: header 20 bytes, square tiles, tile-cell attributes MMMMCCCC, no char attributes."""
    colours, colouring, mode, map_w, map_h, n_chars, n_tiles, size = _square_tile_header(r)
    if r.byte("CHAREX"):
        _no_charex(r, "CHAREX")
    r.take(1, "RESERVED")
    chars = _chars(r, n_chars)
    tiles = _tiles(r, n_tiles, size, size, 2)
    cell_materials, cell_colours = _nibbles(r.array(n_tiles * size * size, 1, "CELL_ATTRIBS"))
    tile_colours = r.array(n_tiles, 1, "TILE_COLOURS") if colouring == "per-tile" else None
    return _project(version, mode, colouring, colours, chars, None, None, tiles, tile_colours,
                    cell_colours.reshape(tiles.shape) if colouring == "per-tile-cell" else None,
                    _map(r, map_w, map_h, 1), cell_materials=cell_materials.reshape(tiles.shape))


def _no_charex(r: _Reader, field: str) -> None:
    raise r.fail(field, "the character set is saved expanded (CHAREX): the file holds no tile data and the "
                        "rule that replaces it is not in the sources this reader follows; save it compressed")


def _v4(r: _Reader, version: int) -> CharpadProject:
    """[CP23] version 4: header 24 bytes, char and tile-cell attributes MMMMCCCC."""
    colours = _colours(r)
    colouring = _colouring(r, OLD_COLOURING)
    mode = "multicolor" if r.byte("MCMODE") == 1 else "hires"
    n_chars, n_tiles = r.word("NUM_CHARS") + 1, r.byte("NUM_TILES") + 1
    tile_w, tile_h = r.byte("TILE_WID"), r.byte("TILE_HEI")
    map_w, map_h = r.word("MAP_WID"), r.word("MAP_HEI")
    if r.byte("CHAREX"):
        _no_charex(r, "CHAREX")
    r.take(4, "RESERVED")
    chars = _chars(r, n_chars)
    materials, _ = _nibbles(r.array(n_chars, 1, "CHAR_ATTRIBS"))
    tiles = _tiles(r, n_tiles, tile_h, tile_w, 2)
    _, cell_colours = _nibbles(r.array(n_tiles * tile_w * tile_h, 1, "CELL_ATTRIBS"))
    tile_colours = r.array(n_tiles, 1, "TILE_COLOURS") if colouring == "per-tile" else None
    return _project(version, mode, colouring, colours, chars, materials, None, tiles, tile_colours,
                    cell_colours.reshape(tiles.shape) if colouring == "per-tile-cell" else None,
                    _map(r, map_w, map_h, 1))


def _v5(r: _Reader, version: int) -> CharpadProject:
    """[CP23] version 5: header 20 bytes with FLAGS; 16-bit map."""
    colours = _colours(r)
    colouring = _colouring(r, NEW_COLOURING)
    flags = r.byte("FLAGS")
    n_chars, n_tiles = r.word("NUM_CHARS") + 1, r.word("NUM_TILES") + 1
    tile_w, tile_h = r.byte("TILE_WID"), r.byte("TILE_HEI")
    map_w, map_h = r.word("MAP_WID"), r.word("MAP_HEI")
    tile_system = bool(flags & V5_TILESYS)
    if tile_system and flags & V5_CHAREX:
        _no_charex(r, "FLAGS")
    chars = _chars(r, n_chars)
    materials, char_colours = _nibbles(r.array(n_chars, 1, "CHAR_ATTRIBS"))
    tiles = _tiles(r, n_tiles, tile_h, tile_w, 2) if tile_system else None
    tile_colours = r.array(n_tiles, 1, "TILE_COLOURS") if tile_system and colouring == "per-tile" else None
    _tile_colouring(r, colouring, tile_system)
    mode = "multicolor" if flags & V5_MCMODE else "hires"
    return _project(version, mode, colouring, colours, chars, materials, char_colours, tiles, tile_colours, None,
                    _map(r, map_w, map_h, 2))


def _tile_colouring(r: _Reader, colouring: str, tile_system: bool) -> None:
    if colouring == "per-tile" and not tile_system:
        raise r.fail("COLR_METH", "per-tile colouring in a project without a tile set")


def _v6(r: _Reader, version: int) -> CharpadProject:
    """[CP26] version 6 (10-byte header) and [C64LIB] version 7 (12-byte header); blocks $DA $Bn."""
    if version == 6:
        colours = _colours(r)
        colouring = _colouring(r, NEW_COLOURING)
        flags = r.byte("FLAGS")
        mode = "multicolor" if flags & V6_MCMODE else "hires"
        tile_system = bool(flags & V6_TILESYS)
    else:
        background, mc1, mc2 = (b & COLOR_MASK for b in r.take(3, "COLOURS"))
        r.byte("BG_COLOUR_4")
        colours = (background, mc1, mc2, r.byte("CHAR_COLOUR") & COLOR_MASK)
        colouring = _colouring(r, NEW_COLOURING)
        mode_byte = r.byte("DISPLAY_MODE")
        if mode_byte not in MODES:
            raise r.fail("DISPLAY_MODE", f"display mode {mode_byte} is not 0 (hires), 1 (multicolour) or 2 (ECM)")
        mode = MODES[mode_byte]
        tile_system = bool(r.byte("FLAGS") & V7_TILESYS)
    blocks = iter(range(16))
    r.block(next(blocks), "CHARDAT")
    n_chars = r.word("CHARCNT") + 1
    chars = _chars(r, n_chars, "CHARDAT")
    r.block(next(blocks), "CHARATTS")
    materials, char_colours = _nibbles(r.array(n_chars, 1, "CHARATTS"))
    tiles = tile_colours = None
    if tile_system:
        tiles = _tile_block(r, blocks)
        n_tiles = len(tiles)
        if colouring == "per-tile":
            r.block(next(blocks), "TILECOLRS")
            tile_colours = r.array(n_tiles, 1, "TILECOLRS")
        _tile_tags_and_names(r, blocks, n_tiles)
    _tile_colouring(r, colouring, tile_system)
    r.block(next(blocks), "MAP")
    map_w, map_h = r.word("MAPWID"), r.word("MAPHEI")
    return _project(version, mode, colouring, colours, chars, materials, char_colours, tiles, tile_colours, None,
                    _map(r, map_w, map_h, 2, "MAPDAT"))


def _v8(r: _Reader, version: int) -> CharpadProject:
    """Versions 8, 82 and 9 [C64LIB, OSCAR64, C64STUDIO]: display mode, colouring, flags, (v9: flexigrid),
    7 or (v8 prototype) 8 colours, then blocks $DA $Bn."""
    mode_byte = r.byte("DISP_MODE")
    if mode_byte not in V8_MODES:
        raise r.fail("DISP_MODE", f"display mode {mode_byte} is not one of "
                                  f"{', '.join(f'{k} ({v})' for k, v in V8_MODES.items())}")
    mode = V8_MODES[mode_byte]
    colouring = _colouring(r, NEW_COLOURING)
    tile_system = bool(r.byte("FLAGS") & V8_TILESYS)
    if version == 9:
        r.take(V9_FLEXIGRID, "FLEXIGRID")
    background, mc1, mc2 = (b & COLOR_MASK for b in r.take(3, "COLOURS"))
    r.byte("BG_COLOUR_4")
    matrix, screen_lo, screen_hi = (b & COLOR_MASK for b in r.take(3, "BASE_COLOURS"))
    layout, entry = "", ENTRY[mode]
    mark = bytes([BLOCK_MARK, BLOCK_BASE])
    if version == 8 and r.raw[r.at:r.at + 2] != mark and r.raw[r.at + 1:r.at + 3] == mark:
        layout = "prototype"  # CharPad 2.8 preview: a 4th base colour, 4-byte colour entries
        if mode in BITMAP_MODES:
            raise r.fail("DISP_MODE", f"a {mode} project in the CharPad 2.8 preview layout of version 8 is not "
                                      f"read (no such file was at hand to check it); save it in a later CharPad")
        matrix = r.byte("BASE_COLOURS") & COLOR_MASK
        entry = PROTO_ENTRY
    blocks = iter(range(16))
    r.block(next(blocks), "CHARDAT")
    n_chars = r.word("CHARCNT") + 1
    chars = _chars(r, n_chars, "CHARDAT")
    r.block(next(blocks), "CHARMATS")
    materials = r.array(n_chars, 1, "CHARMATS") & COLOR_MASK
    char_colours = char_screen = tiles = tile_colours = tile_screen = None
    if colouring == "per-char":
        r.block(next(blocks), "CHARCOLRS")
        char_colours, char_screen = _entries(r, n_chars, entry, "CHARCOLRS")
    if tile_system:
        tiles = _tile_block(r, blocks)
        n_tiles = len(tiles)
        if colouring == "per-tile":
            r.block(next(blocks), "TILECOLRS")
            tile_colours, tile_screen = _entries(r, n_tiles, entry, "TILECOLRS")
        _tile_tags_and_names(r, blocks, n_tiles)
    _tile_colouring(r, colouring, tile_system)
    r.block(next(blocks), "MAP")
    map_w, map_h = r.word("MAPWID"), r.word("MAPHEI")
    return _project(version, mode, colouring, (background, mc1, mc2, matrix), chars, materials, char_colours,
                    tiles, tile_colours, None, _map(r, map_w, map_h, 2, "MAPDAT"),
                    screen_colour=screen_hi << SCREEN_NIBBLE | screen_lo, char_screen=char_screen,
                    tile_screen=tile_screen, layout=layout)


def _entries(r: _Reader, count: int, entry: tuple, field: str) -> tuple[np.ndarray, np.ndarray | None]:
    """count colour entries -> (colour-matrix nibbles, screen-RAM bytes or None in the text modes)."""
    size, matrix, low, high = entry
    data = r.array(count * size, 1, field).reshape(count, size) & COLOR_MASK
    colours = data[:, matrix].astype(np.uint8) if matrix is not None else np.zeros(count, np.uint8)
    screen = None if low is None else (data[:, high] << SCREEN_NIBBLE | data[:, low]).astype(np.uint8)
    return colours, screen


def _names(r: _Reader, count: int) -> None:
    """Tile names: ASCII, each ended by a zero byte [CP26, C64LIB]."""
    for _ in range(count):
        end = r.raw.find(b"\0", r.at)
        if end < 0:
            raise r.fail("TILENAMES", f"a tile name from byte {r.at} has no terminating zero byte")
        r.at = end + 1


# ---- for routine specs and scenes -----------------------------------------------------------------

def read_ctm_file(path: str | Path) -> CharpadProject:
    return read_ctm(read_bytes(path, "CharPad file"), str(path))


def material_table(path: str | Path) -> bytes:
    """256 bytes: the CharPad material (0-15) of every screen code, for a spec's `[memory]`
    generator (docs/specs.md, "CharPad materials")."""
    return read_ctm_file(path).material_table(str(path))


def screen_codes(path: str | Path, col: int = 0, row: int = 0) -> bytes:
    """The 1000 screen codes a 40 x 25 screen shows of the project's map from screen cell (col, row);
    cells past the map's edge are 0."""
    project = read_ctm_file(path)
    return project.window(col, row, str(path))[0].tobytes()
