"""Spritemate sprite files (.spm, JSON), detected by content.

The layout is read from Spritemate's source (github.com/Esshahn/spritemate: src/js/Load.ts,
src/js/Save.ts, src/js/SpriteTypes.ts, src/js/Export-Base.ts); nothing here is copied from it:
- a JSON object with `colors` (keys "0", "2", "3": background, multicolour 1 ($D025), multicolour 2
  ($D026)) and `sprites`, a list of objects with `color` (0-15, the sprite's own colour), `multicolor`,
  `double_x`, `double_y`, `overlay` (booleans; files without `overlay` exist) and `pixels`: 21 rows
  of 24 pens. Newer files add `version`, `filename`, `name`, `current_sprite`, `pen`, `animation`.
- Pens: 0 transparent, 1 the sprite's colour, 2 multicolour 1, 3 multicolour 2. Files saved before
  Spritemate's commit 996f695 (2018-05-26, "changed internal sprite format") write them, and the
  `colors` keys, as "t", "i", "m1", "m2" (Load.ts still turns these into 0-3).
- A multicolour sprite keeps its 24 pens per row but only the even columns count: Spritemate draws and
  exports a multicolour pixel from pens[y][0], [2], ... (Export-Base.ts steps by 2; Save.ts reads
  every other pen). Bit pairs, as Save.ts writes them to SpritePad files: pen 0 -> 00, 1 -> 10,
  2 -> 01, 3 -> 11 - the VIC-II's own meaning of the pairs
  (01 $D025, 10 the sprite's colour, 11 $D026) [Bauer 3.8.2].
- Hires: pen 0 is a clear bit, any other pen a set bit.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from retro.chips.vic.constants import SPRITE_HEIGHT, SPRITE_WIDTH
from retro.errors import InputError
from retro.fileio import read_bytes
from retro.numbers import MAX_DIGITS

LEGACY_PENS = {"t": 0, "i": 1, "m1": 2, "m2": 3}  # before 2018-05-26
LEGACY_COLOUR_KEYS = {"t": "0", "m1": "2", "m2": "3"}
PEN_PAIR = (0b00, 0b10, 0b01, 0b11)  # pen -> multicolour bit pair
MAX_SPRITES = 4096  # Spritemate files hold a few hundred at most; this bounds the work on a hostile file
_NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
_KEY_BEFORE = re.compile(r'"([^"\\]{1,40})"\s*:\s*$')  # the key whose value starts where the search ends


class _NotANumber(Exception):
    """A JSON number retro does not read (too long, or NaN / Infinity, which JSON does not have)."""


def _strict_int(text: str) -> int:
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise _NotANumber(text)
    return int(text)


def _strict_float(text: str) -> float:
    if len(text) > MAX_DIGITS:
        raise _NotANumber(text)
    return float(text)


def _no_constant(text: str):
    raise _NotANumber(text)


def _number_error(text: str, number: str, name: str) -> InputError:
    """Where in the file the refused number is, for the error."""
    at = next((m.start() for m in _NUMBER.finditer(text) if m.group() == number), None)
    if at is None:
        at = text.find(number)
    line = text.count("\n", 0, at) + 1
    column = at - (text.rfind("\n", 0, at) + 1) + 1
    key = _KEY_BEFORE.search(text, max(0, at - 200), at)
    what = (f"a number of {len(number)} characters (at most {MAX_DIGITS} are read)" if len(number) > MAX_DIGITS
            else f"{number} is not a JSON number")
    return InputError(f"{name}: not a Spritemate file: line {line} column {column}: "
                      f"{key.group(1) + ': ' if key else ''}{what}")


@dataclass(frozen=True)
class SpritemateSprite:
    data: bytes  # 63 bytes
    name: str
    colour: int
    multicolor: bool
    overlay: bool
    expand_x: bool
    expand_y: bool


@dataclass(frozen=True)
class SpritemateFile:
    version: str  # the file's "version", or "legacy" (pens written as t, i, m1, m2) / "unversioned"
    background: int
    multicolor1: int
    multicolor2: int
    sprites: tuple[SpritemateSprite, ...]


def looks_like_spm(raw: bytes) -> bool:
    """A JSON object (optionally after a UTF-8 byte order mark and white space)."""
    return raw.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"{")


def _colour(value, field: str, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 15:
        raise InputError(f"{name}: {field}: {value!r} is not a C64 colour (0-15)")
    return value


def _flag(sprite: dict, key: str, field: str, name: str) -> bool:
    value = sprite.get(key, False)
    if not isinstance(value, bool):
        raise InputError(f"{name}: {field}.{key}: expected true or false, got {value!r}")
    return value


def _pens(rows, field: str, name: str) -> np.ndarray:
    if not isinstance(rows, list) or len(rows) != SPRITE_HEIGHT:
        got = len(rows) if isinstance(rows, list) else type(rows).__name__
        raise InputError(f"{name}: {field}: expected {SPRITE_HEIGHT} rows of {SPRITE_WIDTH} pens, got {got}")
    pens = np.zeros((SPRITE_HEIGHT, SPRITE_WIDTH), dtype=np.uint8)
    for y, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != SPRITE_WIDTH:
            got = len(row) if isinstance(row, list) else type(row).__name__
            raise InputError(f"{name}: {field}[{y}]: expected {SPRITE_WIDTH} pens, got {got}")
        for x, pen in enumerate(row):
            value = LEGACY_PENS.get(pen) if isinstance(pen, str) else pen
            if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 3:
                raise InputError(f"{name}: {field}[{y}][{x}]: {pen!r} is not a pen (0-3, or t, i, m1, m2)")
            pens[y, x] = value
    return pens


def _data(pens: np.ndarray, multicolor: bool) -> bytes:
    if multicolor:
        pairs = np.array(PEN_PAIR, dtype=np.uint8)[pens[:, 0::2]]  # (21, 12): the even columns count
        bits = np.empty((SPRITE_HEIGHT, SPRITE_WIDTH), dtype=np.uint8)
        bits[:, 0::2] = pairs >> 1
        bits[:, 1::2] = pairs & 1
    else:
        bits = (pens != 0).astype(np.uint8)
    return np.packbits(bits, axis=1).tobytes()


def parse_spm(raw: bytes, name: str = "sprite file") -> SpritemateFile:
    """Spritemate JSON bytes -> sprites (63 bytes each) with their attributes and the shared colours."""
    doc = _json_document(raw, name)
    colours = doc.get("colors")
    if not isinstance(colours, dict):
        raise InputError(f"{name}: colors: expected an object with keys \"0\", \"2\", \"3\"")
    legacy = any(key in colours for key in LEGACY_COLOUR_KEYS)
    shared = {}
    for key in ("0", "2", "3"):
        spelled = next((k for k, v in LEGACY_COLOUR_KEYS.items() if v == key), key) if legacy else key
        if spelled not in colours:
            raise InputError(f"{name}: colors.{spelled}: missing")
        shared[key] = _colour(colours[spelled], f"colors.{spelled}", name)
    entries = doc["sprites"]
    if not isinstance(entries, list) or not entries:
        raise InputError(f"{name}: sprites: expected a list of at least one sprite")
    if len(entries) > MAX_SPRITES:
        raise InputError(f"{name}: sprites: {len(entries)} sprites, at most {MAX_SPRITES} are read")
    sprites = tuple(_sprite(sprite, i, name) for i, sprite in enumerate(entries))
    version = doc.get("version")
    label = str(version) if isinstance(version, (str, int, float)) else ("legacy" if legacy else "unversioned")
    return SpritemateFile(label, shared["0"], shared["2"], shared["3"], sprites)


def _json_document(raw: bytes, name: str) -> dict:
    """The file's JSON object, numbers read strictly; any fault one line naming the file."""
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"{name}: not a Spritemate file: not UTF-8 text (byte {exc.start})") from None
    try:
        doc = json.loads(text, parse_int=_strict_int, parse_float=_strict_float, parse_constant=_no_constant)
    except _NotANumber as exc:
        raise _number_error(text, exc.args[0], name) from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{name}: not a Spritemate file: JSON error at line {exc.lineno} column {exc.colno}: "
                         f"{exc.msg}") from None
    except RecursionError:
        raise InputError(f"{name}: not a Spritemate file: JSON nested too deeply") from None
    if not isinstance(doc, dict) or "sprites" not in doc:
        raise InputError(f"{name}: not a Spritemate file: a JSON object with \"colors\" and \"sprites\" is expected")
    return doc


def _sprite(sprite, i: int, name: str) -> SpritemateSprite:
    field = f"sprites[{i}]"
    if not isinstance(sprite, dict):
        raise InputError(f"{name}: {field}: expected an object, got {type(sprite).__name__}")
    for key in ("color", "pixels"):
        if key not in sprite:
            raise InputError(f"{name}: {field}.{key}: missing")
    multicolor = _flag(sprite, "multicolor", field, name)
    pens = _pens(sprite["pixels"], f"{field}.pixels", name)
    label = sprite.get("name", f"sprite{i + 1}")
    return SpritemateSprite(_data(pens, multicolor), str(label), _colour(sprite["color"], f"{field}.color", name),
                            multicolor, _flag(sprite, "overlay", field, name), _flag(sprite, "double_x", field, name),
                            _flag(sprite, "double_y", field, name))


def read_spm(path: str | Path) -> SpritemateFile:
    return parse_spm(read_bytes(path, "sprite file"), str(path))
