"""The collision methods of the study and their verdicts on every case of a pair at once.

A verdict is a float array with one value per case of the pair (see corpus.Pair): 1.0 when the
method reports a collision, 0.0 when it does not; the tile method, which depends on where the pair
sits on the 8x8 cell grid, reports the fraction of the 64 grid alignments in which it says "hit".

Each method answers as the project's 6502 routine (or the chip) would on the same inputs: the
same edge convention, the same integer parameters. The costs of those routines are in costs.py.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import (
    Box,
    bit_rows,
    fitted_circle,
    full_box,
    pixel_hull,
    tight_box,
)

CELL = 8  # a C64 text cell / NES tile is 8x8 pixels: the grid of the tile method


@dataclass(frozen=True)
class Method:
    key: str
    label: str
    verdict: Callable[[Pair], np.ndarray]
    rule: str  # what exactly is tested, one sentence for the docs and the CSV
    host_only: bool = False  # no 6502 routine: cycles are not measured (SAT)


def _box_overlap(a: Box, b: Box, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Half-open boxes a (at the origin) and b (moved by dx, dy) share a pixel."""
    ax0, ay0, ax1, ay1 = a
    bx0, by0, bx1, by1 = b
    return (ax0 < bx1 + dx) & (bx0 + dx < ax1) & (ay0 < by1 + dy) & (by0 + dy < ay1)


def full_box_verdict(pair: Pair) -> np.ndarray:
    return _box_overlap(full_box(pair.a.mask), full_box(pair.b.mask), pair.dx, pair.dy).astype(float)


def tight_box_verdict(pair: Pair) -> np.ndarray:
    return _box_overlap(tight_box(pair.a.mask), tight_box(pair.b.mask), pair.dx, pair.dy).astype(float)


# The circle routine's edge convention: set from the routine's reference when it is known (costs.py
# checks it against retro.routines.reference); False means tangent circles do not collide.
CIRCLE_TOUCHING_HITS = False


def circle_verdict(pair: Pair) -> np.ndarray:
    ca = fitted_circle(pair.a.mask, CIRCLE_TOUCHING_HITS)
    cb = fitted_circle(pair.b.mask, CIRCLE_TOUCHING_HITS)
    ddx = cb.cx + pair.dx - ca.cx
    ddy = cb.cy + pair.dy - ca.cy
    d2 = ddx * ddx + ddy * ddy
    reach = (ca.r + cb.r) ** 2
    hit = d2 <= reach if CIRCLE_TOUCHING_HITS else d2 < reach
    return hit.astype(float)


def _cell_overlap_fraction(a0: int, a1: int, b0: int, b1: int, d: np.ndarray) -> np.ndarray:
    """On one axis: the fraction of the CELL alignments of the pair in which the cells touched by
    [a0, a1) and by [b0 + d, b1 + d) share a cell (pixel ranges half-open)."""
    hits = np.zeros(d.shape, dtype=float)
    for align in range(CELL):
        a_first, a_last = (align + a0) // CELL, (align + a1 - 1) // CELL
        b_first, b_last = (align + b0 + d) // CELL, (align + b1 - 1 + d) // CELL
        hits += (a_first <= b_last) & (b_first <= a_last)
    return hits / CELL


def tile_verdict(pair: Pair) -> np.ndarray:
    """Tight hitboxes quantised to 8x8 cells: hit when the cells one box touches meet the cells the
    other touches (what tile_box reports for b's box on a map where a's cells are marked). Averaged
    over the 64 positions of the pair on the cell grid; x and y alignments are independent and
    uniform, so the average is the product of the per-axis averages."""
    ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
    bx0, by0, bx1, by1 = tight_box(pair.b.mask)
    return _cell_overlap_fraction(ax0, ax1, bx0, bx1, pair.dx) * _cell_overlap_fraction(ay0, ay1, by0, by1, pair.dy)


def pixel_verdict(pair: Pair) -> np.ndarray:
    """Software pixel-perfect, the way the 6502 routine does it: AND each row of a with the row of b
    shifted by dx, over the overlapping rows only. Independent of corpus.overlap_counts."""
    rows_a = np.array(bit_rows(pair.a.mask), dtype=object)
    rows_b = np.array(bit_rows(pair.b.mask), dtype=object)
    ha, hb, wa, wb = pair.a.height, pair.b.height, pair.a.width, pair.b.width
    out = np.zeros((ha + hb - 1, wa + wb - 1), dtype=float)
    for col, dx in enumerate(range(-(wb - 1), wa)):
        # Line b up with a: b's column 0 moves to a's column dx (shift right means smaller bits).
        shift = (wa - wb) - dx
        shifted = rows_b << shift if shift >= 0 else rows_b >> -shift
        both = (rows_a[:, None] & shifted[None, :]) != 0  # [row of a, row of b]
        for row, dy in enumerate(range(-(hb - 1), ha)):
            out[row, col] = np.diagonal(both, offset=-dy).any()
    return out.ravel()


def latch_verdict(pair: Pair) -> np.ndarray:
    """The VIC-II's $D01E after one frame with the two sprites placed at the offset (see latch.py)."""
    from retro.analysis.study.latch import latch_verdicts

    return latch_verdicts(pair)


def hull_sat_verdict(pair: Pair) -> np.ndarray:
    """retro.geometry.sat on the convex hulls of the opaque pixels (touching counts as separated)."""
    from retro.geometry.sat import sat

    hull_a = pixel_hull(pair.a.mask)
    hull_b = pixel_hull(pair.b.mask)
    out = np.empty(pair.cases, dtype=float)
    for i, (dx, dy) in enumerate(zip(pair.dx.tolist(), pair.dy.tolist())):
        out[i] = sat(hull_a, [(x + dx, y + dy) for x, y in hull_b]) is not None
    return out


METHODS: tuple[Method, ...] = (
    Method("box", "sprite box AABB", full_box_verdict,
           "the full 24x21 sprite boxes overlap (half-open: touching boxes do not)"),
    Method("tight", "tight hitbox AABB", tight_box_verdict,
           "the bounding boxes of the opaque pixels overlap (half-open)"),
    Method("circle", "fitted circle", circle_verdict,
           "integer circles enclosing the opaque pixels: squared centre distance against (r1+r2)^2"),
    Method("tile", "tile cells (8x8)", tile_verdict,
           "the 8x8 cells touched by the two tight hitboxes meet; averaged over the 64 grid alignments"),
    Method("pixel", "software pixel-perfect", pixel_verdict,
           "AND of the opacity rows over the overlapping rows (exact)"),
    Method("latch", "VIC-II latch $D01E", latch_verdict,
           "both sprites' bits set in $D01E after the frame (exact pixels, but not which pair or when)"),
    Method("sat", "SAT on convex hull", hull_sat_verdict,
           "retro.geometry.sat on the convex hulls of the opaque pixel squares", host_only=True),
)
METHOD_KEYS = tuple(m.key for m in METHODS)


def method(key: str) -> Method:
    for m in METHODS:
        if m.key == key:
            return m
    raise KeyError(key)
