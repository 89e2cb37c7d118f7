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
    REG_SPRITE_X0,
    REG_SPRITE_X_MSB,
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
from retro.errors import InputError
from retro.fileio import is_dir, is_file, read_bytes
from retro.numbers import parse_int
from retro.scenes import earlier_spelling
from retro.loaders.gfx_charpad import read_ctm
from retro.loaders.gfx_koala import koala_from_bytes
from retro.loaders.gfx_screen import vic_part, vic_parts
from retro.sprites import parse_hex, parse_rows, read_sprite, scene_colours

TOP_KEYS = {"chip", "video", "registers", "sprite", "memory", "cpu"}
CPU_KEYS = {"start_line", "start_cycle", "irq_vector"}  # where the beam is when the routine starts
SPRITE_KEYS = {"index", "x", "y", "enabled", "multicolor", "expand_x", "expand_y", "behind", "color", "data",
               "rows", "file", "frame", "palette", "velocity"}
MAX_SPEED = 255  # pixels a frame, either axis: faster than anything on screen
MEMORY_KEYS = {"screen", "color", "charset", "bitmap", "idle", "charpad", "koala"}
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
    irq_vector: str = "$fffe"  # or "$0314": the KERNAL's IRQ entry is put in RAM (retro.machines.c64)

    def attach(self, machine):
        """Map a VIC-II device for this scene at $D000-$D3FF with the beam at the scene's start position now."""
        from retro.chips.vic.constants import VIC_LAST
        from retro.chips.vic.device import VicDevice
        from retro.machines.c64 import IRQ_VECTOR_KERNAL, install_kernal_irq_entry

        device = VicDevice.at_beam(self.state, machine.cycle, self.start_line, self.start_cycle)
        if self.irq_vector == IRQ_VECTOR_KERNAL:
            install_kernal_irq_entry(machine)
        return machine.attach(device, VIC_BASE, VIC_LAST)


class _Where:
    def __init__(self, source: str):
        self.source = source

    def error(self, field_name: str, message: str) -> InputError:
        return InputError(f"{self.source}: {field_name}: {message}")

    def table(self, value, field_name: str, allowed: set[str]) -> dict:
        if not isinstance(value, dict):
            raise self.error(field_name, f"expected a table, got {type(value).__name__}")
        unknown = sorted(set(value) - allowed)
        if unknown:
            raise self.error(f"{field_name}.{unknown[0]}" if field_name else unknown[0],
                             f"unknown key (known: {', '.join(sorted(allowed))})")
        return value

    def number(self, value, field_name: str, lo: int, hi: int) -> int:
        if isinstance(value, float) or isinstance(value, (list, dict)):
            raise self.error(field_name, f"expected an integer, got {value!r}")
        try:
            return parse_int(value, field=field_name, lo=lo, hi=hi)
        except InputError as exc:
            raise InputError(f"{self.source}: {exc}") from None

    def flag(self, value, field_name: str) -> bool:
        if not isinstance(value, bool):
            raise self.error(field_name, f"expected true or false, got {value!r}")
        return value

    def byte_list(self, value, field_name: str, length: int) -> list[int]:
        if not isinstance(value, list) or len(value) != length:
            got = len(value) if isinstance(value, list) else type(value).__name__
            raise self.error(field_name, f"expected a list of {length} bytes, got {got}")
        return [self.number(v, f"{field_name}[{i}]", 0, 0xFF) for i, v in enumerate(value)]

    def file(self, value, field_name: str, what: str) -> Path:
        if not isinstance(value, str) or not value:
            raise self.error(field_name, f"expected a file name, got {value!r}")
        path = Path(value)
        if not path.is_absolute():
            path = Path(self.source).parent / path
        if is_dir(path):
            raise self.error(field_name, f"{what} {value!r} is a folder, not a file ({path})")
        if not is_file(path):
            raise self.error(field_name, f"{what} {value!r} not found (looked for {path})")
        return path


def register_offset(key: str, where: _Where) -> int:
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


