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
    fill = 0                           # or file = "title.nam" (1024 bytes: 960 tiles + 64 attribute bytes;
                                       # a file of 2 or 4 nametables also needs part = 0-3)
    cells = [{ col = 16, row = 15, tile = 3 }]

OAM entries not given are $FF (off screen); nametable cells not given are 0, and so are the
attribute bytes unless a `.nam` file gives them. Numbers may be TOML integers or strings in any
notation `parse_int` accepts.
"""

from __future__ import annotations

from dataclasses import dataclass

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
from retro.chips.ppu.state import PpuState
from retro.errors import InputError
from retro.fields import Fields
from retro.loaders.gfx_chr import chr_from_bytes
from retro.loaders.gfx_nametable import ATTRIBUTE_BYTES, NAMETABLE_TILES, PPU_ADDRESSES, nametables_from_bytes
from retro.scenes import earlier_spelling

DEFAULT_MASK = 0x1E          # background and sprites on, left columns shown
UNUSED_OAM_BYTE = 0xFF       # Y = $FF puts unused sprites below the screen
PIXEL_DIGITS = {".": 0, "0": 0, "1": 1, "2": 2, "3": 3}
TOP_KEYS = {"chip", "video", "ppu", "oam", "chr", "nametable"}
PPU_KEYS = {"ctrl", "mask", "scroll_x", "scroll_y", "mirroring"}
OAM_KEYS = {"y", "tile", "attr", "x"}
CHR_KEYS = {"file", "table", "tiles"}
NAMETABLE_KEYS = {"index", "fill", "file", "part", "cells"}
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
    cpu_variant: str = "2a03"

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


def parse(doc: dict, source: str) -> NesScene:
    fields = Fields(source)
    fields.table(doc, "", TOP_KEYS)
    video_name = fields.choice(doc.get("video", "ntsc"), "video", VIDEO_STANDARDS)
    ppu = fields.table(doc.get("ppu", {}), "ppu", PPU_KEYS)
    mirroring = fields.choice(ppu.get("mirroring", "horizontal"), "ppu.mirroring", MIRRORING)
    return NesScene(
        source=source, video=VIDEO_STANDARDS[video_name],
        ctrl=fields.byte(ppu.get("ctrl", 0), "ppu.ctrl"),
        mask=fields.byte(ppu.get("mask", DEFAULT_MASK), "ppu.mask"),
        scroll_x=fields.byte(ppu.get("scroll_x", 0), "ppu.scroll_x"),
        scroll_y=fields.byte(ppu.get("scroll_y", 0), "ppu.scroll_y"),
        mirroring=mirroring,
        oam=_parse_oam(doc.get("oam"), fields),
        chr=_parse_chr(doc.get("chr", {}), fields),
        nametables=_parse_nametables(doc.get("nametable", []), fields, mirroring),
    )


# ---- pieces ---------------------------------------------------------------------------------------

def _parse_oam(value, fields: Fields) -> tuple[OamEntry, ...]:
    if value is None:
        raise fields.error("oam", "missing: give at least entry 0 as [[oam]] with y, tile and x")
    entries = fields.array_of_tables(value, "oam")
    if not entries or len(entries) > OAM_SIZE // OAM_ENTRY_SIZE:
        raise fields.error("oam", f"expected 1-{OAM_SIZE // OAM_ENTRY_SIZE} entries, got {len(entries)}")
    result = []
    for number, entry in enumerate(entries):
        field = f"oam[{number}]"
        fields.known(entry, field, OAM_KEYS)
        result.append(OamEntry(
            y=fields.byte(fields.required(entry, "y", field), f"{field}.y"),
            tile=fields.byte(fields.required(entry, "tile", field), f"{field}.tile"),
            attr=fields.byte(entry.get("attr", 0), f"{field}.attr"),
            x=fields.byte(fields.required(entry, "x", field), f"{field}.x")))
    return tuple(result)


def _parse_chr(value, fields: Fields) -> bytes:
    table = fields.table(value, "chr", CHR_KEYS)
    data = bytearray(CHR_SIZE)
    if "file" in table:
        content = fields.read_file(table["file"], "chr.file", "CHR file")
        at = fields.integer(table.get("table", 0), "chr.table", 0, 1)
        try:
            data[:] = chr_from_bytes(content, str(fields.folder / table["file"]), at)
        except InputError as exc:
            raise fields.error("chr.file", str(exc)) from None
    elif "table" in table:
        raise fields.error("chr.table", "places a 4 KiB chr.file; give the file too")
    tiles = fields.table(table.get("tiles", {}), "chr.tiles")
    spelled: dict[int, str] = {}
    for key, rows in tiles.items():
        field = f'chr.tiles."{key}"'
        address = _tile_address(key, fields, field)
        if earlier := earlier_spelling(spelled, address, key):
            raise fields.error(field, f"the same tile as \"{earlier}\"; give it once")
        data[address: address + TILE_BYTES] = _tile_bytes(rows, fields, field)
    return bytes(data)


def _tile_address(key: str, fields: Fields, field: str) -> int:
    table_text, sep, index_text = key.partition(":")
    if not sep:
        raise fields.error(field, "expected a key 'TABLE:INDEX', e.g. \"0:3\" (table 0 or 1, tile 0-255)")
    table = fields.integer(table_text, f"{field} table", 0, 1)
    index = fields.integer(index_text, f"{field} index", 0, TILES_PER_TABLE - 1)
    return table * PATTERN_TABLE_SIZE + index * TILE_BYTES


def _tile_bytes(rows, fields: Fields, field: str) -> bytes:
    if not isinstance(rows, list):
        raise fields.error(field, "expected 8 rows of 8 pixels or 16 bytes")
    if len(rows) == TILE_BYTES:
        return bytes(fields.byte_list(rows, field, TILE_BYTES))
    if len(rows) != TILE_SIZE:
        raise fields.error(field, f"expected 8 rows of 8 pixels or 16 bytes, got {len(rows)} items")
    planes = bytearray(TILE_BYTES)
    for r, row in enumerate(rows):
        if not isinstance(row, str):
            raise fields.error(f"{field}[{r}]", f"expected a row string of 8 pixels 0-3 or '.', got {row!r}")
        if len(row) != TILE_SIZE:
            raise fields.error(f"{field}[{r}]", f"row {row!r} has {len(row)} pixels, expected {TILE_SIZE}")
        for c, char in enumerate(row):
            if char not in PIXEL_DIGITS:
                raise fields.error(f"{field}[{r}]", f"pixel {char!r} is not 0-3 or '.'")
            value = PIXEL_DIGITS[char]
            bit = 0x80 >> c
            planes[r] |= bit if value & 1 else 0
            planes[r + PLANE_OFFSET] |= bit if value & 2 else 0
    return bytes(planes)


def _parse_nametables(value, fields: Fields, mirroring: str) -> tuple[Nametable, ...]:
    tables = fields.array_of_tables(value, "nametable")
    result: list[Nametable] = []
    memory_owner: dict[int, int] = {}
    for number, table in enumerate(tables):
        field = f"nametable[{number}]"
        fields.known(table, field, NAMETABLE_KEYS)
        index = fields.integer(fields.required(table, "index", field), f"{field}.index", 0, NAMETABLE_COUNT - 1)
        page = MIRRORING[mirroring][index]
        if page in memory_owner:
            raise fields.error(f"{field}.index", f"nametable {index} is the same memory as nametable "
                               f"{memory_owner[page]} under {mirroring} mirroring; give it once")
        memory_owner[page] = index
        cells = []
        raw_cells = fields.array(table.get("cells", []), f"{field}.cells", "{col, row, tile} tables")
        for c, cell in enumerate(raw_cells):
            cell_field = f"{field}.cells[{c}]"
            cell = fields.table(cell, cell_field, CELL_KEYS)
            cells.append(NametableCell(
                col=fields.integer(fields.required(cell, "col", cell_field), f"{cell_field}.col", 0, NAMETABLE_COLUMNS - 1),
                row=fields.integer(fields.required(cell, "row", cell_field), f"{cell_field}.row", 0, NAMETABLE_ROWS - 1),
                tile=fields.byte(fields.required(cell, "tile", cell_field), f"{cell_field}.tile")))
        tiles, attributes = None, bytes(ATTRIBUTE_BYTES)
        if "file" in table:
            if "fill" in table:
                raise fields.error(f"{field}.fill", "give fill or file, not both (the file gives every tile)")
            content = fields.read_file(table["file"], f"{field}.file", "nametable file")
            try:
                in_file = nametables_from_bytes(content, repr(table["file"]))
            except InputError as exc:
                raise fields.error(f"{field}.file", str(exc)) from None
            if "part" not in table and len(in_file) > 1:
                where = ", ".join(f"{n}: ${a:04X}" for n, a in enumerate(PPU_ADDRESSES[:len(in_file)]))
                raise fields.error(f"{field}.part", f"{table['file']!r} holds {len(in_file)} nametables ({where}); "
                                   f"say which with part = 0-{len(in_file) - 1}")
            part = fields.integer(table.get("part", 0), f"{field}.part", 0, len(in_file) - 1)
            tiles, attributes = in_file[part].tiles, in_file[part].attributes
        elif "part" in table:
            raise fields.error(f"{field}.part", "part picks a nametable of a file: give file too")
        result.append(Nametable(index=index, fill=fields.byte(table.get("fill", 0), f"{field}.fill"),
                                cells=tuple(cells), tiles=tiles, attributes=attributes))
    return tuple(result)
