"""C64 sprite formats <-> numpy arrays: raw .spr blocks, text rows, PNG.

A sprite is 63 bytes: 21 rows of 3 bytes, most significant bit leftmost [PRG p.145]. In memory and
in raw .spr files each sprite takes a 64-byte block (the last byte unused); a file may hold several
blocks (animation frames). Hires: one bit per pixel, 1 opaque. Multicolor: two bits per double-wide
pixel; 01, 10 and 11 are opaque, 00 transparent [Bauer 3.8.1, 3.8.2].

Sprite files are read by content, whatever their name (`read_sprite_frames`, `read_sprite`):
PNG (signature, or a .png name): a sprite or a sheet of them, colours through a C64 palette
(retro/loaders/gfx_png_sprites.py; `write_png`'s preview colours read back exactly); Spritemate
JSON (retro/loaders/gfx_spritemate.py); SpritePad (retro/loaders/gfx_spritepad.py); otherwise raw
64-byte blocks (or one 63-byte sprite).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from retro.chips.vic.constants import (
    SPRITE_BLOCK,
    SPRITE_BYTES,
    SPRITE_HEIGHT,
    SPRITE_MC_WIDTH,
    SPRITE_WIDTH,
)
from retro.chips.vic.sprite_bits import decode, opaque_mask  # noqa: F401 - part of this module's API
from retro.errors import InputError
from retro.fileio import read_bytes, write_atomic
from retro.loaders.gfx_png_sprites import PNG_MAGIC, SpriteColours, read_png_sheet
from retro.loaders.gfx_spritemate import looks_like_spm, parse_spm
from retro.loaders.gfx_spritepad import looks_like_spd, parse_spd

HIRES_ROW_CHARS = {".": 0, "#": 1}
MULTICOLOR_ROW_CHARS = {".": 0, "1": 1, "2": 2, "3": 3}
TRANSPARENT_PREVIEW = (0, 0, 0)
HIRES_PREVIEW = (255, 255, 255)
# Preview colours for the multicolor values 1, 2, 3: light blue, white, yellow, exactly Colodore's C64 colours
# 14, 1 and 7 (retro/chips/palettes.py), so a PNG written here reads back as C64 colours too
MULTICOLOR_PREVIEW = {1: (112, 109, 235), 2: (255, 255, 255), 3: (237, 241, 113)}


def encode(pixels: np.ndarray, multicolor: bool = False) -> bytes:
    """The inverse of decode: (21, 24) bits or (21, 12) pairs -> 63 bytes."""
    pixels = np.asarray(pixels, dtype=np.uint8)
    width = SPRITE_MC_WIDTH if multicolor else SPRITE_WIDTH
    if pixels.shape != (SPRITE_HEIGHT, width):
        raise InputError(f"sprite pixels: expected shape ({SPRITE_HEIGHT}, {width}), got {pixels.shape}")
    if multicolor:
        bits = np.empty((SPRITE_HEIGHT, SPRITE_WIDTH), dtype=np.uint8)
        bits[:, 0::2] = pixels >> 1
        bits[:, 1::2] = pixels & 1
    else:
        bits = pixels & 1
    return np.packbits(bits, axis=1).tobytes()


def block(data: bytes) -> bytes:
    """63 bytes -> a 64-byte block (padding byte 0)."""
    return bytes(data[:SPRITE_BYTES]).ljust(SPRITE_BLOCK, b"\0")


def parse_hex(text: str, field: str = "data") -> bytes:
    """'ff 00 3c ...' (whitespace optional) -> 63 bytes; 64 are accepted (the padding byte is dropped)."""
    digits = "".join(str(text).split())
    try:
        data = bytes.fromhex(digits)
    except ValueError:
        raise InputError(f"{field}: not hex bytes (expected pairs of hex digits like 'ff 00 3c')") from None
    if len(data) not in (SPRITE_BYTES, SPRITE_BLOCK):
        raise InputError(f"{field}: expected {SPRITE_BYTES} or {SPRITE_BLOCK} bytes, got {len(data)}")
    return data[:SPRITE_BYTES]


def parse_rows(rows: list, multicolor: bool, field: str = "rows") -> bytes:
    """21 strings: 24 of '.#' (hires) or 12 of '.123' (multicolor) -> 63 bytes."""
    chars = MULTICOLOR_ROW_CHARS if multicolor else HIRES_ROW_CHARS
    width = SPRITE_MC_WIDTH if multicolor else SPRITE_WIDTH
    kind = "multicolor" if multicolor else "hires"
    if not isinstance(rows, list) or len(rows) != SPRITE_HEIGHT:
        count = len(rows) if isinstance(rows, list) else "not a list"
        raise InputError(f"{field}: expected {SPRITE_HEIGHT} strings, got {count}")
    pixels = np.zeros((SPRITE_HEIGHT, width), dtype=np.uint8)
    for r, row in enumerate(rows):
        if not isinstance(row, str) or len(row) != width:
            got = len(row) if isinstance(row, str) else type(row).__name__
            raise InputError(f"{field}[{r}]: a {kind} row has {width} characters of "
                             f"{' '.join(chars)}, got {got}")
        for c, ch in enumerate(row):
            if ch not in chars:
                raise InputError(f"{field}[{r}]: character {ch!r} at {c} is not one of {' '.join(chars)}")
            pixels[r, c] = chars[ch]
    return encode(pixels, multicolor)


def format_rows(data: bytes, multicolor: bool = False) -> list[str]:
    chars = "".join(MULTICOLOR_ROW_CHARS) if multicolor else "".join(HIRES_ROW_CHARS)
    return ["".join(chars[v] for v in row) for row in decode(data, multicolor)]


@dataclass(frozen=True)
class SpriteFrame:
    """One sprite of a file: the 63 bytes scenes use, and what the format says about it."""

    data: bytes
    multicolor: bool | None  # None: the format does not record the mode (raw, PNG)
    colour: int | None = None  # the sprite's own colour ($D027+n), where the format records it
    overlay: bool = False  # SpritePad / Spritemate: the next sprite is drawn over this one
    name: str = ""


def sprite_format(raw: bytes, path: str | Path) -> str:
    """"png", "spm", "spd" or "raw", from the content (the name only breaks ties, see below).

    A PNG starts with its 8-byte signature (a file named .png is read as one whatever it holds, so a
    broken one says so). A Spritemate file is a JSON object: one named .spm, or one that is not a
    raw sprite length, is read as Spritemate; a raw-length file starting with "{" is tried as
    Spritemate first and read raw if it is not JSON. SpritePad: see gfx_spritepad.looks_like_spd."""
    suffix = Path(path).suffix.lower()
    if raw.startswith(PNG_MAGIC) or suffix == ".png":
        return "png"
    if suffix == ".spm" or (looks_like_spm(raw) and not _raw_length(raw)):
        return "spm"
    if looks_like_spm(raw):
        try:
            parse_spm(raw, str(path))
            return "spm"
        except InputError:
            pass
    if looks_like_spd(raw):
        return "spd"
    return "raw"


def _raw_length(raw: bytes) -> bool:
    return len(raw) == SPRITE_BYTES or (bool(raw) and len(raw) % SPRITE_BLOCK == 0)


def scene_colours(registers, index: int) -> SpriteColours:
    """The colours sprite `index` shows in, from a VIC-II register image ($D000 at 0)."""
    from retro.chips.vic.sprite_registers import sprite_colours

    return SpriteColours(*sprite_colours(registers, index))


def read_sprite_frames(path: str | Path, multicolor: bool = False, colours: SpriteColours | None = None,
                       palette: str | None = None, field: str = "file") -> list[SpriteFrame]:
    """Every sprite of a sprite file, whatever its format (see `sprite_format`).

    `multicolor`, `colours` and `palette` matter for PNG only (its pixels do not say the mode; see
    gfx_png_sprites for the colours); giving a palette for another format is an error."""
    return _read_frames(path, multicolor, colours, palette, field)[0]


def _read_frames(path: str | Path, multicolor: bool, colours: SpriteColours | None, palette: str | None,
                 field: str) -> tuple[list[SpriteFrame], str]:
    raw = read_bytes(path, "sprite file")  # read once, then told apart by content
    kind = sprite_format(raw, path)
    if palette is not None and kind != "png":
        raise InputError(f"{path}: palette: only a PNG's colours go through a palette (this is a "
                         f"{KIND_NAMES[kind]})")
    if kind == "png":
        sheet = read_png_sheet(raw, str(path), multicolor, colours, palette)
        return [SpriteFrame(data, None) for data in sheet.frames], kind
    if kind == "spm":
        spm = parse_spm(raw, str(path))
        return [SpriteFrame(s.data, s.multicolor, s.colour, s.overlay, s.name) for s in spm.sprites], kind
    if kind == "spd":
        spd = parse_spd(raw, str(path))
        return [SpriteFrame(s.data, s.multicolor, s.colour, s.overlay) for s in spd.sprites], kind
    if not _raw_length(raw):
        raise InputError(f"{path}: {field}: a raw sprite file holds 64-byte blocks (or one 63-byte sprite), "
                         f"got {len(raw)} bytes")
    return [SpriteFrame(raw[i:i + SPRITE_BYTES], None) for i in range(0, len(raw), SPRITE_BLOCK)], kind


KIND_NAMES = {"png": "PNG", "spm": "Spritemate file", "spd": "SpritePad file", "raw": "raw sprite file"}


def read_sprite(path: str | Path, frame: int = 0, multicolor: bool = False, colours: SpriteColours | None = None,
                palette: str | None = None, field: str = "file") -> bytes:
    """Frame N of any sprite file -> 63 bytes."""
    frames, kind = _read_frames(path, multicolor, colours, palette, field)
    if not 0 <= frame < len(frames):
        raise InputError(f"{path}: frame: {frame} is outside 0..{len(frames) - 1} "
                         f"({len(frames)} sprite{'s' if len(frames) != 1 else ''} in the {KIND_NAMES[kind]})")
    return frames[frame].data


def read_spr(path: str | Path, frame: int = 0, field: str = "file") -> bytes:
    """Frame N of a sprite file (raw .spr blocks, SpritePad, Spritemate, or a hires PNG) -> 63 bytes."""
    return read_sprite(path, frame, field=field)


def write_spr(path: str | Path, frames: list[bytes]) -> Path:
    return write_atomic(path, b"".join(block(f) for f in frames))


def read_png(path: str | Path, multicolor: bool = False, frame: int = 0, colours: SpriteColours | None = None,
             palette: str | None = None) -> bytes:
    """Frame N of a PNG sprite or sheet -> 63 bytes (rules: retro/loaders/gfx_png_sprites.py)."""
    frames = read_png_sheet(read_bytes(path, "sprite PNG"), str(path), multicolor, colours, palette).frames
    if not 0 <= frame < len(frames):
        raise InputError(f"{path}: frame: {frame} is outside 0..{len(frames) - 1} ({len(frames)} sprites in the PNG)")
    return frames[frame]
