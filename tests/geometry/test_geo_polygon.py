"""Polygon helpers: winding, convexity, rotation, and the convex decomposition checked with shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from geometry_shapes import random_star
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon
from shapely.ops import unary_union

from retro.errors import InputError
from retro.geometry import (
    convex_decompose,
    convex_polygon,
    is_ccw,
    is_convex,
    polygon_centroid,
    regular_polygon,
    rotate_point,
    rotate_polygon,
    signed_area,
    simplify_polygon,
    triangulate,
)


def test_area_and_winding_by_hand():
    square = [(0, 0), (2, 0), (2, 2), (0, 2)]  # counter-clockwise with y up
    assert signed_area(square) == 4 and is_ccw(square)
    assert signed_area(square[::-1]) == -4 and not is_ccw(square[::-1])
    assert convex_polygon(square[::-1])[0] in square  # returned counter-clockwise
    assert signed_area(convex_polygon(square[::-1])) == 4
    assert polygon_centroid(square) == pytest.approx((1, 1))


def test_is_convex():
    assert is_convex([(0, 0), (2, 0), (2, 2), (0, 2)])
    assert not is_convex([(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)])


def test_rotation_by_hand():
    assert rotate_point((1, 0), math.pi / 2) == pytest.approx((0, 1))
    assert rotate_point((2, 1), math.pi, about=(1, 1)) == pytest.approx((0, 1))
    square = [(0, 0), (2, 0), (2, 2), (0, 2)]
    turned = rotate_polygon(square, math.pi / 4)  # about the centroid (1, 1)
    assert turned[0] == pytest.approx((1, 1 - math.sqrt(2)))
    pent = regular_polygon(5, 2.0, (3, 4), rotation=0.3)
    assert all(math.hypot(x - 3, y - 4) == pytest.approx(2.0) for x, y in pent)
    assert signed_area(pent) > 0


@given(st.floats(-10, 10), st.floats(-100, 100), st.floats(-100, 100))
@settings(max_examples=60, deadline=None)
def test_rotation_preserves_area_and_distance(angle, ox, oy):
    poly = [(0, 0), (3, 0), (4, 2), (1, 3)]
    turned = rotate_polygon(poly, angle, about=(ox, oy))
    assert signed_area(turned) == pytest.approx(signed_area(poly), abs=1e-6)
    assert math.dist(turned[0], turned[2]) == pytest.approx(math.dist(poly[0], poly[2]))


def test_simplify_removes_repeats_and_collinear_vertices():
    messy = [(0, 0), (1, 0), (2, 0), (2, 0), (2, 2), (0, 2), (0, 0)]
    assert simplify_polygon(messy) == [(2.0, 0.0), (2.0, 2.0), (0.0, 2.0), (0.0, 0.0)]
    with pytest.raises(InputError, match="fewer than 3"):
        simplify_polygon([(0, 0), (1, 0), (2, 0)])


def test_decomposition_covers_the_polygon_with_convex_pieces():
    rng = np.random.default_rng(10)
    for _ in range(300):
        ring = random_star(rng, (0, 0), integer=bool(rng.random() < 0.5))
        whole = Polygon(ring)
        triangles = triangulate(ring)
        assert len(triangles) == len(ring) - 2  # ear clipping of a simple n-gon: n - 2 ears
        pieces = convex_decompose(ring)
        assert 1 <= len(pieces) <= len(triangles)
        shapes = [Polygon(p) for p in pieces]
        for p in pieces:
            assert is_convex(p) and signed_area(p) > 0
        # The pieces tile the polygon: areas add up, union equals it, interiors are disjoint.
        assert sum(s.area for s in shapes) == pytest.approx(whole.area, rel=1e-9)
        assert unary_union(shapes).symmetric_difference(whole).area == pytest.approx(0, abs=1e-9 * whole.area)
        for i in range(len(shapes)):
            for j in range(i + 1, len(shapes)):
                assert not shapely.relate_pattern(shapes[i], shapes[j], "T********")


def test_convex_polygon_decomposes_into_itself():
    hexagon = regular_polygon(6, 1.0)
    assert len(convex_decompose(hexagon)) == 1
    l_shape = [(0, 0), (4, 0), (4, 1), (1, 1), (1, 4), (0, 4)]
    assert len(convex_decompose(l_shape)) == 2  # one reflex vertex: two convex pieces suffice


def test_convex_hull_matches_shapely_on_random_point_sets():
    import numpy as np
    from shapely.geometry import MultiPoint
    from shapely.geometry import Polygon as ShapelyPolygon

    from retro.geometry import convex_hull, is_ccw

    rng = np.random.default_rng(7)
    for _ in range(200):
        points = rng.integers(-20, 21, size=(int(rng.integers(3, 40)), 2))
        hull = convex_hull(points)
        expected = MultiPoint([tuple(p) for p in points.tolist()]).convex_hull
        if expected.geom_type != "Polygon":
            continue  # all points collinear: no area to compare
        assert is_ccw(hull)
        assert ShapelyPolygon(hull).symmetric_difference(expected).area == 0
        assert len(hull) == len(expected.exterior.coords) - 1  # no collinear or repeated vertices
