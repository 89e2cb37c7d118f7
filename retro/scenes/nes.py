"""NES scene files (TOML) -> `NesScene`, checked key by key; errors name the file and the field.

Format (see docs/nes.md):

    chip = "nes"
    video = "ntsc"                     # or "pal" (default "ntsc")
    [ppu]
    ctrl = 0x00                        # $2000 (default 0)
    mask = 0x1e                        # $2001 (default $1E)
    scroll_x = 0                       # as written to $2005 (coarse and fine; default 0)
    scroll_y = 0
    mirroring = "horizontal"           # "horizontal", "vertical", "single" (default "horizontal")
    [[oam]]                            # entry 0 first; up to 64; y, tile, x required, attr default 0
    y = 119
    tile = 3
    attr = 0x00
    x = 128
    [chr]                              # file = "game.chr" (8 KiB, 4 KiB + table = 0/1, or a .nes; relative to the scene) and/or tiles
    tiles = { "0:3" = ["33333333", ...] }   # "table:index": 8 rows of 8 values 0-3 ('.' = 0), or 16 bytes
    [[nametable]]                      # 32x30 tiles; index 0-3; anything not given is tile 0
    index = 0
    fill = 0                           # or file = "title.nam" (1024 bytes: 960 tiles + 64 attribute bytes)
    cells = [{ col = 16, row = 15, tile = 3 }]

OAM entries not given are $FF (off screen); nametable cells not given are 0, and so are the
attribute bytes unless a `.nam` file gives them. Numbers may be TOML integers or strings in any
notation `parse_int` accepts.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.chips.ppu.constants import (
    CHR_SIZE,
    CIRAM_SIZE,
    MIRRORING,
    NAMETABLE_COLUMNS,
    NAMETABLE_COUNT,
    NAMETABLE_ROWS,
    NAMETABLE_SIZE,
    OAM_ENTRY_SIZE,
    OAM_SIZE,
    PATTERN_TABLE_SIZE,
    PLANE_OFFSET,
    TILE_BYTES,
    TILE_SIZE,
    TILES_PER_TABLE,
    VIDEO_STANDARDS,
    VideoStandard,
)
from retro.chips.ppu.device import PpuDevice, attach_ppu
from retro.chips.ppu.state import PpuState
from retro.errors import InputError
from retro.fileio import read_bytes
from retro.loaders.gfx_chr import chr_from_bytes
from retro.loaders.gfx_nametable import ATTRIBUTE_BYTES, NAMETABLE_TILES, nametable_from_bytes
from retro.numbers import parse_int
from retro.scenes import earlier_spelling

DEFAULT_MASK = 0x1E          # background and sprites on, left columns shown
UNUSED_OAM_BYTE = 0xFF       # Y = $FF puts unused sprites below the screen
PIXEL_DIGITS = {".": 0, "0": 0, "1": 1, "2": 2, "3": 3}
TOP_KEYS = {"chip", "video", "ppu", "oam", "chr", "nametable"}
PPU_KEYS = {"ctrl", "mask", "scroll_x", "scroll_y", "mirroring"}
OAM_KEYS = {"y", "tile", "attr", "x"}
CHR_KEYS = {"file", "table", "tiles"}
NAMETABLE_KEYS = {"index", "fill", "file", "cells"}
CELL_KEYS = {"col", "row", "tile"}


@dataclass(frozen=True)
class OamEntry:
    y: int
    tile: int
    attr: int
    x: int


@dataclass(frozen=True)
class NametableCell:
    col: int
    row: int
    tile: int


@dataclass(frozen=True)
class Nametable:
    index: int
    fill: int
    cells: tuple[NametableCell, ...]
    tiles: bytes | None = None             # 960 tile numbers from a .nam file (then `fill` is unused)
    attributes: bytes = bytes(ATTRIBUTE_BYTES)  # the attribute table (from a .nam file; else 0)


@dataclass(frozen=True)
class NesScene:
    source: str
    video: VideoStandard
    ctrl: int
    mask: int
    scroll_x: int
    scroll_y: int
    mirroring: str
    oam: tuple[OamEntry, ...]
    chr: bytes
    nametables: tuple[Nametable, ...]

    cpu_variant = "2a03"

    def oam_bytes(self) -> bytes:
        data = bytearray([UNUSED_OAM_BYTE]) * OAM_SIZE
        for number, entry in enumerate(self.oam):
            data[number * OAM_ENTRY_SIZE: (number + 1) * OAM_ENTRY_SIZE] = bytes([entry.y, entry.tile, entry.attr, entry.x])
        return bytes(data)

    def ciram_bytes(self) -> bytes:
        ciram = bytearray(CIRAM_SIZE)
        for table in self.nametables:
            base = MIRRORING[self.mirroring][table.index] * NAMETABLE_SIZE
            tiles = table.tiles if table.tiles is not None else bytes([table.fill]) * NAMETABLE_TILES
            ciram[base: base + NAMETABLE_TILES] = tiles
            ciram[base + NAMETABLE_TILES: base + NAMETABLE_SIZE] = table.attributes
            for cell in table.cells:
                ciram[base + cell.row * NAMETABLE_COLUMNS + cell.col] = cell.tile
        return bytes(ciram)

    def ppu_state(self) -> PpuState:
        return PpuState(ctrl=self.ctrl, mask=self.mask, scroll_x=self.scroll_x, scroll_y=self.scroll_y,
                        mirroring=self.mirroring, video=self.video, oam=self.oam_bytes(), chr=self.chr,
                        ciram=self.ciram_bytes())

    def attach(self, machine) -> PpuDevice:
        """Map a PPU holding this scene onto the machine's bus (registers as the scene sets them)."""
        return attach_ppu(machine, PpuDevice(self.ppu_state()))


