"""Software pixel-perfect: AND each row of one sprite's opacity with the other's rows shifted by dx,
over the overlapping rows (exact). asm/pixel.s on the two 63-byte opacity masks."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Pair, Shape
from retro.analysis.study.fits import bit_rows
from retro.analysis.study.methods.base import Method


def opacity_bytes(shape: Shape) -> tuple[int, ...]:
    """The sprite's opacity as hires rows (what a software pixel test ANDs: for a multicolor sprite,
    a pair 01/10/11 becomes 11, so the 01 rim counts, as on the VIC-II). A smaller shape (an NES
    sprite, 8x8 or 8x16) sits in the top-left corner of the 24x21 rows, the rest transparent: the
    same pixels meet at every offset."""
    from retro.chips.vic.constants import SPRITE_HEIGHT, SPRITE_WIDTH
    from retro.sprites import encode

    rows = np.zeros((SPRITE_HEIGHT, SPRITE_WIDTH), dtype="uint8")
    rows[:shape.height, :shape.width] = shape.mask
    return tuple(encode(rows))


def pixel_grid(pair: Pair) -> np.ndarray:
    """[dy + hb - 1, dx + wb - 1]: the row-AND answer at every offset where the sprite boxes meet.
    Independent of corpus.overlap_counts (shifted integers, not a correlation)."""
    rows_a = np.array(bit_rows(pair.a.mask), dtype=object)
    rows_b = np.array(bit_rows(pair.b.mask), dtype=object)
    ha, hb, wa, wb = pair.a.height, pair.b.height, pair.a.width, pair.b.width
    out = np.zeros((ha + hb - 1, wa + wb - 1), dtype=bool)
    for col, dx in enumerate(range(-(wb - 1), wa)):
        # Line b up with a: b's column 0 moves to a's column dx (shift right means smaller bits).
        shift = (wa - wb) - dx
        shifted = rows_b << shift if shift >= 0 else rows_b >> -shift
        both = (rows_a[:, None] & shifted[None, :]) != 0  # [row of a, row of b]
        for row, dy in enumerate(range(-(hb - 1), ha)):
            out[row, col] = np.diagonal(both, offset=-dy).any()
    return out


@dataclass(frozen=True, kw_only=True)
class PixelMethod(Method):
    def x_extent(self, shape) -> tuple[int, int]:
        """Hits only where opaque pixels meet: the tight box's columns."""
        from retro.analysis.study.fits import tight_box

        x0, _, x1, _ = tight_box(shape.mask)
        return x0, x1

    def verdict(self, pair: Pair) -> np.ndarray:
        grid = pixel_grid(pair)
        row, col = pair.dy + pair.b.height - 1, pair.dx + pair.b.width - 1
        inside = (row >= 0) & (row < grid.shape[0]) & (col >= 0) & (col < grid.shape[1])
        out = np.zeros(pair.dx.shape, dtype=float)  # where the sprite boxes do not meet, no pixel does
        out[inside] = grid[row[inside], col[inside]]
        return out

    def unmeasurable(self, pair: Pair) -> str:
        from retro.chips.vic.constants import SPRITE_HEIGHT, SPRITE_WIDTH

        if any(s.height > SPRITE_HEIGHT or s.width > SPRITE_WIDTH for s in (pair.a, pair.b)):
            return "asm/pixel.s takes sprites of at most 24x21 pixels (not expanded ones)"
        return ""

    def case_maker(self, pair: Pair):
        masks = opacity_bytes(pair.a), opacity_bytes(pair.b)
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()
        # asm/pixel.toml: the offset as two's-complement bytes, and the two opacity masks
        return lambda i: dict(dx=dxs[i] & 0xFF, dy=dys[i] & 0xFF, mask_a=masks[0], mask_b=masks[1])

    def host_calls(self, pair: Pair, indices: list[int]):
        from retro.geometry.masks import mask_overlap

        return [lambda dx=int(pair.dx[i]), dy=int(pair.dy[i]): mask_overlap(pair.a.mask, pair.b.mask, (dx, dy))
                for i in indices]


PIXEL = PixelMethod(
    key="pixel", label="software pixel-perfect", colour="#d62728", marker="*", routine="pixel",
    rule="AND of the opacity rows over the overlapping rows (exact)",
    counted="asm/pixel.s: shift tables counted; the two 63-byte opacity masks are prepared once per sprite, "
            "not counted", origin=__name__)
