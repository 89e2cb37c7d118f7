"""Separating axis theorem (SAT) for convex polygons, with the minimum translation vector (MTV).

Two convex polygons are disjoint exactly when their projections onto some edge normal of either
polygon are disjoint. The candidate axes are the edge normals of a, then of b, in vertex order; the
test stops at the first separating axis. Projections use the *unnormalised* normals, so for integer
coordinates (below 2**26) the overlap decision is exact; only the reported depth is divided by the
normal's length.

Convention: touching counts as separated. Projections that only share an end point
(max_a == min_b) separate, so polygons meeting along an edge or at a vertex do not collide.

MTV: among all axes, the smallest push of a out of b. For convex polygons the penetration depth is
always attained along one of these edge normals (they are the edge normals of the Minkowski
difference), so this minimum is the true minimum over all directions. Ties keep the first axis in
the order above; on one axis, moving a along +normal wins a tie with -normal.
"""

from __future__ import annotations

import math

from retro.geometry.polygon import (
    Polygon,
    convex_decompose,
    convex_polygon,
    simple_polygon,
)
from retro.geometry.vectors import PointLike, as_nonzero_vector, as_points

Axis = tuple[float, float]


def _project(poly: Polygon, nx: float, ny: float) -> tuple[float, float]:
    values = [nx * x + ny * y for x, y in poly]
    return min(values), max(values)


def _sat_checked(a: Polygon, b: Polygon, want_mtv: bool) -> tuple[Axis, float] | None | bool:
    best_depth = math.inf
    best_axis: Axis = (0.0, 0.0)
    for poly in (a, b):
        n = len(poly)
        for i in range(n):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % n]
            nx, ny = y1 - y0, x0 - x1  # outward normal of a counter-clockwise edge
            a_lo, a_hi = _project(a, nx, ny)
            b_lo, b_hi = _project(b, nx, ny)
            if a_hi <= b_lo or b_hi <= a_lo:
                return None  # first separating axis found: stop
            if want_mtv:
                length = math.hypot(nx, ny)
                forward = (b_hi - a_lo) / length   # push a along +normal until a_lo == b_hi
                backward = (a_hi - b_lo) / length  # push a along -normal until a_hi == b_lo
                if forward < best_depth:
                    best_depth, best_axis = forward, (nx / length, ny / length)
                if backward < best_depth:
                    best_depth, best_axis = backward, (-nx / length, -ny / length)
    return (best_axis, best_depth) if want_mtv else True


def sat(a: object, b: object) -> tuple[Axis, float] | None:
    """None when the convex polygons a and b are separated (touching counts as separated), else
    (axis, depth): `axis` a unit vector and `depth` > 0 such that moving a by axis * depth is the
    smallest move that separates it from b (after the move they touch).

    Polygons are sequences of (x, y) vertices in either winding; a degenerate or non-convex
    polygon raises InputError naming it ("a" or "b") and the problem.
    """
    return _sat_checked(convex_polygon(a, "a"), convex_polygon(b, "b"), want_mtv=True)  # type: ignore[return-value]


def sat_overlap(a: object, b: object) -> bool:
    """True when the convex polygons' interiors intersect; stops at the first separating axis
    without computing the MTV."""
    return _sat_checked(convex_polygon(a, "a"), convex_polygon(b, "b"), want_mtv=False) is True


def _bounds(poly: Polygon) -> tuple[float, float, float, float]:
    xs = [p[0] for p in poly]
    ys = [p[1] for p in poly]
    return min(xs), min(ys), max(xs), max(ys)


def pieces_overlap(pieces_a: list[Polygon], pieces_b: list[Polygon]) -> bool:
    """True when some convex piece of a overlaps some convex piece of b (pieces as returned by
    `convex_decompose`, already counter-clockwise). Decompose once, test every frame."""
    boxes_b = [_bounds(q) for q in pieces_b]
    for p in pieces_a:
        ax0, ay0, ax1, ay1 = _bounds(p)
        for q, (bx0, by0, bx1, by1) in zip(pieces_b, boxes_b):
            if ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1 and _sat_checked(p, q, False):
                return True
    return False


def polygons_overlap(a: object, b: object) -> bool:
    """True when the interiors of two simple polygons (concave allowed) intersect; touching counts
    as separated. Each polygon is split into convex pieces and the pieces are tested with SAT:
    the interiors meet exactly when some pair of pieces has overlapping interiors."""
    return pieces_overlap(convex_decompose(simple_polygon(a, "a"), "a"), convex_decompose(simple_polygon(b, "b"), "b"))


def project_polygon(poly: object, axis: PointLike) -> tuple[float, float]:
    """(min, max) of the polygon's vertices projected onto `axis` (not normalised). For pictures."""
    ax, ay = as_nonzero_vector(axis, "axis")
    return _project([(float(x), float(y)) for x, y in as_points(poly, "poly")], ax, ay)
