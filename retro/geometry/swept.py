"""Swept (continuous) tests: when, within one frame, does a moving shape first touch a static one.

A discrete test at the start and the end of the frame misses a fast object passing through a thin
one (tunnelling). Here the moving shape travels from its start position by `velocity` over the
frame, parameter t in [0, 1], and the test solves for the time interval during which the interiors
overlap. Both functions return None when that interval does not meet [0, 1], else the time of
first contact max(t_enter, 0): 0 when the shapes already overlap at the start of the frame. Moving
into contact exactly at t = 1, or sliding along an edge, is touching and so returns None.
To move two shapes at once, pass the relative velocity (v_moving - v_other).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from retro.geometry.aabb import as_box
from retro.geometry.rays import circle_roots
from retro.geometry.vectors import Number, PointLike, as_point, as_positive


@dataclass(frozen=True)
class SweptHit:
    """Time of first contact and the contact normal: a unit axis pointing from the other box
    towards the moving one, (0, 0) when they already overlap at t = 0."""

    t: float
    normal: tuple[int, int]


def _swept_interval(a_min, a_max, v, b_min, b_max) -> tuple[float, float, int] | None:
    """Open interval of t (any real t) in which box a moved by v*t overlaps b, and the axis
    (0 = x, 1 = y) whose entry time is the later one (x wins ties)."""
    t_lo, t_hi, entry_axis = -math.inf, math.inf, 0
    for axis in (0, 1):
        speed = v[axis]
        if speed == 0:
            if not (a_min[axis] < b_max[axis] and b_min[axis] < a_max[axis]):
                return None
            continue
        t0 = (b_min[axis] - a_max[axis]) / speed
        t1 = (b_max[axis] - a_min[axis]) / speed
        if t0 > t1:
            t0, t1 = t1, t0
        if t0 > t_lo:
            t_lo, entry_axis = t0, axis
        t_hi = min(t_hi, t1)
    if t_lo >= t_hi:
        return None
    return t_lo, t_hi, entry_axis


def swept_aabb_hit(box_min: PointLike, box_max: PointLike, velocity: PointLike,
                   other_min: PointLike, other_max: PointLike) -> SweptHit | None:
    """Like `swept_aabb`, but also gives the contact normal (for sliding and bouncing)."""
    a_min, a_max = as_box(box_min, box_max, "box")
    b_min, b_max = as_box(other_min, other_max, "other")
    v = as_point(velocity, "velocity")
    found = _swept_interval(a_min, a_max, v, b_min, b_max)
    if found is None:
        return None
    t_enter, t_exit, axis = found
    if t_enter >= 1 or t_exit <= 0:
        return None
    if t_enter <= 0:
        return SweptHit(0.0, (0, 0))
    normal = [0, 0]
    normal[axis] = -1 if v[axis] > 0 else 1
    return SweptHit(float(t_enter), (normal[0], normal[1]))


def swept_aabb(box_min: PointLike, box_max: PointLike, velocity: PointLike,
               other_min: PointLike, other_max: PointLike) -> float | None:
    """None when the box moving by `velocity` over one frame never overlaps the other box, else
    the time of first contact in [0, 1] (0 if they overlap already)."""
    hit = swept_aabb_hit(box_min, box_max, velocity, other_min, other_max)
    return None if hit is None else hit.t


def swept_circle(center: PointLike, radius: Number, velocity: PointLike,
                 other_center: PointLike, other_radius: Number) -> float | None:
    """None when the circle moving by `velocity` over one frame never overlaps the other circle,
    else the time of first contact in [0, 1] (0 if they overlap already). Solved as a ray from the
    centre against a circle of the summed radius."""
    cx, cy = as_point(center, "center")
    ox, oy = as_point(other_center, "other_center")
    vx, vy = as_point(velocity, "velocity")
    r = as_positive(radius, "radius") + as_positive(other_radius, "other_radius")
    mx, my = cx - ox, cy - oy
    c = mx * mx + my * my - r * r
    if vx == 0 and vy == 0:
        return 0.0 if c < 0 else None
    roots = circle_roots(mx, my, vx, vy, r)
    if roots is None:
        return None
    t1, t2 = roots
    if t1 >= 1 or t2 <= 0:
        return None
    return float(max(t1, 0.0))
