"""VIC-II scene files: the TOML format of docs/vic.md -> VicScene (validated dataclasses).

Every error is one line naming the file and the field: `FILE: sprite[2].x: ...`. Sprite `file`
paths, and the files `[memory]` reads (charset, bitmap, screen and colour RAM, CharPad projects,
Koala pictures: retro/loaders/gfx_screen.py), resolve relative to the scene file.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from retro.chips.vic.constants import (
    BANK_COUNT,
    CHAR_HEIGHT,
    COLOR_MASK,
    READ_ONLY_LATCHES,
    REG_IRQ_LATCH,
    REG_SPRITE_COLOR0,
    REG_SPRITE_ENABLE,
    REG_SPRITE_EXPAND_X,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_MULTICOLOR,
    REG_SPRITE_PRIORITY,
    REG_SPRITE_Y0,
    REGISTER_COUNT,
    SCREEN_CELLS,
    SPRITE_BYTES,
    SPRITE_COUNT,
    TEXT_COLUMNS,
    TEXT_ROWS,
    VIC_BASE,
    VIDEOS,
    X_BITS_MASK,
    Y_COMPARE_MASK,
)
from retro.chips.vic.graphics import VicMemory
from retro.chips.vic.model import VicState
from retro.chips.vic.sprite_registers import set_sprite_x
from retro.errors import InputError
from retro.fields import Fields
from retro.fileio import read_bytes
from retro.scenes import earlier_spelling
from retro.loaders.gfx_charpad import read_ctm
from retro.loaders.gfx_koala import koala_from_bytes
from retro.loaders.gfx_screen import vic_part, vic_parts
from retro.sprites import parse_hex, parse_rows, read_sprite, scene_colours

TOP_KEYS = {"chip", "video", "registers", "sprite", "memory", "cpu"}
CPU_KEYS = {"start_line", "start_cycle", "irq_vector"}  # where the beam is when the routine starts
SPRITE_KEYS = {"index", "x", "y", "enabled", "multicolor", "expand_x", "expand_y", "behind", "color", "data",
               "rows", "file", "frame", "palette", "velocity"}
IRQ_VECTOR_HARDWARE = "$fffe"  # the program puts its handler's address at $FFFE/$FFFF in RAM
IRQ_VECTOR_KERNAL = "$0314"  # the program puts it at $0314/$0315; the KERNAL entry saves A, X, Y first
IRQ_VECTORS = (IRQ_VECTOR_HARDWARE, IRQ_VECTOR_KERNAL)
MAX_SPEED = 255  # pixels a frame, either axis: faster than anything on screen
MEMORY_KEYS = {"screen", "color", "charset", "bitmap", "idle", "charpad", "koala", "bank"}
FILL_KEYS = {"fill", "cells", "file"}
# keys that read one file into several parts of memory (retro/loaders/gfx_screen.py)
WHOLE_FILE_PARTS = {"charpad": ("charset", "screen", "color"), "koala": ("bitmap", "screen", "color")}
WHOLE_FILE_KEYS = {"charpad": {"file", "col", "row"}, "koala": {"file"}}
MAX_MAP_CELL = 0xFFFF * 8  # a CharPad map is at most 65535 entries of tiles up to 8 cells wide
SCREEN_CELL_KEYS = {"col", "row", "value"}
BITMAP_KEYS = {"cells", "file"}
BITMAP_CELL_KEYS = {"col", "row", "bytes"}
SPRITE_FLAGS = {"enabled": REG_SPRITE_ENABLE, "multicolor": REG_SPRITE_MULTICOLOR, "expand_x": REG_SPRITE_EXPAND_X,
                "expand_y": REG_SPRITE_EXPAND_Y, "behind": REG_SPRITE_PRIORITY}


@dataclass(frozen=True)
class SpriteSpec:
    index: int
    data: bytes  # 63 bytes
    source: str  # "data", "rows", "file NAME"
    velocity: tuple[int, int] = (0, 0)  # X and Y added every frame (`retro vic --frames N`)


@dataclass(frozen=True, eq=False)
class VicScene:
    """A validated VIC-II scene: initial registers, sprite data, what the VIC sees in memory."""

    source: str
    video: str
    registers: bytes
    sprites: tuple[SpriteSpec, ...]
    memory: VicMemory
    state: VicState = field(repr=False)
    cpu_variant: str = "6510"
    start_line: int = 0  # [cpu] start_line / start_cycle: the beam when the routine is entered
    start_cycle: int = 1
    irq_vector: str = IRQ_VECTOR_HARDWARE  # or IRQ_VECTOR_KERNAL (retro.machines.c64 puts the KERNAL's entry in RAM)
    bank: int = 0  # [memory] bank: the VIC-II's 16K bank (CIA 2 $DD00 bits 0-1 inverted) in a program run


def register_offset(key: str, where: Fields) -> int:
    text = str(key).strip().lower()
    digits = text[1:] if text.startswith("$") else text[2:] if text.startswith("0x") else text
    try:
        address = int(digits, 16)
    except ValueError:
        raise where.error(f"registers.{key}", "not a register address (write \"$d011\", \"0xd011\" or \"d011\")") from None
    offset = address - VIC_BASE
    if not 0 <= offset < REGISTER_COUNT:
        raise where.error(f"registers.{key}", f"not a VIC-II register (${VIC_BASE:04x}-${VIC_BASE + REGISTER_COUNT - 1:04x})")
    if offset in READ_ONLY_LATCHES or offset == REG_IRQ_LATCH:
        raise where.error(f"registers.{key}", "a latch the chip sets; a scene starts with it clear")
    return offset


def _sprite(entry, i: int, registers: bytearray, seen: set[int], where: Fields) -> SpriteSpec:
    name = f"sprite[{i}]"
    entry = where.table(entry, name, SPRITE_KEYS)
    n = where.integer(where.required(entry, "index", name, f"the sprite's number, 0-{SPRITE_COUNT - 1}"),
                      f"{name}.index", 0, SPRITE_COUNT - 1)
    if n in seen:
        raise where.error(f"{name}.index", f"sprite {n} is declared twice")
    seen.add(n)
    _sprite_registers(entry, n, name, registers, where)
    velocity = (0, 0)
    if "velocity" in entry:
        value = entry["velocity"]
        if not isinstance(value, list) or len(value) != 2:
            raise where.error(f"{name}.velocity", "expected [dx, dy]: pixels added to X and Y every frame")
        velocity = tuple(where.integer(v, f"{name}.velocity", -MAX_SPEED, MAX_SPEED) for v in value)
    data, source = _sprite_data(entry, n, name, registers, where)
    return SpriteSpec(n, data[:SPRITE_BYTES], source, velocity)


def _sprite_registers(entry: dict, n: int, name: str, registers: bytearray, where: Fields) -> None:
    """A sprite's place, flags and colour into the register image."""
    bit = 1 << n
    if "x" in entry:
        x = where.integer(entry["x"], f"{name}.x", 0, X_BITS_MASK)
        set_sprite_x(registers, n, x)
    if "y" in entry:
        registers[REG_SPRITE_Y0 + 2 * n] = where.integer(entry["y"], f"{name}.y", 0, Y_COMPARE_MASK)
    flags = {"enabled": True, **{k: entry[k] for k in SPRITE_FLAGS if k in entry}}
    for key, value in flags.items():
        on = where.flag(value, f"{name}.{key}")
        register = SPRITE_FLAGS[key]
        registers[register] = (registers[register] & ~bit) | (bit if on else 0)
    if "color" in entry:
        registers[REG_SPRITE_COLOR0 + n] = where.integer(entry["color"], f"{name}.color", 0, COLOR_MASK)


