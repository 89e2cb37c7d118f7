"""Rays against dense sampling along the ray, and the ray scene against testing every shape."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import LineString

from retro.geometry import (
    Box,
    Circle,
    RayScene,
    Segment,
    ray_aabb,
    ray_circle,
    ray_segment,
)
from retro.geometry.raycast import hit_time

T_MAX, STEP = 30.0, 0.002
TS = np.arange(0, T_MAX, STEP)


def sample_inside(origin, direction, inside) -> np.ndarray:
    px = origin[0] + TS * direction[0]
    py = origin[1] + TS * direction[1]
    return TS[inside(px, py)]


def test_ray_aabb_by_hand():
    assert ray_aabb((0, 0), (1, 1), (1, 1), (2, 2)) == (1.0, 2.0)
    assert ray_aabb((1.5, 1.5), (1, 0), (1, 1), (2, 2)) == (-0.5, 0.5)   # origin inside
    assert ray_aabb((3, 1.5), (1, 0), (1, 1), (2, 2)) is None            # box behind
    assert ray_aabb((0, 1), (1, 0), (1, 1), (2, 2)) is None              # slides along an edge
    assert ray_aabb((0, 1), (1, 1), (0, 2), (1, 3)) is None              # grazes a corner
    assert ray_aabb((2, 1.5), (1, 0), (1, 1), (2, 2)) is None            # leaving from the edge


def test_ray_aabb_against_sampling():
    rng = np.random.default_rng(11)
    for _ in range(400):
        lo = rng.uniform(-5, 5, 2)
        hi = lo + rng.uniform(0.1, 6, 2)
        origin = rng.uniform(-10, 10, 2)
        direction = rng.normal(0, 1, 2)
        if rng.random() < 0.2:
            direction[rng.integers(2)] = 0.0  # axis-parallel rays: the division-free branch
        if not direction.any():
            continue
        hit = ray_aabb(origin, direction, lo, hi)
        inside = sample_inside(origin, direction, lambda x, y: (lo[0] < x) & (x < hi[0]) & (lo[1] < y) & (y < hi[1]))
        if hit is None:
            assert len(inside) == 0
            continue
        t_in, t_out = hit
        assert t_out > 0 and t_in < t_out
        if len(inside):
            assert inside.min() >= t_in - 1e-9 and inside.max() <= t_out + 1e-9
        if min(t_out, T_MAX) - max(t_in, 0) > 2 * STEP:
            assert len(inside) > 0
        if t_in > 0:  # the entry point is on the boundary
            x, y = origin + t_in * direction
            assert min(abs(x - lo[0]), abs(x - hi[0]), abs(y - lo[1]), abs(y - hi[1])) < 1e-9


def test_ray_circle_against_sampling():
    rng = np.random.default_rng(12)
    for _ in range(400):
        c = rng.uniform(-5, 5, 2)
        r = rng.uniform(0.2, 4)
        origin = rng.uniform(-10, 10, 2)
        direction = rng.normal(0, 1, 2)
        hit = ray_circle(origin, direction, c, r)
        inside = sample_inside(origin, direction, lambda x, y: (x - c[0]) ** 2 + (y - c[1]) ** 2 < r * r)
        if hit is None:
            assert len(inside) == 0
            continue
        t_in, t_out = hit
        assert t_out > 0
        for t in hit:
            assert math.dist(origin + t * direction, c) == pytest.approx(r)
        if len(inside):
            assert inside.min() >= t_in - 1e-9 and inside.max() <= t_out + 1e-9
        if min(t_out, T_MAX) - max(t_in, 0) > 2 * STEP:
            assert len(inside) > 0
    assert ray_circle((0, 1), (1, 0), (5, 0), 1) is None  # tangent: touching only


def test_ray_segment_against_shapely():
    rng = np.random.default_rng(13)
    hits = 0
    for k in range(600):
        a, b = rng.integers(-8, 9, 2).astype(float), rng.integers(-8, 9, 2).astype(float)
        if (a == b).all():
            continue
        origin = rng.integers(-8, 9, 2).astype(float)
        direction = rng.integers(-3, 4, 2).astype(float)
        if not direction.any():
            continue
        t = ray_segment(origin, direction, a, b)
        far = origin + 1000 * direction
        crossing = LineString([origin, far]).intersection(LineString([a, b]))
        if crossing.is_empty:
            assert t is None
            continue
        hits += 1
        points = [crossing.coords[0]] if crossing.geom_type == "Point" else list(crossing.coords)
        nearest = min(math.dist(origin, p) for p in points) / math.hypot(*direction)
        assert t == pytest.approx(nearest, abs=1e-9)
    assert hits > 100


def test_first_hit_through_the_tree_matches_every_shape_tested():
    rng = np.random.default_rng(14)
    shapes = []
    for _ in range(300):
        kind = rng.integers(3)
        p = rng.uniform(0, 200, 2)
        if kind == 0:
            shapes.append(Box(tuple(p), tuple(p + rng.uniform(1, 6, 2))))
        elif kind == 1:
            shapes.append(Circle(tuple(p), float(rng.uniform(0.5, 4))))
        else:
            shapes.append(Segment(tuple(p), tuple(p + rng.uniform(-8, 8, 2))))
    scene = RayScene(shapes)
    tested = []
    for _ in range(300):
        origin = rng.uniform(0, 200, 2)
        direction = rng.normal(0, 1, 2)
        times = [hit_time(s, origin, direction) for s in shapes]
        best = min(((t, i) for i, t in enumerate(times) if t is not None), default=None)
        hit = scene.first_hit(origin, direction)
        if best is None:
            assert hit is None
            continue
        assert (hit.t, hit.index) == best
        assert hit.point == pytest.approx(tuple(origin + hit.t * direction))
        tested.append(hit.shapes_tested)
        if best[0] > 0:  # nothing is hit before the first hit
            assert scene.first_hit(origin, direction, max_t=best[0] * 0.999) is None
    assert np.mean(tested) < len(shapes) / 5  # the tree prunes most shapes
