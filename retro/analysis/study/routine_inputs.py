"""From a corpus case to a 6502 routine call: one adapter per method.

An adapter knows its source file and entry and what its cycle figure counts; its session turns case
`index` of a pair into the routine's logical case (the reference's argument order) and runs it
through a RoutineRunner on the routine's spec (asm/NAME.toml), which alone knows the calling conventions, returning
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


ORIGIN = 64  # shape a's sprite box sits at (64, 64): every coordinate of the corpus stays in 0..255


def _opacity_bytes(shape) -> bytes:
    """The sprite's opacity as hires rows (what a software pixel test ANDs: for a multicolor sprite,
    a pair 01/10/11 becomes 11, so the 01 rim counts, as on the VIC-II)."""
    from retro.sprites import encode

    return encode(shape.mask.astype("uint8"))


# ---- issue 5's routines (asm/), called through their specs ---------------------------------------
# Each spec (asm/NAME.toml) holds the routine's calling convention; the study only
# builds the logical case (the reference's argument order) and lets RoutineRunner pass it.


def routine_runner(name: str):
    """A loaded RoutineRunner for the built-in routine `name` (its spec in asm/)."""
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    return RoutineRunner(get(name))


class _Issue5Session(Session):
    def __init__(self, pair: Pair, adapter: "Issue5Adapter") -> None:
        from retro.analysis.study.methods import method

        self.pair = pair
        self.key = adapter.key
        self.masks = (tuple(_opacity_bytes(pair.a)), tuple(_opacity_bytes(pair.b))) if self.key == "pixel" else ()
        self.runner = routine_runner(adapter.routine)
        self.verdict = method(self.key).verdict(pair)

    def run(self, index: int) -> tuple[bool, bool, int]:
        from retro.analysis.study.fits import fitted_circle, full_box, tight_box
        from retro.analysis.study.methods import CIRCLE_TOUCHING_HITS

        pair, dx, dy = self.pair, int(self.pair.dx[index]), int(self.pair.dy[index])
        if self.key in ("box", "tight"):
            fit = full_box if self.key == "box" else tight_box
            ax0, ay0, ax1, ay1 = fit(pair.a.mask)
            bx0, by0, bx1, by1 = fit(pair.b.mask)
            case = (ORIGIN + ax0, ORIGIN + ay0, ax1 - ax0, ay1 - ay0,
                    ORIGIN + dx + bx0, ORIGIN + dy + by0, bx1 - bx0, by1 - by0)
        elif self.key == "circle":
            ca, cb = fitted_circle(pair.a.mask, CIRCLE_TOUCHING_HITS), fitted_circle(pair.b.mask, CIRCLE_TOUCHING_HITS)
            case = (ORIGIN + ca.cx, ORIGIN + ca.cy, ca.r, ORIGIN + dx + cb.cx, ORIGIN + dy + cb.cy, cb.r)
        else:  # pixel: the offset as two's-complement bytes, and the pair's opacity masks
            case = (dx & 0xFF, dy & 0xFF, *self.masks)
        (answer,), cycles = self.runner.run(case)
        return bool(answer), bool(self.verdict[index]), cycles


class _TileBoxSession(Session):
    """asm/tile_box.s: a's cells marked on the C64 screen (code 1, tile_props[1] = 1), b's tight box
    in sprite coordinates; hit when the OR of the touched cells' properties is non-zero. The 64 cell
    alignments are taken in turn over the sampled cases."""

    MARK = 1

    def __init__(self, pair: Pair, adapter: "Issue5Adapter") -> None:
        from retro.chips.vic import screen

        self.pair, self.screen = pair, screen
        props = [0] * 256
        props[self.MARK] = self.MARK
        self.runner = routine_runner(adapter.routine)
        self.runner.set_memory("screen", [0] * (screen.COLUMNS * screen.ROWS))
        self.runner.set_memory("props", props)
        self.marked: list[int] = []

    def run(self, index: int) -> tuple[bool, bool, int]:
        from retro.analysis.study.fits import tight_box

        s, pair = self.screen, self.pair
        dx, dy = int(pair.dx[index]), int(pair.dy[index])
        align = index % 64
        ox, oy = ORIGIN + align % 8, ORIGIN + align // 8  # pixel offsets from the screen's cell grid
        ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
        bx0, by0, bx1, by1 = tight_box(pair.b.mask)
        memory = self.runner.machine.memory
        for address in self.marked:
            memory[address] = 0
        a_cells = {(c, r) for r in range((oy + ay0) // s.CELL_PIXELS, (oy + ay1 - 1) // s.CELL_PIXELS + 1)
                   for c in range((ox + ax0) // s.CELL_PIXELS, (ox + ax1 - 1) // s.CELL_PIXELS + 1)}
        self.marked = [s.row_address(r) + c for c, r in a_cells]
        for address in self.marked:
            memory[address] = self.MARK
        x = s.SPRITE_X_AT_COLUMN_0 + ox + dx + bx0
        y = s.SPRITE_Y_AT_ROW_0 + oy + dy + by0
        (answer,), cycles = self.runner.run((x & 0xFF, x >> 8, y, bx1 - bx0, by1 - by0))
        b_cells = {(c, r) for r in range((oy + dy + by0) // s.CELL_PIXELS, (oy + dy + by1 - 1) // s.CELL_PIXELS + 1)
                   for c in range((ox + dx + bx0) // s.CELL_PIXELS, (ox + dx + bx1 - 1) // s.CELL_PIXELS + 1)}
        return answer != 0, bool(a_cells & b_cells), cycles


@dataclass(frozen=True)
class Issue5Adapter(Adapter):
    def size(self) -> tuple[int, int]:
        """(bytes of code, bytes of lookup tables), counted as `retro cycles` counts them."""
        size = routine_runner(self.routine).size()
        return size.code_bytes, size.table_bytes

    def session(self, pair: Pair) -> Session:
        return _TileBoxSession(pair, self) if self.key == "tile" else _Issue5Session(pair, self)


ADAPTERS: dict[str, Adapter] = {
    "box": Issue5Adapter("box", "aabb8.s", "aabb8", "asm/aabb8.s on the full 24x21 boxes"),
    "tight": Issue5Adapter("tight", "aabb8.s", "aabb8", "asm/aabb8.s on the tight hitboxes"),
    "circle": Issue5Adapter("circle", "circle.s", "circle", "asm/circle.s on the fitted circles (its tables counted)"),
    "tile": Issue5Adapter("tile", "tile_box.s", "tile_box", "asm/tile_box.s: b's tight box against the C64 screen "
                          "where a's cells are marked; the screen and property bytes are not counted"),
    "pixel": Issue5Adapter("pixel", "pixel.s", "pixel", "asm/pixel.s: shift tables counted; the two 63-byte opacity "
                           "masks are prepared once per sprite, not counted"),
    "latch": LatchAdapter("latch", "latch_test.s", "latch_test",
                          "one LDA $D01E (read and clear) with the copy kept for other pairs, and the test of one "
                          "pair's two bits; once per frame, not per pair of objects"),
}
