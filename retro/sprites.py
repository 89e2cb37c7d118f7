"""C64 sprite formats <-> numpy arrays: raw .spr blocks, text rows, PNG.

A sprite is 63 bytes: 21 rows of 3 bytes, most significant bit leftmost [PRG p.145]. In memory and
in raw .spr files each sprite takes a 64-byte block (the last byte unused); a file may hold several
blocks (animation frames). Hires: one bit per pixel, 1 opaque. Multicolor: two bits per double-wide
pixel; 01, 10 and 11 are opaque, 00 transparent [Bauer 3.8.1, 3.8.2].

PNG: 24x21 pixels. Transparent (alpha 0) or black pixels are 0. Hires: any other colour is 1.
Multicolor: each pair of pixels holds one value; the left pixel's colour must be one of
MULTICOLOR_PREVIEW (the colours `write_png` uses), so files written here read back exactly.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from PIL import Image

from retro.chips.vic.constants import (
    SPRITE_BLOCK,
    SPRITE_BYTES,
    SPRITE_BYTES_PER_ROW,
    SPRITE_HEIGHT,
    SPRITE_MC_WIDTH,
    SPRITE_WIDTH,
)
from retro.errors import InputError
from retro.fileio import read_bytes, write_atomic
from retro.loaders.gfx_spritepad import looks_like_spd, parse_spd

HIRES_ROW_CHARS = {".": 0, "#": 1}
MULTICOLOR_ROW_CHARS = {".": 0, "1": 1, "2": 2, "3": 3}
TRANSPARENT_PREVIEW = (0, 0, 0)
HIRES_PREVIEW = (255, 255, 255)
# Preview colours for the multicolor values 1, 2, 3 (light blue, white, yellow: C64-like, distinct)
MULTICOLOR_PREVIEW = {1: (112, 109, 235), 2: (255, 255, 255), 3: (237, 241, 113)}


def decode(data: bytes, multicolor: bool = False) -> np.ndarray:
    """63 (or 64) bytes -> (21, 24) uint8 of 0/1 (hires) or (21, 12) uint8 of 0-3 (multicolor)."""
    raw = np.frombuffer(bytes(data[:SPRITE_BYTES]), dtype=np.uint8)
    if raw.size != SPRITE_BYTES:
        raise InputError(f"sprite data: expected {SPRITE_BYTES} or {SPRITE_BLOCK} bytes, got {len(data)}")
    bits = np.unpackbits(raw.reshape(SPRITE_HEIGHT, SPRITE_BYTES_PER_ROW), axis=1)
    if not multicolor:
        return bits
    return bits[:, 0::2] * 2 + bits[:, 1::2]


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


def opaque_mask(data: bytes, multicolor: bool = False) -> np.ndarray:
    """(21, 24) bool: where the sprite outputs a non-transparent pixel (what collides)."""
    if not multicolor:
        return decode(data).astype(bool)
    return np.repeat(decode(data, True) != 0, 2, axis=1)


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


def read_spr(path: str | Path, frame: int = 0, field: str = "file") -> bytes:
    """Frame N of a raw .spr file (64-byte blocks; a lone 63-byte sprite is accepted) or of a
    SpritePad .spd file (detected by content) -> 63 bytes."""
    raw = read_bytes(path, "sprite file")
    if looks_like_spd(raw):
        sprites = parse_spd(raw, str(path)).sprites
        if not 0 <= frame < len(sprites):
            raise InputError(f"{path}: frame: {frame} is outside 0..{len(sprites) - 1} "
                             f"({len(sprites)} sprites in the SpritePad file)")
        return sprites[frame].data
    if len(raw) == SPRITE_BYTES:
        frames = 1
    elif raw and len(raw) % SPRITE_BLOCK == 0:
        frames = len(raw) // SPRITE_BLOCK
    else:
        raise InputError(f"{path}: {field}: a raw sprite file holds 64-byte blocks (or one 63-byte sprite), "
                         f"got {len(raw)} bytes")
    if not 0 <= frame < frames:
        raise InputError(f"{path}: frame: {frame} is outside 0..{frames - 1} ({frames} frames in the file)")
    return raw[frame * SPRITE_BLOCK: frame * SPRITE_BLOCK + SPRITE_BYTES]


def write_spr(path: str | Path, frames: list[bytes]) -> Path:
    return write_atomic(path, b"".join(block(f) for f in frames))


def read_png(path: str | Path, multicolor: bool = False) -> bytes:
    """A 24x21 PNG -> 63 bytes (see the module docstring for the colour rules)."""
    raw = read_bytes(path, "sprite PNG")
    try:
        image = Image.open(io.BytesIO(raw))  # reads the header only: the size is known before decoding
    except Exception:  # Pillow raises several types for bad files
        raise InputError(f"{path}: not a readable PNG image") from None
    if image.size != (SPRITE_WIDTH, SPRITE_HEIGHT):
        raise InputError(f"{path}: a sprite PNG must be {SPRITE_WIDTH}x{SPRITE_HEIGHT} pixels, "
                         f"got {image.width}x{image.height}")
    try:
        image = image.convert("RGBA")
    except Exception:  # a valid header over damaged pixel data
        raise InputError(f"{path}: not a readable PNG image") from None
    rgba = np.asarray(image)
    empty = (rgba[..., 3] == 0) | np.all(rgba[..., :3] == TRANSPARENT_PREVIEW, axis=-1)
    if not multicolor:
        return encode(~empty)
    pixels = np.zeros((SPRITE_HEIGHT, SPRITE_MC_WIDTH), dtype=np.uint8)
    for r in range(SPRITE_HEIGHT):
        for c in range(SPRITE_MC_WIDTH):
            if empty[r, 2 * c]:
                continue
            colour = tuple(int(v) for v in rgba[r, 2 * c, :3])
            value = next((v for v, rgb in MULTICOLOR_PREVIEW.items() if rgb == colour), None)
            if value is None:
                raise InputError(f"{path}: pixel ({2 * c}, {r}) has colour {colour}, which is none of the "
                                 f"multicolor preview colours {MULTICOLOR_PREVIEW}")
            pixels[r, c] = value
    return encode(pixels, True)


def to_image(data: bytes, multicolor: bool = False) -> Image.Image:
    """The sprite as a 24x21 RGB image in the preview colours (what read_png reads back)."""
    rgb = np.zeros((SPRITE_HEIGHT, SPRITE_WIDTH, 3), dtype=np.uint8)
    if multicolor:
        values = np.repeat(decode(data, True), 2, axis=1)
        for value, colour in MULTICOLOR_PREVIEW.items():
            rgb[values == value] = colour
    else:
        rgb[decode(data).astype(bool)] = HIRES_PREVIEW
    return Image.fromarray(rgb, "RGB")


def write_png(path: str | Path, data: bytes, multicolor: bool = False, scale: int = 1) -> Path:
    from retro.render.images import save_png, upscale

    return save_png(upscale(to_image(data, multicolor), scale), path)