def parse(doc: dict, source: str) -> NesScene:
    _known_keys(doc, TOP_KEYS, source, "")
    video_name = doc.get("video", "ntsc")
    if not isinstance(video_name, str) or video_name not in VIDEO_STANDARDS:
        raise InputError(f"{source}: video: expected one of {', '.join(repr(v) for v in VIDEO_STANDARDS)}, got {video_name!r}")
    ppu = _table(doc.get("ppu", {}), source, "ppu")
    _known_keys(ppu, PPU_KEYS, source, "ppu.")
    mirroring = ppu.get("mirroring", "horizontal")
    if not isinstance(mirroring, str) or mirroring not in MIRRORING:
        raise InputError(f"{source}: ppu.mirroring: expected one of {', '.join(repr(m) for m in MIRRORING)}, got {mirroring!r}")
    return NesScene(
        source=source, video=VIDEO_STANDARDS[video_name],
        ctrl=_byte(ppu.get("ctrl", 0), source, "ppu.ctrl"),
        mask=_byte(ppu.get("mask", DEFAULT_MASK), source, "ppu.mask"),
        scroll_x=_byte(ppu.get("scroll_x", 0), source, "ppu.scroll_x"),
        scroll_y=_byte(ppu.get("scroll_y", 0), source, "ppu.scroll_y"),
        mirroring=mirroring,
        oam=_parse_oam(doc.get("oam"), source),
        chr=_parse_chr(doc.get("chr", {}), source),
        nametables=_parse_nametables(doc.get("nametable", []), source, mirroring),
    )


# ---- pieces ---------------------------------------------------------------------------------------

def _fail(source: str, field: str, message: str) -> InputError:
    return InputError(f"{source}: {field}: {message}")


def _known_keys(table: dict, known: set[str], source: str, prefix: str) -> None:
    for key in table:
        if key not in known:
            raise _fail(source, f"{prefix}{key}", f"unknown key (known: {', '.join(sorted(known))})")


def _table(value, source: str, field: str) -> dict:
    if not isinstance(value, dict):
        raise _fail(source, field, f"expected a table, got {type(value).__name__}")
    return value


