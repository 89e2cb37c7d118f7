"""PNG sprites and sprite sheets -> 63-byte sprites, colours mapped through a C64 palette.

Size (read from the header, before any pixel is decoded): 21 rows a sprite; 24 pixels a sprite, or
for a multicolour sprite also 12 (one image pixel a multicolour pixel). A sheet is a grid of such
cells, read left to right, then top to bottom (frame 0 top left), at most MAX_SHEET_SPRITES.

Colours, pixel by pixel:
1. Alpha 0 is transparent. Alpha 255 is a colour. Anything between is refused, naming the pixel.
2. A colour is the nearest (Euclidean RGB) colour of the palette: the one named, or, when none is
   named, the C64 palette (c64-pepto, then c64-colodore) that holds every colour of the image exactly,
   or c64-pepto. When the nearest palette colour is not clearly nearer than the next one (its distance
   is more than AMBIGUOUS_RATIO of the next one's), the colour is ambiguous and refused, naming the
   pixel: the two palettes differ enough that a picture in one read through the other can land
   between two colours (Pepto's light blue is as near Colodore's purple as its light blue).
3. The C64 colour gives the bits, through the sprite's colours (SpriteColours: a scene's $D021,
   $D025, the sprite's $D027+n, $D026):
   - hires: clear where transparent, black or the background colour; set anywhere else (a hires
     sprite has one colour, so which other colour the picture uses does not matter);
   - multicolour, when the background, $D025, the sprite's colour and $D026 are four different
     colours: background -> 00, $D025 -> 01, sprite colour -> 10, $D026 -> 11 [Bauer 3.8.2]; black,
     when it is none of the sprite's colours, -> 00; any other colour is refused, naming the pixel;
   - multicolour otherwise (no colours given, or two of them alike, as in a scene that sets none):
     the preview colours `retro.render.sprite_png.write_png` draws with, light blue -> 01, white -> 10,
     yellow -> 11; black, and the background colour when it is none of those three, -> 00; any
     other colour is refused, naming the pixel.
4. Multicolour layout: an image whose width is a multiple of 24 and whose every horizontal pixel
   pair (x even, x + 1) gives the same bits is read with two image pixels a multicolour pixel (24x21
   cells, as on screen); so is any image exactly 24 pixels wide, where a pair of two values is
   refused naming the pixels. Otherwise (width a multiple of 12) one image pixel is one multicolour
   pixel (12x21 cells).
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np
from PIL import Image

from retro.chips.vic.constants import SPRITE_HEIGHT, SPRITE_MC_WIDTH, SPRITE_WIDTH
from retro.errors import InputError
from retro.chips.palettes import C64_DEFAULT_PALETTE, PALETTES

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
MAX_SHEET_SPRITES = 1024  # a 32 x 32 sheet; 1024 x 24 x 21 pixels decode to about 2 MB of RGBA
C64_PALETTES = ("c64-pepto", "c64-colodore")  # the auto choice tries them in this order
AMBIGUOUS_RATIO = 0.9
AMBIGUOUS_SQUARED = 81  # 100 * AMBIGUOUS_RATIO ** 2, for the comparison in integers
BLACK = 0
C64_COLOUR_NAMES = ("black", "white", "red", "cyan", "purple", "green", "blue", "yellow", "orange", "brown",
                    "light red", "dark grey", "grey", "light green", "light blue", "light grey")
PREVIEW_VALUES = {14: 1, 1: 2, 7: 3}  # light blue, white, yellow: retro.sprites.MULTICOLOR_PREVIEW


@dataclass(frozen=True)
class SpriteColours:
    """The colours a sprite is shown in: what a PNG of it shows."""

    background: int = 0  # $D021: pair 00
    multicolor1: int = 0  # $D025: pair 01
    colour: int = 0  # $D027+n: hires 1, pair 10
    multicolor2: int = 0  # $D026: pair 11

    def distinct(self) -> bool:
        return len({self.background, self.multicolor1, self.colour, self.multicolor2}) == 4


@dataclass(frozen=True)
class PngSheet:
    frames: tuple[bytes, ...]  # 63 bytes each, left to right then top to bottom
    cell_width: int  # 24, or 12 (multicolour, one image pixel a multicolour pixel)
    palette: str  # the palette the colours were matched in


def _named(colour: int) -> str:
    return f"{colour} ({C64_COLOUR_NAMES[colour]})"


def _cells(width: int, height: int, multicolor: bool, name: str) -> None:
    narrow = SPRITE_MC_WIDTH if multicolor else SPRITE_WIDTH
    if width == 0 or height == 0 or width % narrow or height % SPRITE_HEIGHT:
        also = f", or multiples of {SPRITE_MC_WIDTH}x{SPRITE_HEIGHT} for multicolour" if multicolor else ""
        raise InputError(f"{name}: a sprite PNG is {SPRITE_WIDTH}x{SPRITE_HEIGHT} pixels or a sheet of them "
                         f"(multiples of {SPRITE_WIDTH}x{SPRITE_HEIGHT}{also}), got {width}x{height}")
    most = (width // narrow) * (height // SPRITE_HEIGHT)
    if most > MAX_SHEET_SPRITES:
        raise InputError(f"{name}: a {width}x{height} sheet holds up to {most} sprites; at most "
                         f"{MAX_SHEET_SPRITES} are read")


def _first(mask: np.ndarray) -> tuple[int, int]:
    y, x = np.unravel_index(int(np.argmax(mask)), mask.shape)
    return int(x), int(y)


def _pack(rgb: np.ndarray) -> np.ndarray:
    rgb = np.asarray(rgb, dtype=np.int64)
    return (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]


def _palette_for(used: np.ndarray, chosen: str | None) -> str:
    """The palette chosen, else the first C64 palette holding every used (packed) colour exactly."""
    if chosen is not None:
        if not isinstance(chosen, str) or chosen not in C64_PALETTES:
            raise InputError(f"palette: {chosen!r} is not a C64 palette (known: {', '.join(C64_PALETTES)})")
        return chosen
    for candidate in C64_PALETTES:
        if np.isin(used, _pack(PALETTES[candidate])).all():
            return candidate
    return C64_DEFAULT_PALETTE


def _c64_colours(rgba: np.ndarray, chosen: str | None, name: str) -> tuple[np.ndarray, str]:
    """(H, W) int: the C64 colour of each pixel, -1 where transparent; and the palette used."""
    alpha = rgba[..., 3]
    partial = (alpha != 0) & (alpha != 255)
    if partial.any():
        x, y = _first(partial)
        raise InputError(f"{name}: pixel ({x}, {y}) is partly transparent (alpha {int(alpha[y, x])}): a sprite "
                         f"pixel is transparent (alpha 0) or one colour")
    opaque = alpha == 255
    packed = np.where(opaque, _pack(rgba[..., :3]), -1)
    used, inverse = np.unique(packed, return_inverse=True)
    inverse = inverse.reshape(packed.shape)
    palette_name = _palette_for(used[used >= 0], chosen)
    colours = np.array(PALETTES[palette_name], dtype=np.int64)  # (16, 3)
    rgb = np.stack([(used >> 16) & 255, (used >> 8) & 255, used & 255], axis=1)  # (colours used, 3)
    # squared distances, (colours used, 16), exact in integers: |p|^2 - 2 p.c + |c|^2
    square = (rgb * rgb).sum(axis=1)[:, None] - 2 * rgb @ colours.T + (colours * colours).sum(axis=1)[None, :]
    order = np.argsort(square, axis=1, kind="stable")
    nearest, second = order[:, 0], order[:, 1]
    rows = np.arange(len(used))
    d1, d2 = np.sqrt(square[rows, nearest]), np.sqrt(square[rows, second])
    # d1 > AMBIGUOUS_RATIO * d2, in integers: 100 d1^2 > 81 d2^2
    ambiguous = (used >= 0) & (100 * square[rows, nearest] > AMBIGUOUS_SQUARED * square[rows, second])
    if ambiguous.any():
        x, y = _first(ambiguous[inverse])
        u = int(inverse[y, x])
        raise InputError(f"{name}: pixel ({x}, {y}): colour #{int(used[u]):06x} is about as near C64 colour "
                         f"{_named(int(nearest[u]))} as {_named(int(second[u]))} in the {palette_name} palette "
                         f"({d1[u]:.1f} and {d2[u]:.1f} apart): draw it in the palette's own colours or name "
                         f"the palette it uses")
    return np.where(used >= 0, nearest, -1)[inverse].astype(np.int16), palette_name


def _values(c64: np.ndarray, multicolor: bool, colours: SpriteColours | None, name: str) -> np.ndarray:
    """(H, W) uint8: the bit (hires) or bit pair (multicolour) of each image pixel."""
    background = colours.background if colours is not None else BLACK
    if not multicolor:
        return ((c64 >= 0) & (c64 != BLACK) & (c64 != background)).astype(np.uint8)
    if colours is not None and colours.distinct():
        values = {colours.background: 0, colours.multicolor1: 1, colours.colour: 2, colours.multicolor2: 3}
        what = (f"this sprite's colours: background $D021 = {_named(colours.background)}, $D025 = "
                f"{_named(colours.multicolor1)}, sprite colour = {_named(colours.colour)}, $D026 = "
                f"{_named(colours.multicolor2)}")
    else:
        values = dict(PREVIEW_VALUES)
        values.setdefault(background, 0)
        what = ("the multicolour preview colours (light blue 14 = 01, white 1 = 10, yellow 7 = 11): give the "
                "scene four different colours in $D021, $D025, $D026 and the sprite's color to read a picture "
                "in the sprite's own colours")
    values.setdefault(BLACK, 0)
    table = np.full(17, 255, dtype=np.uint8)  # index 16 stands for transparent (-1)
    table[16] = 0
    for colour, value in values.items():
        table[colour] = value
    out = table[np.where(c64 < 0, 16, c64)]
    unknown = out == 255
    if unknown.any():
        x, y = _first(unknown)
        raise InputError(f"{name}: pixel ({x}, {y}) is C64 colour {_named(int(c64[y, x]))}, none of {what}")
    return out


def _layout(values: np.ndarray, multicolor: bool, name: str) -> int:
    width = values.shape[1]
    if not multicolor:
        return SPRITE_WIDTH
    if width % SPRITE_WIDTH == 0:
        differ = values[:, 0::2] != values[:, 1::2]
        if not differ.any():
            return SPRITE_WIDTH
        if width == SPRITE_WIDTH:
            x, y = _first(differ)
            raise InputError(f"{name}: pixels ({2 * x}, {y}) and ({2 * x + 1}, {y}) differ: in a multicolour "
                             f"sprite 24 pixels wide a pixel is two image pixels (or draw it 12x21)")
    return SPRITE_MC_WIDTH


def _encode(cell: np.ndarray, multicolor: bool) -> bytes:
    if multicolor:
        bits = np.empty((SPRITE_HEIGHT, SPRITE_WIDTH), dtype=np.uint8)
        bits[:, 0::2] = cell >> 1
        bits[:, 1::2] = cell & 1
    else:
        bits = cell
    return np.packbits(bits, axis=1).tobytes()


def read_png_sheet(raw: bytes, name: str, multicolor: bool = False, colours: SpriteColours | None = None,
                   palette: str | None = None) -> PngSheet:
    """A PNG's bytes -> every sprite in it (see the module docstring for the rules)."""
    try:
        image = Image.open(io.BytesIO(raw))  # reads the header only: the size is known before decoding
    except Exception:  # Pillow raises several types for bad files
        raise InputError(f"{name}: not a readable PNG image") from None
    _cells(image.width, image.height, multicolor, name)
    try:
        rgba = np.asarray(image.convert("RGBA"))
    except Exception:  # a valid header over damaged pixel data
        raise InputError(f"{name}: not a readable PNG image") from None
    c64, palette_name = _c64_colours(rgba, palette, name)
    values = _values(c64, multicolor, colours, name)
    cell_width = _layout(values, multicolor, name)
    frames = []
    for top in range(0, values.shape[0], SPRITE_HEIGHT):
        for left in range(0, values.shape[1], cell_width):
            cell = values[top:top + SPRITE_HEIGHT, left:left + cell_width]
            if multicolor and cell_width == SPRITE_WIDTH:
                cell = cell[:, 0::2]
            frames.append(_encode(cell, multicolor))
    return PngSheet(tuple(frames), cell_width, palette_name)
