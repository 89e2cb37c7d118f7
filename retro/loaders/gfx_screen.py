"""What a VIC-II scene's `[memory]` takes from a file, detected by content (docs/vic.md).

`vic_part(raw, name, part)` gives one part ("screen", "color", "charset", "bitmap") of:
- a CharPad project (starts with "CTM"; retro/loaders/gfx_charpad.py): charset, screen (the
  40 x 25 window of its map at col, row) and colour RAM; a project in a bitmap display mode
  (CharPad 2.8 and later) gives the bitmap (each window cell's character), screen RAM (its
  screen-matrix colours) and colour RAM, and no charset;
- a Koala picture (10003 bytes, or 10001 without the load address; retro/loaders/gfx_koala.py):
  bitmap, screen and colour RAM;
- a raw memory dump: screen or colour RAM as 1000 bytes (40 x 25) or 1024 (the whole 1 KiB, sprite
  pointers and unused bytes after the 1000 cells), either behind a 2-byte load address (1002,
  1026); a bitmap as 8000 bytes (8002 with a load address); a charset as raw glyphs or .64c
  (retro/loaders/gfx_charset.py). Colour RAM keeps the low nibble of each byte (the chip has 4
  bits a cell; a dump's high nibbles are whatever the bus held).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.chips.vic.constants import BITMAP_BYTES, COLOR_MASK, SCREEN_CELLS
from retro.errors import InputError
from retro.loaders.gfx_charpad import looks_like_ctm, read_ctm
from retro.loaders.gfx_charset import charset_from_bytes
from retro.loaders.gfx_koala import koala_from_bytes, looks_like_koala

LOAD_ADDRESS_BYTES = 2
SCREEN_PAGE = 1024
SCREEN_SIZES = (SCREEN_CELLS, SCREEN_PAGE)
PARTS = ("screen", "color", "charset", "bitmap")


@dataclass(frozen=True, eq=False)
class Part:
    values: np.ndarray           # uint8: 1000 (screen, colour), 2048 (charset) or 8000 (bitmap)
    covered: np.ndarray | None   # bool per cell when the file covers only some cells (a small CharPad map)
    kind: str                    # "CharPad version N", "Koala picture", "raw"


def kind_of(raw: bytes) -> str:
    if looks_like_ctm(raw):
        return "charpad"
    if looks_like_koala(raw):
        return "koala"
    return "raw"


def vic_part(raw: bytes, name: str, part: str, col: int = 0, row: int = 0) -> Part:
    return vic_parts(raw, name, (part,), col, row)[part]


def vic_parts(raw: bytes, name: str, parts, col: int = 0, row: int = 0) -> dict[str, Part]:
    """The named parts of one file, read once."""
    kind = kind_of(raw)
    if kind == "charpad":
        project = read_ctm(raw, name)
        what = f"CharPad version {project.version}"
        out = {}
        if project.bitmap_mode:
            if "charset" in parts:
                raise InputError(f"{name}: a CharPad project in display mode {project.mode} has no charset: give it "
                                 f"as bitmap, screen and color files (memory.bitmap.file, ...)")
            bitmap, screen, colours, covered = project.bitmap_window(col, row, name)
            covered = None if covered.all() else covered
            out = {"bitmap": Part(bitmap, None, what), "screen": Part(screen, covered, what),
                   "color": Part(colours, covered, what)}
            return {part: out[part] for part in parts}
        if "bitmap" in parts:
            raise InputError(f"{name}: a CharPad project has no bitmap")
        if "charset" in parts:
            out["charset"] = Part(np.frombuffer(project.charset(), dtype=np.uint8).copy(), None, what)
        if "screen" in parts or "color" in parts:
            codes, colours, covered = project.window(col, row, name)
            covered = None if covered.all() else covered
            out["screen"], out["color"] = Part(codes, covered, what), Part(colours, covered, what)
        return {part: out[part] for part in parts}
    if kind == "koala":
        picture = koala_from_bytes(raw, name)
        if "charset" in parts:
            raise InputError(f"{name}: a Koala picture has no charset")
        values = {"screen": picture.screen, "color": picture.colour, "bitmap": picture.bitmap}
        return {part: Part(values[part].copy(), None, "Koala picture") for part in parts}
    return {part: _raw_part(raw, name, part) for part in parts}


def _raw_part(raw: bytes, name: str, part: str) -> Part:
    if part == "charset":
        return Part(np.frombuffer(charset_from_bytes(raw, name), dtype=np.uint8).copy(), None, "raw")
    if part == "bitmap":
        data = raw[LOAD_ADDRESS_BYTES:] if len(raw) == BITMAP_BYTES + LOAD_ADDRESS_BYTES else raw
        if len(data) != BITMAP_BYTES:
            raise InputError(f"{name}: {len(raw)} bytes: a bitmap file is 8000 bytes (8002 with a load address), or a "
                             f"Koala picture (10003 bytes)")
        return Part(np.frombuffer(data, dtype=np.uint8).copy(), None, "raw")
    data = raw[LOAD_ADDRESS_BYTES:] if len(raw) - LOAD_ADDRESS_BYTES in SCREEN_SIZES else raw
    if len(data) not in SCREEN_SIZES:
        what = "screen RAM" if part == "screen" else "colour RAM"
        raise InputError(f"{name}: {len(raw)} bytes: a {what} file is 1000 or 1024 bytes (1002 or 1026 with a load "
                         f"address), a Koala picture or a CharPad project")
    values = np.frombuffer(data[:SCREEN_CELLS], dtype=np.uint8).copy()
    return Part(values & COLOR_MASK if part == "color" else values, None, "raw")