def _array_of_tables(value, source: str, field: str) -> list[dict]:
    if not isinstance(value, list):
        raise _fail(source, field, f"expected an array of tables ([[{field}]]), got {type(value).__name__}")
    return [_table(item, source, f"{field}[{number}]") for number, item in enumerate(value)]


def _int(value, source: str, field: str, lo: int, hi: int) -> int:
    if isinstance(value, (list, dict)):
        raise _fail(source, field, f"expected a number, got {type(value).__name__}")
    return parse_int(value, field=f"{source}: {field}", lo=lo, hi=hi)


def _byte(value, source: str, field: str) -> int:
    return _int(value, source, field, 0, 0xFF)


def _required(table: dict, key: str, source: str, field: str):
    if key not in table:
        raise _fail(source, f"{field}.{key}", "missing")
    return table[key]


def _parse_oam(value, source: str) -> tuple[OamEntry, ...]:
    if value is None:
        raise _fail(source, "oam", "missing: give at least entry 0 as [[oam]] with y, tile and x")
    entries = _array_of_tables(value, source, "oam")
    if not entries or len(entries) > OAM_SIZE // OAM_ENTRY_SIZE:
        raise _fail(source, "oam", f"expected 1-{OAM_SIZE // OAM_ENTRY_SIZE} entries, got {len(entries)}")
    result = []
    for number, entry in enumerate(entries):
        field = f"oam[{number}]"
        _known_keys(entry, OAM_KEYS, source, f"{field}.")
        result.append(OamEntry(
            y=_byte(_required(entry, "y", source, field), source, f"{field}.y"),
            tile=_byte(_required(entry, "tile", source, field), source, f"{field}.tile"),
            attr=_byte(entry.get("attr", 0), source, f"{field}.attr"),
            x=_byte(_required(entry, "x", source, field), source, f"{field}.x")))
    return tuple(result)


def _parse_chr(value, source: str) -> bytes:
    table = _table(value, source, "chr")
    _known_keys(table, CHR_KEYS, source, "chr.")
    data = bytearray(CHR_SIZE)
    if "file" in table:
        name = table["file"]
        if not isinstance(name, str):
            raise _fail(source, "chr.file", f"expected a file name, got {type(name).__name__}")
        path = Path(source).parent / name
        try:
            content = read_bytes(path, "CHR file")
        except InputError as exc:
            raise _fail(source, "chr.file", str(exc)) from None
        at = _int(table.get("table", 0), source, "chr.table", 0, 1)
        try:
            data[:] = chr_from_bytes(content, str(path), at)
        except InputError as exc:
            raise _fail(source, "chr.file", str(exc)) from None
    elif "table" in table:
        raise _fail(source, "chr.table", "places a 4 KiB chr.file; give the file too")
    tiles = _table(table.get("tiles", {}), source, "chr.tiles")
    spelled: dict[int, str] = {}
    for key, rows in tiles.items():
        field = f'chr.tiles."{key}"'
        address = _tile_address(key, source, field)
        if earlier := earlier_spelling(spelled, address, key):
            raise _fail(source, field, f"the same tile as \"{earlier}\"; give it once")
        data[address: address + TILE_BYTES] = _tile_bytes(rows, source, field)
    return bytes(data)


def _tile_address(key: str, source: str, field: str) -> int:
    table_text, sep, index_text = key.partition(":")
    if not sep:
        raise _fail(source, field, "expected a key 'TABLE:INDEX', e.g. \"0:3\" (table 0 or 1, tile 0-255)")
    table = _int(table_text, source, f"{field} table", 0, 1)
    index = _int(index_text, source, f"{field} index", 0, TILES_PER_TABLE - 1)
    return table * PATTERN_TABLE_SIZE + index * TILE_BYTES


