"""Circles: point-in-circle, circle-circle and circle-vs-AABB, all by squared distance (no sqrt).

Edge convention as for boxes: only interiors count, so tangent circles (distance == r1 + r2) do NOT
overlap and a point on the circle is outside. Radii must be > 0. Integer inputs are compared
exactly.
"""

from __future__ import annotations

import math

from retro.geometry.aabb import as_box
from retro.geometry.vectors import Number, PointLike, as_point, as_positive


def point_in_circle(point: PointLike, center: PointLike, radius: Number) -> bool:
    """True when |point - center|^2 < radius^2."""
    px, py = as_point(point)
    cx, cy = as_point(center, "center")
    r = as_positive(radius, "radius")
    dx, dy = px - cx, py - cy
    return dx * dx + dy * dy < r * r


def circle_overlap(a_center: PointLike, a_radius: Number, b_center: PointLike, b_radius: Number) -> bool:
    """True when |ca - cb|^2 < (ra + rb)^2; tangent circles do not overlap."""
    ax, ay = as_point(a_center, "a_center")
    bx, by = as_point(b_center, "b_center")
    r = as_positive(a_radius, "a_radius") + as_positive(b_radius, "b_radius")
    dx, dy = ax - bx, ay - by
    return dx * dx + dy * dy < r * r


def closest_point_on_aabb(point: PointLike, box_min: PointLike, box_max: PointLike) -> tuple[Number, Number]:
    """The point of the closed box nearest to `point` (the point itself when inside): clamp x and y."""
    px, py = as_point(point)
    (x0, y0), (x1, y1) = as_box(box_min, box_max)
    return min(max(px, x0), x1), min(max(py, y0), y1)


def circle_aabb_overlap(center: PointLike, radius: Number, box_min: PointLike, box_max: PointLike) -> bool:
    """True when the disc and the box interiors intersect: clamp the centre into the box and compare
    the squared distance to radius^2. A centre inside the box always overlaps (distance 0 < r^2).

    Note: for a zero-size box (a point or a segment) this reports overlap when the point/segment
    lies inside the disc, although such a box has no interior of its own.
    """
    cx, cy = as_point(center, "center")
    r = as_positive(radius, "radius")
    qx, qy = closest_point_on_aabb((cx, cy), box_min, box_max)
    dx, dy = cx - qx, cy - qy
    return dx * dx + dy * dy < r * r


def circle_mtv(a_center: PointLike, a_radius: Number, b_center: PointLike, b_radius: Number) -> tuple[tuple[float, float], float] | None:
    """None when the circles do not overlap, else (axis, depth) like `sat`: moving circle a by
    axis * depth separates it from b. Concentric circles use the axis (1, 0)."""
    if not circle_overlap(a_center, a_radius, b_center, b_radius):
        return None
    ax, ay = as_point(a_center, "a_center")
    bx, by = as_point(b_center, "b_center")
    dx, dy = ax - bx, ay - by
    distance = math.hypot(dx, dy)
    depth = float(a_radius + b_radius - distance)
    if distance == 0:
        return (1.0, 0.0), depth
    return (dx / distance, dy / distance), depth


def circle_aabb_mtv(center: PointLike, radius: Number, box_min: PointLike, box_max: PointLike) -> tuple[tuple[float, float], float] | None:
    """None when the circle and box do not overlap, else (axis, depth): moving the circle by
    axis * depth separates it from the box. A centre inside the box leaves through the nearest face
    (ties: -x, +x, -y, +y in that order)."""
    if not circle_aabb_overlap(center, radius, box_min, box_max):
        return None
    cx, cy = as_point(center, "center")
    (x0, y0), (x1, y1) = as_box(box_min, box_max)
    qx, qy = closest_point_on_aabb((cx, cy), (x0, y0), (x1, y1))
    dx, dy = cx - qx, cy - qy
    if dx != 0 or dy != 0:  # centre outside: push straight away from the nearest box point
        distance = math.hypot(dx, dy)
        return (dx / distance, dy / distance), float(radius - distance)
    faces = [((-1.0, 0.0), cx - x0), ((1.0, 0.0), x1 - cx), ((0.0, -1.0), cy - y0), ((0.0, 1.0), y1 - cy)]
    axis, gap = min(faces, key=lambda f: f[1])
    return axis, float(gap + radius)
