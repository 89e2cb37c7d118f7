"""From a corpus case to a 6502 routine call: one adapter per method, following the calling
conventions written in each routine's asm/ header (and retro/routines.py).

An adapter knows its source file and entry, what its cycle figure counts, and how to turn case
`index` of a pair into memory/register inputs; its session runs the call and returns
(routine's answer, the study's verdict for that case, cycles).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from retro.analysis.study.corpus import Pair
from retro.paths import ASM_DIR


@lru_cache(maxsize=None)
def _program(source: str):
    from retro.assembler import assemble_file

    return assemble_file(ASM_DIR / source)


class Session:
    def run(self, index: int) -> tuple[bool, bool, int]:
        raise NotImplementedError


@dataclass(frozen=True)
class Adapter:
    key: str
    source: str  # file under asm/
    routine: str  # entry label
    counted: str

    def available(self) -> bool:
        try:
            return self.routine in _program(self.source).symbols
        except Exception:  # missing file or a source still being written: reported as not measured
            return False

    def missing(self) -> str:
        return f"not measured: entry {self.routine!r} not found in asm/{self.source}"

    def size(self) -> tuple[int, int]:
        """(bytes of code, bytes of tables) of the routine's program."""
        program = _program(self.source)
        return len(program.code), 0

    def session(self, pair: Pair) -> Session:
        raise NotImplementedError


# ---- the hardware latch --------------------------------------------------------------------------

class _LatchSession(Session):
    def __init__(self, pair: Pair) -> None:
        from retro.analysis.study.latch import latch_machine, latch_verdicts

        self.pair = pair
        self.verdict = latch_verdicts(pair) > 0
        self.machine, self.prepare = latch_machine(_program("latch_test.s"))

    def run(self, index: int) -> tuple[bool, bool, int]:
        self.prepare(self.pair, index)
        result = self.machine.call("latch_test", memory={"latch_bits": [0b11]})
        return bool(result.flags["C"]), bool(self.verdict[index]), result.cycles


@dataclass(frozen=True)
class LatchAdapter(Adapter):
    def session(self, pair: Pair) -> Session:
        return _LatchSession(pair)


# ---- the fallback routines (fallback_asm.py) until issue 5's routines exist ----------------------

ORIGIN = 64  # shape a's sprite box sits at (64, 64): every coordinate of the corpus stays in 0..255