def _tile_bytes(rows, source: str, field: str) -> bytes:
    if not isinstance(rows, list):
        raise _fail(source, field, "expected 8 rows of 8 pixels or 16 bytes")
    if len(rows) == TILE_BYTES:
        return bytes(_byte(v, source, f"{field}[{i}]") for i, v in enumerate(rows))
    if len(rows) != TILE_SIZE:
        raise _fail(source, field, f"expected 8 rows of 8 pixels or 16 bytes, got {len(rows)} items")
    planes = bytearray(TILE_BYTES)
    for r, row in enumerate(rows):
        if not isinstance(row, str):
            raise _fail(source, f"{field}[{r}]", f"expected a row string of 8 pixels 0-3 or '.', got {row!r}")
        if len(row) != TILE_SIZE:
            raise _fail(source, f"{field}[{r}]", f"row {row!r} has {len(row)} pixels, expected {TILE_SIZE}")
        for c, char in enumerate(row):
            if char not in PIXEL_DIGITS:
                raise _fail(source, f"{field}[{r}]", f"pixel {char!r} is not 0-3 or '.'")
            value = PIXEL_DIGITS[char]
            bit = 0x80 >> c
            planes[r] |= bit if value & 1 else 0
            planes[r + PLANE_OFFSET] |= bit if value & 2 else 0
    return bytes(planes)


def _parse_nametables(value, source: str, mirroring: str) -> tuple[Nametable, ...]:
    tables = _array_of_tables(value, source, "nametable")
    result: list[Nametable] = []
    memory_owner: dict[int, int] = {}
    for number, table in enumerate(tables):
        field = f"nametable[{number}]"
        _known_keys(table, NAMETABLE_KEYS, source, f"{field}.")
        index = _int(_required(table, "index", source, field), source, f"{field}.index", 0, NAMETABLE_COUNT - 1)
        page = MIRRORING[mirroring][index]
        if page in memory_owner:
            raise _fail(source, f"{field}.index", f"nametable {index} is the same memory as nametable "
                        f"{memory_owner[page]} under {mirroring} mirroring; give it once")
        memory_owner[page] = index
        cells = []
        raw_cells = table.get("cells", [])
        if not isinstance(raw_cells, list):
            raise _fail(source, f"{field}.cells", "expected an array of { col, row, tile } tables")
        for c, cell in enumerate(raw_cells):
            cell_field = f"{field}.cells[{c}]"
            cell = _table(cell, source, cell_field)
            _known_keys(cell, CELL_KEYS, source, f"{cell_field}.")
            cells.append(NametableCell(
                col=_int(_required(cell, "col", source, cell_field), source, f"{cell_field}.col", 0, NAMETABLE_COLUMNS - 1),
                row=_int(_required(cell, "row", source, cell_field), source, f"{cell_field}.row", 0, NAMETABLE_ROWS - 1),
                tile=_byte(_required(cell, "tile", source, cell_field), source, f"{cell_field}.tile")))
        tiles, attributes = None, bytes(ATTRIBUTE_BYTES)
        if "file" in table:
            if "fill" in table:
                raise _fail(source, f"{field}.fill", "give fill or file, not both (the file gives every tile)")
            content = _read_file(table["file"], source, f"{field}.file", "nametable file")
            try:
                loaded = nametable_from_bytes(content, repr(table["file"]))
            except InputError as exc:
                raise _fail(source, f"{field}.file", str(exc)) from None
            tiles, attributes = loaded.tiles, loaded.attributes
        result.append(Nametable(index=index, fill=_byte(table.get("fill", 0), source, f"{field}.fill"),
                                cells=tuple(cells), tiles=tiles, attributes=attributes))
    return tuple(result)


def _read_file(name, source: str, field: str, what: str) -> bytes:
    """A file named relative to the scene file; any failure is one line naming the field."""
    if not isinstance(name, str) or not name:
        raise _fail(source, field, f"expected a file name, got {name!r}")
    try:
        return read_bytes(Path(source).parent / name, what)
    except InputError as exc:
        raise _fail(source, field, str(exc)) from None