def _sprite(entry, i: int, registers: bytearray, seen: set[int], where: _Where) -> SpriteSpec:
    name = f"sprite[{i}]"
    entry = where.table(entry, name, SPRITE_KEYS)
    if "index" not in entry:
        raise where.error(f"{name}.index", "missing (0-7)")
    n = where.number(entry["index"], f"{name}.index", 0, SPRITE_COUNT - 1)
    if n in seen:
        raise where.error(f"{name}.index", f"sprite {n} is declared twice")
    seen.add(n)
    bit = 1 << n
    if "x" in entry:
        x = where.number(entry["x"], f"{name}.x", 0, X_BITS_MASK)
        registers[REG_SPRITE_X0 + 2 * n] = x & 0xFF
        registers[REG_SPRITE_X_MSB] = (registers[REG_SPRITE_X_MSB] & ~bit) | (bit if x >> 8 else 0)
    if "y" in entry:
        registers[REG_SPRITE_Y0 + 2 * n] = where.number(entry["y"], f"{name}.y", 0, Y_COMPARE_MASK)
    flags = {"enabled": True, **{k: entry[k] for k in SPRITE_FLAGS if k in entry}}
    for key, value in flags.items():
        on = where.flag(value, f"{name}.{key}")
        register = SPRITE_FLAGS[key]
        registers[register] = (registers[register] & ~bit) | (bit if on else 0)
    if "color" in entry:
        registers[REG_SPRITE_COLOR0 + n] = where.number(entry["color"], f"{name}.color", 0, COLOR_MASK)
    velocity = (0, 0)
    if "velocity" in entry:
        value = entry["velocity"]
        if not isinstance(value, list) or len(value) != 2:
            raise where.error(f"{name}.velocity", "expected [dx, dy]: pixels added to X and Y every frame")
        velocity = tuple(where.number(v, f"{name}.velocity", -MAX_SPEED, MAX_SPEED) for v in value)
    multicolor = bool(registers[REG_SPRITE_MULTICOLOR] & bit)
    given = [k for k in ("data", "rows", "file") if k in entry]
    if len(given) != 1:
        raise where.error(name, f"give exactly one of data, rows, file (got {', '.join(given) or 'none'})")
    for key in ("frame", "palette"):
        if key in entry and given[0] != "file":
            raise where.error(f"{name}.{key}", "goes with file")
    kind = given[0]
    try:
        if kind == "data":
            data = parse_hex(entry["data"], field="data")
            source = "data"
        elif kind == "rows":
            data = parse_rows(entry["rows"], multicolor, field="rows")
            source = "rows"
        else:
            path = where.file(entry["file"], f"{name}.file", "sprite file")
            frame = where.number(entry.get("frame", 0), f"{name}.frame", 0, 1 << 16)
            # any sprite file, by content (retro/sprites.py); a PNG is read in this sprite's colours
            data = read_sprite(path, frame, multicolor, scene_colours(registers, n), entry.get("palette"))
            source = f"file {entry['file']}"
    except InputError as exc:
        message = str(exc)
        if message.startswith(f"{where.source}: "):
            raise
        if message.startswith(kind) or message.startswith("rows["):
            raise InputError(f"{where.source}: {name}.{message}") from None
        raise InputError(f"{where.source}: {name}: {message}") from None
    return SpriteSpec(n, data[:SPRITE_BYTES], source, velocity)


def _fill_cells(spec, name: str, where: _Where, hi: int, given: tuple | None) -> np.ndarray:
    """memory.screen / memory.color: `fill`, then a `file` (or the part a whole-file key gave), then `cells`."""
    spec = where.table(spec if spec is not None else {}, f"memory.{name}", FILL_KEYS)
    values = np.full(SCREEN_CELLS, where.number(spec.get("fill", 0), f"memory.{name}.fill", 0, hi), np.uint8)
    part = _part_file(spec, name, where, given)
    if part is not None:
        covered = part.covered if part.covered is not None else slice(None)
        values[covered] = part.values[covered]
    cells = spec.get("cells", [])
    if not isinstance(cells, list):
        raise where.error(f"memory.{name}.cells", "expected a list of {col, row, value} tables")
    for i, cell in enumerate(cells):
        field_name = f"memory.{name}.cells[{i}]"
        cell, index = _cell(cell, field_name, SCREEN_CELL_KEYS, where)
        values[index] = where.number(cell["value"], f"{field_name}.value", 0, hi)
    return values


def _part_file(table: dict, part: str, where: _Where, given: tuple | None):
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