def _sprite_data(entry: dict, n: int, name: str, registers: bytearray, where: Fields) -> tuple[bytes, str]:
    """The sprite's bytes from `data`, `rows` or a `file` (read in the sprite's colours), and where
    they came from; an error in them names the sprite's key."""
    multicolor = bool(registers[REG_SPRITE_MULTICOLOR] & (1 << n))
    kind = where.exactly_one(entry, ("data", "rows", "file"), name)
    for key in ("frame", "palette"):
        if key in entry and kind != "file":
            raise where.error(f"{name}.{key}", "goes with file")
    try:
        if kind == "data":
            return parse_hex(entry["data"], field="data"), "data"
        if kind == "rows":
            return parse_rows(entry["rows"], multicolor, field="rows"), "rows"
        path = where.file(entry["file"], f"{name}.file", "sprite file")
        frame = where.integer(entry.get("frame", 0), f"{name}.frame", 0, 1 << 16)
        # any sprite file, by content (retro/sprites.py); a PNG is read in this sprite's colours
        data = read_sprite(path, frame, multicolor, scene_colours(registers, n), entry.get("palette"))
        return data, f"file {entry['file']}"
    except InputError as exc:
        message = str(exc)
        if message.startswith(f"{where.source}: "):
            raise
        if message.startswith(kind) or message.startswith("rows["):
            raise InputError(f"{where.source}: {name}.{message}") from None
        raise InputError(f"{where.source}: {name}: {message}") from None


