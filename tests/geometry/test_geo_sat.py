"""SAT and concave polygon overlap against shapely; the MTV against the Minkowski difference."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from geometry_shapes import interiors_intersect, random_convex, random_star
from shapely.affinity import translate
from shapely.geometry import LineString, MultiPoint, Polygon

from retro.geometry import polygons_overlap, sat, sat_overlap


def test_hand_computed_squares():
    a = [(0, 0), (2, 0), (2, 2), (0, 2)]
    # b overlaps a by 1 in x and 0.5 in y: the smallest push of a is 0.5 downwards (-y).
    b = [(1, 1.5), (3, 1.5), (3, 3.5), (1, 3.5)]
    axis, depth = sat(a, b)
    assert axis == pytest.approx((0, -1)) and depth == pytest.approx(0.5)
    assert sat(a, [(2, 0), (4, 0), (4, 2), (2, 2)]) is None      # shares an edge: touching
    assert sat(a, [(2, 2), (3, 2), (3, 3)]) is None                # shares a corner
    assert sat(a, [(2.5, 0), (4, 0), (4, 2)]) is None


def _touching_partner(a, rng):
    """a point-reflected through the midpoint of one of its edges: the copy lies on the other side
    of that edge and shares it, so the two touch along the edge without overlapping."""
    i = int(rng.integers(len(a)))
    (x0, y0), (x1, y1) = a[i], a[(i + 1) % len(a)]
    return [(x0 + x1 - x, y0 + y1 - y) for x, y in a]


def test_sat_agrees_with_shapely_on_random_convex_polygons():
    rng = np.random.default_rng(6)
    counts = {"overlap": 0, "touching": 0, "apart": 0}
    for k in range(2500):
        a = random_convex(rng)
        if k % 5 == 0:
            b = _touching_partner(a, rng)
            if k % 10 == 0:  # nudge it one pixel: now overlapping, touching or apart
                dx, dy = (int(v) for v in rng.integers(-1, 2, 2))
                b = [(x + dx, y + dy) for x, y in b]
        else:
            b = random_convex(rng, 0, 20)
            dx, dy = (int(v) for v in rng.integers(-12, 13, 2))
            b = [(x + dx, y + dy) for x, y in b]
        pa, pb = Polygon(a), Polygon(b)
        expected = interiors_intersect(a, b)
        assert (sat(a, b) is not None) == expected, (a, b)
        assert sat_overlap(a, b) == expected
        if expected:
            counts["overlap"] += 1
            assert pa.intersection(pb).area > 0
        elif pa.intersects(pb):
            counts["touching"] += 1
            assert pa.touches(pb) and pa.intersection(pb).area == 0
        else:
            counts["apart"] += 1
    # The sample exercises all three cases, touching included.
    assert min(counts.values()) > 200, counts


def test_concave_overlap_agrees_with_shapely():
    rng = np.random.default_rng(7)
    touching = overlapping = 0
    for k in range(1200):
        a = random_star(rng, (10, 10))
        if k % 4 == 0:
            b = random_convex(rng, 0, 20)
        else:
            b = random_star(rng, tuple(float(v) for v in rng.integers(0, 21, 2)))
        expected = interiors_intersect(a, b)
        assert polygons_overlap(a, b) == expected, (a, b)
        overlapping += expected
        touching += (not expected) and Polygon(a).intersects(Polygon(b))
    assert overlapping > 300 and touching > 10, (overlapping, touching)


def _minkowski_difference(a, b) -> Polygon:
    """D = B + (-A): moving a by v makes the interiors meet exactly when v is inside D."""
    return MultiPoint([(bx - ax, by - ay) for ax, ay in a for bx, by in b]).convex_hull


def _exit_distance(region: Polygon, u: tuple[float, float]) -> float:
    """How far along unit direction u the origin (inside region) must move to leave it."""
    far = 1e4
    hit = LineString([(0, 0), (u[0] * far, u[1] * far)]).intersection(region.exterior)
    points = [hit] if hit.geom_type == "Point" else list(getattr(hit, "geoms", []))
    return min(math.hypot(p.x, p.y) for p in points)


def test_mtv_is_the_minimum_translation():
    rng = np.random.default_rng(8)
    checked = 0
    directions = [(math.cos(t), math.sin(t)) for t in np.linspace(0, 2 * math.pi, 72, endpoint=False)]
    while checked < 150:
        a = random_convex(rng, 0, 10, integer=False)
        b = random_convex(rng, 0, 10, integer=False)
        result = sat(a, b)
        if result is None:
            continue
        checked += 1
        (ux, uy), depth = result
        assert math.hypot(ux, uy) == pytest.approx(1.0) and depth > 0
        region = _minkowski_difference(a, b)
        # Penetration depth = distance from the origin to the boundary of the Minkowski difference.
        assert depth == pytest.approx(region.exterior.distance(shapely.Point(0, 0)), rel=1e-9, abs=1e-9)
        pa, pb = Polygon(a), Polygon(b)
        beyond = translate(pa, ux * depth * (1 + 1e-9) + ux * 1e-9, uy * depth * (1 + 1e-9) + uy * 1e-9)
        short = translate(pa, ux * depth * (1 - 1e-6), uy * depth * (1 - 1e-6))
        assert beyond.intersection(pb).area < 1e-9
        assert short.intersection(pb).area > 0
        assert sat(list(beyond.exterior.coords)[:-1], b) is None
        assert sat(list(short.exterior.coords)[:-1], b) is not None
        # No sampled direction separates with a shorter move; the best sample comes close.
        along = [_exit_distance(region, u) for u in directions]
        assert min(along) >= depth * (1 - 1e-9)
        assert min(along) <= depth / math.cos(math.pi / 72) + 1e-9


def test_winding_does_not_matter():
    rng = np.random.default_rng(9)
    for _ in range(200):
        a, b = random_convex(rng, integer=False), random_convex(rng, integer=False)
        r1, r2 = sat(a, b), sat(a[::-1], b[::-1])
        assert (r1 is None) == (r2 is None)
        if r1:
            assert r1[1] == pytest.approx(r2[1])
