"""SAT on the convex hulls of the opaque pixel squares (retro.geometry's convention: touching counts
as separated). Host only: no 6502 routine.

The verdict is the separating-axis test of retro.geometry.sat, done for every offset of a pair at
once: each hull is validated once per pair, and the candidate axes (the hulls' edge normals) do not
change when b moves, so b's projection on an axis n at offset d is its projection at the origin
plus n . d. Integer coordinates keep the decision exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import pixel_hull
from retro.analysis.study.methods.base import Method


def _normals(poly: np.ndarray) -> np.ndarray:
    """[edge, (nx, ny)]: a normal of every edge of the polygon (vertices in order)."""
    nxt = np.roll(poly, -1, axis=0)
    return np.stack([nxt[:, 1] - poly[:, 1], poly[:, 0] - nxt[:, 0]], axis=1)


def hulls_overlap(hull_a, hull_b, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """For every offset (dx, dy) of hull b: do the convex polygons' interiors meet? Both hulls are
    validated here, once."""
    from retro.geometry.polygon import convex_polygon

    a = np.array(convex_polygon(hull_a, "a"), dtype=np.int64)
    b = np.array(convex_polygon(hull_b, "b"), dtype=np.int64)
    normals = np.concatenate([_normals(a), _normals(b)])  # [axis, 2]
    pa, pb = a @ normals.T, b @ normals.T  # [vertex, axis]
    a_lo, a_hi, b_lo, b_hi = pa.min(0), pa.max(0), pb.min(0), pb.max(0)
    shift = np.outer(dx, normals[:, 0]) + np.outer(dy, normals[:, 1])  # [case, axis]
    separated = (a_hi <= b_lo + shift) | (b_hi + shift <= a_lo)
    return ~separated.any(axis=1)


@dataclass(frozen=True, kw_only=True)
class SatMethod(Method):
    def x_extent(self, shape) -> tuple[int, int]:
        """Hits only where opaque pixels meet: the tight box's columns."""
        from retro.analysis.study.fits import tight_box

        x0, _, x1, _ = tight_box(shape.mask)
        return x0, x1

    def verdict(self, pair: Pair) -> np.ndarray:
        return hulls_overlap(pixel_hull(pair.a.mask), pixel_hull(pair.b.mask), pair.dx, pair.dy).astype(float)

    def host_calls(self, pair: Pair, indices: list[int]):
        from retro.geometry.sat import sat

        hull_a, hull_b = pixel_hull(pair.a.mask), pixel_hull(pair.b.mask)
        return [lambda dx=int(pair.dx[i]), dy=int(pair.dy[i]): sat(hull_a, [(x + dx, y + dy) for x, y in hull_b])
                for i in indices]


SAT = SatMethod(
    key="sat", label="SAT on convex hull", colour="#9467bd", marker="X",
    rule="retro.geometry.sat on the convex hulls of the opaque pixel squares (touching counts as separated)",
    counted="host-only: no 6502 routine exists for it", origin=__name__)