class _FallbackSession(Session):
    def __init__(self, pair: Pair, key: str) -> None:
        from retro.analysis.study import fallback_asm
        from retro.analysis.study.methods import method
        from retro.cpu import Machine

        self.pair = pair
        self.key = key
        self.machine = Machine()
        self.machine.load(fallback_asm.program())
        self.verdict = method(key).verdict(pair) if key != "tile" else None
        self.marked: list[int] = []
        if key == "pixel":
            self.machine.poke(fallback_asm.SPRITE_A, list(_opacity_bytes(pair.a)))
            self.machine.poke(fallback_asm.SPRITE_B, list(_opacity_bytes(pair.b)))

    def run(self, index: int) -> tuple[bool, bool, int]:
        from retro.analysis.study import fallback_asm as fb
        from retro.analysis.study.fits import fitted_circle, full_box, tight_box
        from retro.analysis.study.methods import CIRCLE_TOUCHING_HITS

        pair, dx, dy = self.pair, int(self.pair.dx[index]), int(self.pair.dy[index])
        if self.key in ("box", "tight"):
            fit = full_box if self.key == "box" else tight_box
            ax0, ay0, ax1, ay1 = fit(pair.a.mask)
            bx0, by0, bx1, by1 = fit(pair.b.mask)
            values = [ORIGIN + ax0, ORIGIN + ay0, ax1 - ax0, ay1 - ay0,
                      ORIGIN + dx + bx0, ORIGIN + dy + by0, bx1 - bx0, by1 - by0]
            result = self.machine.call("sf_aabb8", memory={0x10: values})
            expected = bool(self.verdict[index])
        elif self.key == "circle":
            ca, cb = fitted_circle(pair.a.mask, CIRCLE_TOUCHING_HITS), fitted_circle(pair.b.mask, CIRCLE_TOUCHING_HITS)
            values = [ORIGIN + ca.cx, ORIGIN + ca.cy, ORIGIN + dx + cb.cx, ORIGIN + dy + cb.cy, ca.r + cb.r]
            result = self.machine.call("sf_circle", memory={0x10: values})
            expected = bool(self.verdict[index])
        elif self.key == "tile":
            align = index % 64  # the 64 cell alignments taken in turn over the sampled cases
            ox, oy = ORIGIN + align % 8, ORIGIN + align // 8
            ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
            bx0, by0, bx1, by1 = tight_box(pair.b.mask)
            for address in self.marked:
                self.machine.poke(address, 0)
            self.marked = [fb.MAP + row * fb.MAP_COLUMNS + col
                           for row in range((oy + ay0) // 8, (oy + ay1 - 1) // 8 + 1)
                           for col in range((ox + ax0) // 8, (ox + ax1 - 1) // 8 + 1)]
            for address in self.marked:
                self.machine.poke(address, 1)
            box = [ox + dx + bx0, oy + dy + by0, ox + dx + bx1 - 1, oy + dy + by1 - 1]
            result = self.machine.call("sf_tile_box", memory={0x10: box})
            b_cells = {(r, c) for r in range(box[1] // 8, box[3] // 8 + 1) for c in range(box[0] // 8, box[2] // 8 + 1)}
            a_cells = {((a - fb.MAP) // fb.MAP_COLUMNS, (a - fb.MAP) % fb.MAP_COLUMNS) for a in self.marked}
            expected = bool(a_cells & b_cells)
        else:  # pixel
            pointers = [fb.SPRITE_A & 0xFF, fb.SPRITE_A >> 8, fb.SPRITE_B & 0xFF, fb.SPRITE_B >> 8, dx & 0xFF, dy & 0xFF]
            result = self.machine.call("sf_pixel", memory={0x20: pointers})
            expected = bool(self.verdict[index])
        return bool(result.flags["C"]), expected, result.cycles


def _opacity_bytes(shape) -> bytes:
    """The sprite's opacity as hires rows (what a software pixel test ANDs: for a multicolor sprite,
    a pair 01/10/11 becomes 11, so the 01 rim counts, as on the VIC-II)."""
    from retro.sprites import encode

    return encode(shape.mask.astype("uint8"))


@dataclass(frozen=True)
class FallbackAdapter(Adapter):
    def available(self) -> bool:
        return True

    def size(self) -> tuple[int, int]:
        from retro.analysis.study import fallback_asm

        return fallback_asm.code_bytes(self.routine), fallback_asm.TABLE_BYTES if self.key == "circle" else 0

    def session(self, pair: Pair) -> Session:
        return _FallbackSession(pair, self.key)


# ---- issue 5's routines (asm/), preferred whenever they assemble ---------------------------------

DATA_BUFFERS = ("pixel_mask_a", "pixel_mask_b")  # filled by the caller: data, not tables


def _split_sizes(source: str) -> tuple[int, int]:
    """(code bytes, table bytes) of an asm/ program: code runs from the origin to the first
    generated table (Ophis's zero padding before the page-aligned table stripped); tables are the
    generated ones, the caller-filled mask buffers excluded."""
    from retro import tables
    from retro.assembler import requested_tables
    from retro.fileio import read_text

    program = _program(source)
    names = requested_tables(read_text(ASM_DIR / source))
    storage = getattr(tables, "STORAGE_TABLES", frozenset(DATA_BUFFERS))
    starts = [program.symbols[n] for n in names if n in program.symbols]
    end = (min(starts) if starts else program.origin + len(program.code)) - program.origin
    code = program.code[:end].rstrip(b"\0")
    table_bytes = sum(len(tables.GENERATORS[n]()) for n in names if n not in storage)
    return len(code), table_bytes


class _Issue5Session(Session):
    def __init__(self, pair: Pair, adapter: "Issue5Adapter") -> None:
        from retro.analysis.study.methods import method
        from retro.cpu import Machine

        self.pair = pair
        self.adapter = adapter
        self.machine = Machine()
        self.machine.load(_program(adapter.source))
        self.verdict = method(adapter.key).verdict(pair)
        if adapter.key == "pixel":
            self.machine.poke("pixel_mask_a", list(_opacity_bytes(pair.a)))
            self.machine.poke("pixel_mask_b", list(_opacity_bytes(pair.b)))

    def run(self, index: int) -> tuple[bool, bool, int]:
        from retro.analysis.study.fits import fitted_circle, full_box, tight_box
        from retro.analysis.study.methods import CIRCLE_TOUCHING_HITS

        pair, dx, dy = self.pair, int(self.pair.dx[index]), int(self.pair.dy[index])
        key = self.adapter.key
        if key in ("box", "tight"):
            fit = full_box if key == "box" else tight_box
            ax0, ay0, ax1, ay1 = fit(pair.a.mask)
            bx0, by0, bx1, by1 = fit(pair.b.mask)
            memory = {0x10: [ORIGIN + ax0, ORIGIN + ay0, ax1 - ax0, ay1 - ay0,
                             ORIGIN + dx + bx0, ORIGIN + dy + by0, bx1 - bx0, by1 - by0]}
        elif key == "circle":
            ca, cb = fitted_circle(pair.a.mask, CIRCLE_TOUCHING_HITS), fitted_circle(pair.b.mask, CIRCLE_TOUCHING_HITS)
            memory = {0x10: [ORIGIN + ca.cx, ORIGIN + ca.cy, ca.r, ORIGIN + dx + cb.cx, ORIGIN + dy + cb.cy, cb.r]}
        else:  # pixel
            memory = {0x10: [dx & 0xFF, dy & 0xFF]}
        result = self.machine.call(self.adapter.routine, memory=memory)
        return bool(result.flags["C"]), bool(self.verdict[index]), result.cycles


class _TileBoxSession(Session):
    """asm/tile_box.s: a's cells marked on the C64 screen (code 1, tile_props[1] = 1), b's tight box
    in sprite coordinates; hit when the OR of the touched cells' properties is non-zero. The 64 cell
    alignments are taken in turn over the sampled cases, as for the fallback."""

    MARK = 1

    def __init__(self, pair: Pair, adapter: "Issue5Adapter") -> None:
        from retro.cpu import Machine
        from retro.routines import screen

        self.pair, self.adapter, self.screen = pair, adapter, screen
        self.machine = Machine()
        self.machine.load(_program(adapter.source))
        self.machine.poke(self.machine.resolve("tile_props") + self.MARK, self.MARK)
        self.marked: list[int] = []

    def run(self, index: int) -> tuple[bool, bool, int]:
        from retro.analysis.study.fits import tight_box

        s, pair = self.screen, self.pair
        dx, dy = int(pair.dx[index]), int(pair.dy[index])
        align = index % 64
        ox, oy = ORIGIN + align % 8, ORIGIN + align // 8  # pixel offsets from the screen's cell grid
        ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
        bx0, by0, bx1, by1 = tight_box(pair.b.mask)
        for address in self.marked:
            self.machine.poke(address, 0)
        a_cells = {(c, r) for r in range((oy + ay0) // s.CELL_PIXELS, (oy + ay1 - 1) // s.CELL_PIXELS + 1)
                   for c in range((ox + ax0) // s.CELL_PIXELS, (ox + ax1 - 1) // s.CELL_PIXELS + 1)}
        self.marked = [s.row_address(r) + c for c, r in a_cells]
        for address in self.marked:
            self.machine.poke(address, self.MARK)
        x = s.SPRITE_X_AT_COLUMN_0 + ox + dx + bx0
        y = s.SPRITE_Y_AT_ROW_0 + oy + dy + by0
        result = self.machine.call(self.adapter.routine,
                                   memory={0x10: [x & 0xFF, x >> 8, y, bx1 - bx0, by1 - by0]})
        b_cells = {(c, r) for r in range((oy + dy + by0) // s.CELL_PIXELS, (oy + dy + by1 - 1) // s.CELL_PIXELS + 1)
                   for c in range((ox + dx + bx0) // s.CELL_PIXELS, (ox + dx + bx1 - 1) // s.CELL_PIXELS + 1)}
        return result.a != 0, bool(a_cells & b_cells), result.cycles


@dataclass(frozen=True)
class Issue5Adapter(Adapter):
    fallback: Adapter | None = None

    def size(self) -> tuple[int, int]:
        return _split_sizes(self.source)

    def session(self, pair: Pair) -> Session:
        return _TileBoxSession(pair, self) if self.key == "tile" else _Issue5Session(pair, self)


def _prefer(adapter: Issue5Adapter) -> Adapter:
    """Issue 5's routine when it assembles and has its entry, else the study's fallback."""
    return adapter if adapter.available() else adapter.fallback


_FALLBACK_NOTE = "FALLBACK routine (retro/analysis/study/fallback_asm.py, issue 5's routines absent): "

ADAPTERS: dict[str, Adapter] = {
    "box": _prefer(Issue5Adapter("box", "aabb8.s", "aabb8", "asm/aabb8.s on the full 24x21 boxes",
                                 FallbackAdapter("box", "", "sf_aabb8",
                                                 _FALLBACK_NOTE + "8-bit box test on the full 24x21 boxes"))),
    "tight": _prefer(Issue5Adapter("tight", "aabb8.s", "aabb8", "asm/aabb8.s on the tight hitboxes",
                                   FallbackAdapter("tight", "", "sf_aabb8",
                                                   _FALLBACK_NOTE + "8-bit box test on the tight hitboxes"))),
    "circle": _prefer(Issue5Adapter("circle", "circle.s", "circle", "asm/circle.s on the fitted circles (its tables "
                                    "counted)", FallbackAdapter("circle", "", "sf_circle", _FALLBACK_NOTE +
                                                                "squared distance by square table (512 bytes) "
                                                                "against (r1+r2)^2"))),
    "tile": _prefer(Issue5Adapter("tile", "tile_box.s", "tile_box", "asm/tile_box.s: b's tight box against the "
                                  "C64 screen where a's cells are marked; the screen and property bytes are not "
                                  "counted", FallbackAdapter("tile", "", "sf_tile_box", _FALLBACK_NOTE +
                                                             "b's tight box against a cell map where a's cells are "
                                                             "marked; the map is not counted"))),
    "pixel": _prefer(Issue5Adapter("pixel", "pixel.s", "pixel", "asm/pixel.s: shift tables counted; the two "
                                   "63-byte opacity masks are prepared once per sprite, not counted",
                                   FallbackAdapter("pixel", "", "sf_pixel", _FALLBACK_NOTE + "AND of shifted rows, "
                                                   "early exit; the opacity rows are prepared once per sprite, "
                                                   "not counted"))),
    "latch": LatchAdapter("latch", "latch_test.s", "latch_test",
                          "one LDA $D01E (read and clear) with the copy kept for other pairs, and the test of one "
                          "pair's two bits; once per frame, not per pair of objects"),
}
