"""Rays against single shapes: AABB (slab method), circle (quadratic), segment.

A ray is `origin + t * direction` for t >= 0; the direction need not be unit length (t is then
measured in multiples of it) but must not be zero. Hit points are `origin + t * direction`.

Edge convention as everywhere in retro.geometry: solid shapes (boxes, circles) are hit only when
the ray passes through their interior, so a ray grazing an edge, a corner or a tangent point
misses. Segments have no interior; they are closed (end points included).
"""

from __future__ import annotations

import math

from retro.errors import InputError
from retro.geometry.aabb import as_box
from retro.geometry.vectors import (
    Number,
    PointLike,
    as_nonzero_vector,
    as_point,
    as_positive,
    cross,
)


def slab_interval(origin: tuple[Number, Number], direction: tuple[Number, Number],
                  box_min: tuple[Number, Number], box_max: tuple[Number, Number],
                  closed: bool = False) -> tuple[float, float] | None:
    """Parameter interval of the whole line origin + t * direction (any t, negative too) inside the
    box: open box by default (the interval is then open, returned as its end points), closed box
    with `closed=True`. None when empty. A zero direction component means the line never leaves
    that slab, so it is inside it for all t or for none. Inputs assumed checked."""
    t_lo, t_hi = -math.inf, math.inf
    for o, d, lo, hi in ((origin[0], direction[0], box_min[0], box_max[0]),
                         (origin[1], direction[1], box_min[1], box_max[1])):
        if d == 0:
            inside = lo <= o <= hi if closed else lo < o < hi
            if not inside:
                return None
            continue
        t0, t1 = (lo - o) / d, (hi - o) / d
        if t0 > t1:
            t0, t1 = t1, t0
        t_lo, t_hi = max(t_lo, t0), min(t_hi, t1)
    if t_lo > t_hi or (not closed and t_lo == t_hi):
        return None
    return t_lo, t_hi


def ray_aabb(origin: PointLike, direction: PointLike, box_min: PointLike, box_max: PointLike) -> tuple[float, float] | None:
    """Slab method. None on a miss, else (t_enter, t_exit) with the hit points at
    origin + t * direction; t_enter may be negative when the origin is inside the box.
    A hit means some t > 0 puts the point strictly inside the box."""
    o = as_point(origin, "origin")
    d = as_nonzero_vector(direction, "direction")
    lo, hi = as_box(box_min, box_max)
    interval = slab_interval(o, d, lo, hi)
    if interval is None or interval[1] <= 0:
        return None
    return float(interval[0]), float(interval[1])


def ray_circle(origin: PointLike, direction: PointLike, center: PointLike, radius: Number) -> tuple[float, float] | None:
    """Roots of |origin + t * direction - center|^2 = radius^2. None on a miss (including a
    tangent ray), else (t_enter, t_exit) like `ray_aabb`: t_enter may be negative when the origin
    is inside the circle, and the nearest positive root is t_enter if t_enter > 0 else t_exit."""
    ox, oy = as_point(origin, "origin")
    dx, dy = as_nonzero_vector(direction, "direction")
    cx, cy = as_point(center, "center")
    r = as_positive(radius, "radius")
    roots = circle_roots(ox - cx, oy - cy, dx, dy, r)
    if roots is None or roots[1] <= 0:
        return None
    return roots


def circle_roots(mx: float, my: float, dx: float, dy: float, r: float) -> tuple[float, float] | None:
    """The two t (ascending) at which a point at (mx, my) relative to a circle's centre, moving by
    (dx, dy) per unit of t (not zero), is at distance r from it; None when it never is, or only
    touches (a tangent). Shared by rays and swept circles."""
    a = dx * dx + dy * dy
    b = 2 * (dx * mx + dy * my)
    c = mx * mx + my * my - r * r
    disc = b * b - 4 * a * c
    if disc <= 0:
        return None
    # The numerically stable pair of roots (no cancellation between -b and sqrt(disc)).
    q = -(b + math.copysign(math.sqrt(disc), b)) / 2
    t1, t2 = sorted((q / a, c / q))
    return float(t1), float(t2)


def ray_segment(origin: PointLike, direction: PointLike, seg_a: PointLike, seg_b: PointLike) -> float | None:
    """Smallest t >= 0 at which the ray touches the closed segment a-b, or None. A ray running
    along the segment's own line returns where it first reaches the segment (0 if it starts on it)."""
    ox, oy = as_point(origin, "origin")
    dx, dy = as_nonzero_vector(direction, "direction")
    ax, ay = as_point(seg_a, "seg_a")
    bx, by = as_point(seg_b, "seg_b")
    ex, ey = bx - ax, by - ay
    if ex == 0 and ey == 0:
        raise InputError("segment: zero length (seg_a equals seg_b)")
    wx, wy = ax - ox, ay - oy
    denom = cross(dx, dy, ex, ey)
    if denom != 0:
        t = cross(wx, wy, ex, ey) / denom
        u = cross(wx, wy, dx, dy) / denom
        return float(t) if t >= 0 and 0 <= u <= 1 else None
    if cross(wx, wy, dx, dy) != 0:
        return None  # parallel lines that never meet
    dd = dx * dx + dy * dy
    ta = (wx * dx + wy * dy) / dd
    tb = ((bx - ox) * dx + (by - oy) * dy) / dd
    lo, hi = min(ta, tb), max(ta, tb)
    if hi < 0:
        return None
    return float(max(lo, 0.0))