def _fill_cells(spec, name: str, where: Fields, hi: int, given: tuple | None) -> np.ndarray:
    """memory.screen / memory.color: `fill`, then a `file` (or the part a whole-file key gave), then `cells`."""
    spec = where.table(spec if spec is not None else {}, f"memory.{name}", FILL_KEYS)
    values = np.full(SCREEN_CELLS, where.integer(spec.get("fill", 0), f"memory.{name}.fill", 0, hi), np.uint8)
    part = _part_file(spec, name, where, given)
    if part is not None:
        covered = part.covered if part.covered is not None else slice(None)
        values[covered] = part.values[covered]
    cells = where.array(spec.get("cells", []), f"memory.{name}.cells", "{col, row, value} tables")
    for i, cell in enumerate(cells):
        field_name = f"memory.{name}.cells[{i}]"
        cell, index = _cell(cell, field_name, SCREEN_CELL_KEYS, where)
        values[index] = where.integer(cell["value"], f"{field_name}.value", 0, hi)
    return values


def _part_file(table: dict, part: str, where: Fields, given: tuple | None):
    """The part (gfx_screen.Part) a `file` key in memory.PART gives, or the one a whole-file key
    (memory.charpad, memory.koala) gave; both is an error."""
    if "file" not in table:
        return given[0] if given else None
    if given:
        raise where.error(f"memory.{part}.file", f"memory.{given[1]} gives the {part} already; give one of them")
    field_name = f"memory.{part}.file"
    path = where.file(table["file"], field_name, "file")
    try:
        return vic_part(read_bytes(path), repr(table["file"]), part)
    except InputError as exc:
        raise where.error(field_name, str(exc)) from None


def _whole_files(spec: dict, where: Fields) -> dict[str, tuple]:
    """memory.charpad and memory.koala: {part: (gfx_screen.Part, key)} for every part they give."""
    given: dict[str, tuple] = {}
    for key, parts in WHOLE_FILE_PARTS.items():
        if key not in spec:
            continue
        value = spec[key]
        table = {"file": value} if isinstance(value, str) else where.table(value, f"memory.{key}", WHOLE_FILE_KEYS[key])
        field_name = f"memory.{key}" if isinstance(value, str) else f"memory.{key}.file"
        if "file" not in table:
            raise where.error(field_name, "missing: the file to read")
        col = where.integer(table.get("col", 0), f"memory.{key}.col", 0, MAX_MAP_CELL)
        row = where.integer(table.get("row", 0), f"memory.{key}.row", 0, MAX_MAP_CELL)
        for part in parts:
            if part in given:
                raise where.error(f"memory.{key}", f"memory.{given[part][1]} gives the {part} already; give one of them")
        path = where.file(table["file"], field_name, "file")
        raw = read_bytes(path)
        name = repr(table["file"])
        try:
            if key == "charpad":
                rows, cols = read_ctm(raw, name).size
                for axis, value, size in (("col", col, cols), ("row", row, rows)):
                    if value >= size:
                        raise where.error(f"memory.charpad.{axis}", f"{name}: the map is {cols} x {rows} screen cells: "
                                                                    f"{axis} {value} is past its edge")
            else:
                koala_from_bytes(raw, name)  # refuses what is not a Koala picture
            for part, values in vic_parts(raw, name, parts, col, row).items():
                given[part] = (values, key)
        except InputError as exc:
            if str(exc).startswith(f"{where.source}: "):
                raise
            raise where.error(field_name, str(exc)) from None
    return given


def _cell(cell, field_name: str, keys, where: Fields) -> tuple[dict, int]:
    """A {col, row, ...} table with all its keys: (the table, the cell's index in the 40 x 25 screen)."""
    cell = where.table(cell, field_name, keys)
    for key in sorted(keys):
        where.required(cell, key, field_name)
    col = where.integer(cell["col"], f"{field_name}.col", 0, TEXT_COLUMNS - 1)
    row = where.integer(cell["row"], f"{field_name}.row", 0, TEXT_ROWS - 1)
    return cell, row * TEXT_COLUMNS + col


