"""First hit along a ray among many shapes, through the dynamic AABB tree: only shapes whose
bounding box the ray reaches before the best hit so far are tested exactly."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from retro.errors import InputError
from retro.geometry.aabb import as_box
from retro.geometry.broadphase.aabbtree import AABBTree
from retro.geometry.rays import ray_aabb, ray_circle, ray_segment
from retro.geometry.vectors import (
    Number,
    Point,
    PointLike,
    as_nonzero_vector,
    as_point,
    as_positive,
)


@dataclass(frozen=True)
class Box:
    min: Point
    max: Point


@dataclass(frozen=True)
class Circle:
    center: Point
    radius: Number


@dataclass(frozen=True)
class Segment:
    a: Point
    b: Point


Shape = Box | Circle | Segment


@dataclass(frozen=True)
class RayHit:
    """The shape hit first (its index), the ray parameter t >= 0, the hit point, and how many
    shapes were tested exactly to find it."""

    index: int
    t: float
    point: tuple[float, float]
    shapes_tested: int


def hit_time(shape: Shape, origin: PointLike, direction: PointLike) -> float | None:
    """When the ray first touches the shape: t >= 0, or None. A ray starting inside a box or a
    circle hits it at t = 0."""
    if isinstance(shape, Box):
        span = ray_aabb(origin, direction, shape.min, shape.max)
        return None if span is None else max(span[0], 0.0)
    if isinstance(shape, Circle):
        span = ray_circle(origin, direction, shape.center, shape.radius)
        return None if span is None else max(span[0], 0.0)
    if isinstance(shape, Segment):
        return ray_segment(origin, direction, shape.a, shape.b)
    raise InputError(f"shape: expected Box, Circle or Segment, got {type(shape).__name__}")


def shape_bounds(shape: Shape, name: str = "shape") -> tuple[Point, Point]:
    if isinstance(shape, Box):
        return as_box(shape.min, shape.max, name)
    if isinstance(shape, Circle):
        cx, cy = as_point(shape.center, f"{name}.center")
        r = as_positive(shape.radius, f"{name}.radius")
        return (cx - r, cy - r), (cx + r, cy + r)
    if isinstance(shape, Segment):
        ax, ay = as_point(shape.a, f"{name}.a")
        bx, by = as_point(shape.b, f"{name}.b")
        if (ax, ay) == (bx, by):
            raise InputError(f"{name}: zero-length segment")
        return (min(ax, bx), min(ay, by)), (max(ax, bx), max(ay, by))
    raise InputError(f"{name}: expected Box, Circle or Segment, got {type(shape).__name__}")


class RayScene:
    """Shapes indexed 0..N-1 in an AABB tree, ready for many ray queries."""

    def __init__(self, shapes: Sequence[Shape]) -> None:
        self.shapes = list(shapes)
        self.tree = AABBTree()
        for i, shape in enumerate(self.shapes):
            lo, hi = shape_bounds(shape, f"shapes[{i}]")
            self.tree.insert(i, lo, hi)

    def first_hit(self, origin: PointLike, direction: PointLike, max_t: float = math.inf) -> RayHit | None:
        """The nearest shape the ray touches with t <= max_t (ties: lowest index), or None."""
        o = as_point(origin, "origin")
        d = as_nonzero_vector(direction, "direction")
        found = self.tree.raycast(o, d, lambda i: hit_time(self.shapes[i], o, d), max_t)  # type: ignore[arg-type, index]
        if found is None:
            return None
        t, index, tested = found
        return RayHit(int(index), float(t), (o[0] + t * d[0], o[1] + t * d[1]), tested)  # type: ignore[arg-type]
