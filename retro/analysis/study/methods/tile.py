"""Tile cells: tight hitboxes quantised to the 8x8 cells of a C64 text screen / NES tile map.

The rule: hit when the cells one tight box touches meet the cells the other touches (what
asm/tile_box.s reports for b's box on a map where a's cells are marked). The answer depends on where
the pair sits on the cell grid, so the verdict is averaged over the 64 alignments; x and y
alignments are independent and uniform, so the average is the product of the per-axis averages.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import tight_box
from retro.analysis.study.methods.base import ORIGIN, Method, Session, routine_runner

CELL = 8  # a C64 text cell / NES tile is 8x8 pixels
ALIGNMENTS = CELL * CELL
PAD_LEFT, PAD_RIGHT = CELL // 2 - 1, CELL // 2  # x_extent: CELL - 1 pixels in all


def cell_overlap_fraction(a0: int, a1: int, b0: int, b1: int, d: np.ndarray) -> np.ndarray:
    """On one axis: the fraction of the CELL alignments of the pair in which the cells touched by
    [a0, a1) and by [b0 + d, b1 + d) share a cell (pixel ranges half-open)."""
    hits = np.zeros(d.shape, dtype=float)
    for align in range(CELL):
        a_first, a_last = (align + a0) // CELL, (align + a1 - 1) // CELL
        b_first, b_last = (align + b0 + d) // CELL, (align + b1 - 1 + d) // CELL
        hits += (a_first <= b_last) & (b_first <= a_last)
    return hits / CELL


def _cells(x0: int, y0: int, x1: int, y1: int) -> set[tuple[int, int]]:
    return {(c, r) for r in range(y0 // CELL, (y1 - 1) // CELL + 1) for c in range(x0 // CELL, (x1 - 1) // CELL + 1)}


class TileSession(Session):
    """asm/tile_box.s: a's cells marked on the C64 screen (code 1, tile_props[1] = 1), b's tight box
    in sprite coordinates; hit when the OR of the touched cells' properties is non-zero. The 64 cell
    alignments are taken in turn over the measured cases (case index mod 64)."""

    MARK = 1

    def __init__(self, method: "TileMethod", pair: Pair) -> None:
        from retro.chips.vic import screen

        self.pair, self.screen = pair, screen
        props = [0] * 256
        props[self.MARK] = self.MARK
        self.runner = routine_runner(method.routine)
        self.runner.set_memory("screen", [0] * (screen.COLUMNS * screen.ROWS))
        self.runner.set_memory("props", props)
        self.marked: list[int] = []
        self.a_box, self.b_box = tight_box(pair.a.mask), tight_box(pair.b.mask)

    def _placed(self, index: int) -> tuple[int, int, int, int]:
        align = index % ALIGNMENTS
        ox, oy = ORIGIN + align % CELL, ORIGIN + align // CELL  # pixel offsets from the screen's cell grid
        return ox, oy, int(self.pair.dx[index]), int(self.pair.dy[index])

    def run(self, index: int) -> tuple[bool, int]:
        s = self.screen
        ox, oy, dx, dy = self._placed(index)
        ax0, ay0, ax1, ay1 = self.a_box
        bx0, by0, bx1, by1 = self.b_box
        memory = self.runner.machine.memory
        for address in self.marked:
            memory[address] = 0
        self.marked = [s.row_address(r) + c for c, r in _cells(ox + ax0, oy + ay0, ox + ax1, oy + ay1)]
        for address in self.marked:
            memory[address] = self.MARK
        x = s.SPRITE_X_AT_COLUMN_0 + ox + dx + bx0
        y = s.SPRITE_Y_AT_ROW_0 + oy + dy + by0
        case = dict(x=x & 0xFF, xh=x >> 8, y=y, w=bx1 - bx0, h=by1 - by0)  # asm/tile_box.toml
        (answer,), cycles = self.runner.run(tuple(case[name] for name in self.runner.routine.input_names))
        return answer != 0, cycles

    def expected(self, index: int) -> bool:
        """The rule at this case's one alignment (the verdict is the average over all 64)."""
        ox, oy, dx, dy = self._placed(index)
        ax0, ay0, ax1, ay1 = self.a_box
        bx0, by0, bx1, by1 = self.b_box
        return bool(_cells(ox + ax0, oy + ay0, ox + ax1, oy + ay1)
                    & _cells(ox + dx + bx0, oy + dy + by0, ox + dx + bx1, oy + dy + by1))


@dataclass(frozen=True, kw_only=True)
class TileMethod(Method):
    def verdict(self, pair: Pair) -> np.ndarray:
        ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
        bx0, by0, bx1, by1 = tight_box(pair.b.mask)
        return cell_overlap_fraction(ax0, ax1, bx0, bx1, pair.dx) * cell_overlap_fraction(ay0, ay1, by0, by1, pair.dy)

    def session(self, pair: Pair) -> Session:
        return TileSession(self, pair)

    def x_extent(self, shape) -> tuple[int, int]:
        """The tight box grown by PAD_LEFT + PAD_RIGHT = CELL - 1 pixels: boxes whose columns are
        CELL apart (b's left at least a's last column + CELL) never share a cell, at any alignment."""
        x0, _, x1, _ = tight_box(shape.mask)
        return x0 - PAD_LEFT, x1 + PAD_RIGHT

    def host_calls(self, pair: Pair, indices: list[int]):
        ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
        bx0, by0, bx1, by1 = tight_box(pair.b.mask)

        def cells_meet(dx: int, dy: int) -> bool:
            return (ax0 // CELL <= (bx1 - 1 + dx) // CELL and (bx0 + dx) // CELL <= (ax1 - 1) // CELL
                    and ay0 // CELL <= (by1 - 1 + dy) // CELL and (by0 + dy) // CELL <= (ay1 - 1) // CELL)
        return [lambda dx=int(pair.dx[i]), dy=int(pair.dy[i]): cells_meet(dx, dy) for i in indices]


TILE = TileMethod(
    key="tile", label="tile cells (8x8)", colour="#8c564b", marker="P", routine="tile_box", averaged=True,
    rule="the 8x8 cells touched by the two tight hitboxes meet; averaged over the 64 grid alignments",
    counted="asm/tile_box.s: b's tight box against the C64 screen where a's cells are marked; the screen and "
            "property bytes are not counted", origin=__name__)