def _memory(doc, where: Fields) -> VicMemory:
    spec = where.table(doc, "memory", MEMORY_KEYS)
    memory = VicMemory.blank()
    given = _whole_files(spec, where)
    screen = memory.screen
    if "screen" in spec or "screen" in given:
        screen = _fill_cells(spec.get("screen"), "screen", where, 0xFF, given.get("screen"))
    color = memory.color
    if "color" in spec or "color" in given:
        color = _fill_cells(spec.get("color"), "color", where, COLOR_MASK, given.get("color"))
    charset = memory.charset
    if "charset" in spec or "charset" in given:
        table = spec.get("charset", {})
        if not isinstance(table, dict):
            raise where.error("memory.charset", "expected a table of glyphs by code (\"1\" = [8 bytes]) or file =")
        part = _part_file(table, "charset", where, given.get("charset"))
        if part is not None:
            charset = part.values
        spelled: dict[int, str] = {}
        for key, glyph in table.items():
            if key == "file":
                continue
            code = where.integer(key, f"memory.charset.{key}", 0, 0xFF)
            if earlier := earlier_spelling(spelled, code, key):
                raise where.error(f"memory.charset.{key}", f"the same character code as {earlier!r}; give it once")
            charset[code * CHAR_HEIGHT:(code + 1) * CHAR_HEIGHT] = where.byte_list(glyph, f"memory.charset.{key}",
                                                                                   CHAR_HEIGHT)
    bitmap = memory.bitmap
    if "bitmap" in spec or "bitmap" in given:
        table = where.table(spec.get("bitmap", {}), "memory.bitmap", BITMAP_KEYS)
        part = _part_file(table, "bitmap", where, given.get("bitmap"))
        if part is not None:
            bitmap = part.values
        cells = where.array(table.get("cells", []), "memory.bitmap.cells", "{col, row, bytes} tables")
        for i, cell in enumerate(cells):
            field_name = f"memory.bitmap.cells[{i}]"
            cell, index = _cell(cell, field_name, BITMAP_CELL_KEYS, where)
            start = index * CHAR_HEIGHT
            bitmap[start:start + CHAR_HEIGHT] = where.byte_list(cell["bytes"], f"{field_name}.bytes", CHAR_HEIGHT)
    idle = where.integer(spec.get("idle", 0), "memory.idle", 0, 0xFF)
    return VicMemory(screen, color, charset, bitmap, idle)


def parse(doc: dict, source: str) -> VicScene:
    where = Fields(source)
    where.table(doc, "", TOP_KEYS)
    video = where.choice(doc.get("video", "pal"), "video", VIDEOS,
                         labels={name: f"{name!r} ({standard.chip})" for name, standard in VIDEOS.items()})
    registers = bytearray(REGISTER_COUNT)
    table = doc.get("registers", {})
    if not isinstance(table, dict):
        raise where.error("registers", "expected a table of \"$d0xx\" = value")
    spelled: dict[int, str] = {}  # offset -> the key that set it ("$d011" and "d011" are one register)
    for key, value in table.items():
        offset = register_offset(key, where)
        if earlier := earlier_spelling(spelled, offset, key):
            raise where.error(f"registers.{key}", f"the same register as {earlier!r}; give it once")
        registers[offset] = where.integer(value, f"registers.{key}", 0, 0xFF)
    entries = where.array_of_tables(doc.get("sprite", []), "sprite", SPRITE_KEYS)
    seen: set[int] = set()
    specs = [_sprite(entry, i, registers, seen, where) for i, entry in enumerate(entries)]
    data = [bytes(SPRITE_BYTES)] * SPRITE_COUNT
    for spec in specs:
        data[spec.index] = spec.data
    memory = _memory(doc.get("memory", {}), where)
    state = VicState(VIDEOS[video], bytes(registers), tuple(data), memory)
    cpu = where.table(doc.get("cpu", {}), "cpu", CPU_KEYS)
    start_line = where.integer(cpu.get("start_line", 0), "cpu.start_line", 0, VIDEOS[video].lines - 1)
    start_cycle = where.integer(cpu.get("start_cycle", 1), "cpu.start_cycle", 1, VIDEOS[video].cycles_per_line)
    irq_vector = where.choice(cpu.get("irq_vector", IRQ_VECTORS[0]), "cpu.irq_vector", IRQ_VECTORS, fold_case=True)
    bank = where.integer(where.table(doc.get("memory", {}), "memory", MEMORY_KEYS).get("bank", 0), "memory.bank", 0,
                         BANK_COUNT - 1)
    return VicScene(source, video, bytes(registers), tuple(specs), memory, state, bank=bank, start_line=start_line,
                    start_cycle=start_cycle, irq_vector=irq_vector)


def load(path: str | Path) -> VicScene:
    """Read and validate a VIC-II scene file (the chip key must say "vic-ii")."""
    from retro.scenes import load_scene

    scene = load_scene(path)
    if not isinstance(scene, VicScene):
        raise InputError(f"{path}: chip: expected \"vic-ii\"")
    return scene
