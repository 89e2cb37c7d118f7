"""Boxes and circles: both AABB forms, the strict edge convention, and circle tests against shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, box

from retro.geometry import (
    aabb_contains_point,
    aabb_from_center,
    aabb_mtv,
    aabb_overlap,
    aabb_overlap_centered,
    aabb_to_center,
    circle_aabb_mtv,
    circle_aabb_overlap,
    circle_mtv,
    circle_overlap,
    point_in_circle,
    sat,
)

coords = st.integers(-20, 20)
sizes = st.integers(0, 10)


def test_touching_boxes_do_not_overlap():
    assert not aabb_overlap((0, 0), (8, 8), (8, 0), (16, 8))      # adjacent 8x8 sprites
    assert aabb_overlap((0, 0), (8, 8), (7, 0), (15, 8))          # one shared pixel column
    assert not aabb_overlap((0, 0), (8, 8), (8, 8), (9, 9))       # corner
    assert not aabb_contains_point((0, 0), (2, 2), (2, 1)) and aabb_contains_point((0, 0), (2, 2), (1, 1))


@given(coords, coords, sizes, sizes, coords, coords, sizes, sizes)
@settings(max_examples=400, deadline=None)
def test_aabb_forms_agree_with_shapely(ax, ay, aw, ah, bx, by, bw, bh):
    a_min, a_max, b_min, b_max = (ax, ay), (ax + aw, ay + ah), (bx, by), (bx + bw, by + bh)
    expected = aw > 0 and ah > 0 and bw > 0 and bh > 0 and bool(
        shapely.relate_pattern(box(*a_min, *a_max), box(*b_min, *b_max), "T********"))
    got = aabb_overlap(a_min, a_max, b_min, b_max)
    if aw and ah and bw and bh:
        assert got == expected
    (ca, ha), (cb, hb) = aabb_to_center(a_min, a_max), aabb_to_center(b_min, b_max)
    assert aabb_overlap_centered(ca, ha, cb, hb) == got
    assert aabb_from_center(ca, ha) == (a_min, a_max)
    mtv = aabb_mtv(a_min, a_max, b_min, b_max)
    assert (mtv is not None) == got
    if mtv and aw and ah and bw and bh:  # agrees with SAT on the same boxes as polygons
        poly = lambda lo, hi: [lo, (hi[0], lo[1]), hi, (lo[0], hi[1])]  # noqa: E731
        axis, depth = sat(poly(a_min, a_max), poly(b_min, b_max))
        assert depth == pytest.approx(mtv[1])


def test_integer_inputs_stay_exact():
    big = 2 ** 60  # far beyond float precision: a float conversion would merge these
    assert not aabb_overlap((big, 0), (big + 1, 1), (big + 1, 0), (big + 2, 1))
    assert circle_overlap((big, 0), 3, (big + 4, 3), 3) and not circle_overlap((big, 0), 2, (big + 4, 3), 3)


def test_circles_by_hand():
    assert not circle_overlap((0, 0), 2, (5, 0), 3)               # tangent
    assert circle_overlap((0, 0), 2, (4.9, 0), 3)
    assert not point_in_circle((3, 4), (0, 0), 5) and point_in_circle((3, 3.9), (0, 0), 5)
    axis, depth = circle_mtv((0, 0), 2, (3, 0), 2)
    assert axis == pytest.approx((-1, 0)) and depth == pytest.approx(1)
    assert circle_mtv((1, 1), 1, (1, 1), 2) == ((1.0, 0.0), 3.0)  # concentric: documented axis


@given(st.floats(-10, 10), st.floats(-10, 10), st.floats(0.1, 5), coords, coords, sizes, sizes)
@settings(max_examples=400, deadline=None)
def test_circle_aabb_against_distance_to_box(cx, cy, r, bx, by, bw, bh):
    lo, hi = (bx, by), (bx + bw, by + bh)
    distance = box(*lo, *hi).distance(Point(cx, cy))  # 0 inside the box
    got = circle_aabb_overlap((cx, cy), r, lo, hi)
    if abs(distance - r) > 1e-9:
        assert got == (distance < r)
    mtv = circle_aabb_mtv((cx, cy), r, lo, hi)
    assert (mtv is not None) == got
    if mtv and bw > 0 and bh > 0:  # pushed out, the circle just touches the box
        (ux, uy), depth = mtv
        moved = Point(cx + ux * depth, cy + uy * depth)
        assert box(*lo, *hi).distance(moved) == pytest.approx(r, abs=1e-9)


def test_circle_overlap_matches_distance():
    rng = np.random.default_rng(17)
    for _ in range(500):
        a, b = rng.uniform(-5, 5, 2), rng.uniform(-5, 5, 2)
        ra, rb = rng.uniform(0.1, 3, 2)
        assert circle_overlap(a, ra, b, rb) == (math.dist(a, b) < ra + rb)