def _whole_files(spec: dict, where: _Where) -> dict[str, tuple]:
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
        col = where.number(table.get("col", 0), f"memory.{key}.col", 0, MAX_MAP_CELL)
        row = where.number(table.get("row", 0), f"memory.{key}.row", 0, MAX_MAP_CELL)
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


def _cell(cell, field_name: str, keys, where: _Where) -> tuple[dict, int]:
    """A {col, row, ...} table with all its keys: (the table, the cell's index in the 40 x 25 screen)."""
    cell = where.table(cell, field_name, keys)
    for key in keys:
        if key not in cell:
            raise where.error(f"{field_name}.{key}", "missing")
    col = where.number(cell["col"], f"{field_name}.col", 0, TEXT_COLUMNS - 1)
    row = where.number(cell["row"], f"{field_name}.row", 0, TEXT_ROWS - 1)
    return cell, row * TEXT_COLUMNS + col


def _memory(doc, where: _Where) -> VicMemory:
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
            code = where.number(key, f"memory.charset.{key}", 0, 0xFF)
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
        cells = table.get("cells", [])
        if not isinstance(cells, list):
            raise where.error("memory.bitmap.cells", "expected a list of {col, row, bytes} tables")
        for i, cell in enumerate(cells):
            field_name = f"memory.bitmap.cells[{i}]"
            cell, index = _cell(cell, field_name, BITMAP_CELL_KEYS, where)
            start = index * CHAR_HEIGHT
            bitmap[start:start + CHAR_HEIGHT] = where.byte_list(cell["bytes"], f"{field_name}.bytes", CHAR_HEIGHT)
    idle = where.number(spec.get("idle", 0), "memory.idle", 0, 0xFF)
    return VicMemory(screen, color, charset, bitmap, idle)


def parse(doc: dict, source: str) -> VicScene:
    where = _Where(source)
    where.table(doc, "", TOP_KEYS)
    video = doc.get("video", "pal")
    if not isinstance(video, str) or video not in VIDEOS:
        raise where.error("video", f"expected \"pal\" (6569) or \"ntsc\" (6567R8), got {video!r}")
    registers = bytearray(REGISTER_COUNT)
    table = doc.get("registers", {})
    if not isinstance(table, dict):
        raise where.error("registers", "expected a table of \"$d0xx\" = value")
    spelled: dict[int, str] = {}  # offset -> the key that set it ("$d011" and "d011" are one register)
    for key, value in table.items():
        offset = register_offset(key, where)
        if earlier := earlier_spelling(spelled, offset, key):
            raise where.error(f"registers.{key}", f"the same register as {earlier!r}; give it once")
        registers[offset] = where.number(value, f"registers.{key}", 0, 0xFF)
    entries = doc.get("sprite", [])
    if not isinstance(entries, list):
        raise where.error("sprite", "expected [[sprite]] tables")
    seen: set[int] = set()
    specs = [_sprite(entry, i, registers, seen, where) for i, entry in enumerate(entries)]
    data = [bytes(SPRITE_BYTES)] * SPRITE_COUNT
    for spec in specs:
        data[spec.index] = spec.data
    memory = _memory(doc.get("memory", {}), where)
    state = VicState(VIDEOS[video], bytes(registers), tuple(data), memory)
    cpu = where.table(doc.get("cpu", {}), "cpu", CPU_KEYS)
    start_line = where.number(cpu.get("start_line", 0), "cpu.start_line", 0, VIDEOS[video].lines - 1)
    start_cycle = where.number(cpu.get("start_cycle", 1), "cpu.start_cycle", 1, VIDEOS[video].cycles_per_line)
    irq_vector = str(cpu.get("irq_vector", "$fffe")).lower()
    if irq_vector not in ("$fffe", "$0314"):
        raise where.error("cpu.irq_vector", f"expected \"$fffe\" or \"$0314\", got {cpu.get('irq_vector')!r}")
    return VicScene(source, video, bytes(registers), tuple(specs), memory, state, start_line=start_line,
                    start_cycle=start_cycle, irq_vector=irq_vector)


def load(path: str | Path) -> VicScene:
    """Read and validate a VIC-II scene file (the chip key must say "vic-ii")."""
    from retro.scenes import load_scene

    scene = load_scene(path)
    if not isinstance(scene, VicScene):
        raise InputError(f"{path}: chip: expected \"vic-ii\"")
    return scene
