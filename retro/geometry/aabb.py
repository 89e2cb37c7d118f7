"""Axis-aligned bounding boxes in both common forms: min/max corners and centre/half-size.

Edge convention (the same for every shape in retro.geometry): two boxes overlap only when their
*interiors* intersect, i.e. with strict inequalities. Boxes that merely touch along an edge or at
a corner do NOT overlap. For pixel sprites this is exactly the usual half-open rule: a sprite at x
with width w covers pixels x .. x+w-1, so pass `max = x + w` and touching (adjacent) sprites do
not overlap while sprites sharing a pixel column do.

Integers stay integers, so every test here is exact on pixel coordinates.
"""

from __future__ import annotations

from retro.errors import InputError
from retro.geometry.vectors import Number, Point, PointLike, as_point

Box = tuple[Point, Point]


def as_box(box_min: PointLike, box_max: PointLike, name: str = "box") -> Box:
    """Checked (min, max) corners: finite and min <= max on both axes (zero size is allowed)."""
    lo = as_point(box_min, f"{name}_min")
    hi = as_point(box_max, f"{name}_max")
    for axis, a, b in (("x", lo[0], hi[0]), ("y", lo[1], hi[1])):
        if a > b:
            raise InputError(f"{name}: min.{axis} {a} is greater than max.{axis} {b}")
    return lo, hi


def aabb_from_center(center: PointLike, half_size: PointLike) -> Box:
    """(min, max) corners of the box with the given centre and half-extents (half-size >= 0)."""
    cx, cy = as_point(center, "center")
    hx, hy = as_point(half_size, "half_size")
    if hx < 0 or hy < 0:
        raise InputError(f"half_size: must be >= 0, got ({hx}, {hy})")
    return (cx - hx, cy - hy), (cx + hx, cy + hy)


def aabb_to_center(box_min: PointLike, box_max: PointLike) -> tuple[tuple[float, float], tuple[float, float]]:
    """(centre, half-size) of a box given by its corners."""
    (x0, y0), (x1, y1) = as_box(box_min, box_max)
    return ((x0 + x1) / 2, (y0 + y1) / 2), ((x1 - x0) / 2, (y1 - y0) / 2)


def aabb_overlap(a_min: PointLike, a_max: PointLike, b_min: PointLike, b_max: PointLike) -> bool:
    """True when the interiors of boxes a and b intersect; touching boxes do not overlap."""
    (ax0, ay0), (ax1, ay1) = as_box(a_min, a_max, "a")
    (bx0, by0), (bx1, by1) = as_box(b_min, b_max, "b")
    return ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1


def aabb_overlap_centered(a_center: PointLike, a_half: PointLike, b_center: PointLike, b_half: PointLike) -> bool:
    """Centre/half-size form of `aabb_overlap`: |dx| < ha.x + hb.x and |dy| < ha.y + hb.y."""
    acx, acy = as_point(a_center, "a_center")
    ahx, ahy = as_point(a_half, "a_half")
    bcx, bcy = as_point(b_center, "b_center")
    bhx, bhy = as_point(b_half, "b_half")
    if min(ahx, ahy, bhx, bhy) < 0:
        raise InputError("half sizes must be >= 0")
    return abs(acx - bcx) < ahx + bhx and abs(acy - bcy) < ahy + bhy


def aabb_contains_point(box_min: PointLike, box_max: PointLike, point: PointLike) -> bool:
    """True when the point lies strictly inside the box (a point on an edge is outside)."""
    (x0, y0), (x1, y1) = as_box(box_min, box_max)
    px, py = as_point(point)
    return x0 < px < x1 and y0 < py < y1


def aabb_mtv(a_min: PointLike, a_max: PointLike, b_min: PointLike, b_max: PointLike) -> tuple[tuple[int, int], Number] | None:
    """None when the boxes do not overlap, else (axis, depth) like `sat`: moving a by axis * depth
    is the smallest move that separates it from b. The axis is one of (+-1, 0), (0, +-1); ties
    prefer x, then the positive direction."""
    (ax0, ay0), (ax1, ay1) = as_box(a_min, a_max, "a")
    (bx0, by0), (bx1, by1) = as_box(b_min, b_max, "b")
    if not (ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1):
        return None
    candidates = [((1, 0), bx1 - ax0), ((-1, 0), ax1 - bx0), ((0, 1), by1 - ay0), ((0, -1), ay1 - by0)]
    return min(candidates, key=lambda c: c[1])


def points_bounds(points: PointLike) -> Box:
    """Bounding box of a non-empty sequence of points."""
    pts = [as_point(p, f"points[{i}]") for i, p in enumerate(points)]  # type: ignore[arg-type]
    if not pts:
        raise InputError("points: need at least one point")
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    return (min(xs), min(ys)), (max(xs), max(ys))
