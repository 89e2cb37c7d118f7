"""Bad input: a clear InputError naming the argument and the problem, never a wrong answer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from retro.errors import InputError
from retro.geometry import (
    aabb_overlap,
    circle_overlap,
    convex_decompose,
    mask_overlap,
    polygons_overlap,
    ray_aabb,
    ray_circle,
    ray_segment,
    sat,
    sat_overlap,
    swept_aabb,
    swept_circle,
)

SQUARE = [(0, 0), (2, 0), (2, 2), (0, 2)]
NAN, INF = math.nan, math.inf


@pytest.mark.parametrize("poly, words", [
    ([(0, 0), (1, 1)], "at least 3 vertices"),
    ([], "at least 3 vertices"),
    ([(0, 0), (1, 0), (2, 0)], "zero area"),
    ([(0, 0), (1, 0), (2, 0), (3, 0)], "zero area"),
    ([(0, 0), (2, 0), (2, 2), (0, 0)], "repeats vertex 0"),
    ([(0, 0), (2, 0), (2, 0), (0, 2)], "repeats vertex 1"),
    ([(0, 0), (1, 0), (2, 0), (1, 1)], "collinear"),
    ([(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)], "not convex"),
    ([(0, 0), (2, 2), (2, 0), (0, 2)], "zero area"),            # bow tie: the halves cancel
    ([(0, 0), (3, 3), (3, 0), (0, 2)], "not convex"),           # lopsided bow tie
    ([(0, 0), (1, NAN), (0, 1)], "not finite"),
    ([(0, 0), (INF, 0), (0, 1)], "not finite"),
    ([(0, 0), "ab", (0, 1)], "pairs"),
    ("abc", "pairs"),
])
def test_degenerate_polygons_are_refused_by_sat(poly, words):
    with pytest.raises(InputError, match=words) as err:
        sat(poly, SQUARE)
    assert str(err.value).startswith("a:")
    with pytest.raises(InputError, match=words):
        sat_overlap(SQUARE, poly)


def test_pentagram_is_not_convex():
    star = [(math.cos(4 * math.pi * k / 5), math.sin(4 * math.pi * k / 5)) for k in range(5)]
    with pytest.raises(InputError, match="b: self-intersecting"):
        sat(SQUARE, star)


def test_self_intersecting_concave_polygon_is_refused():
    bow = [(0, 0), (4, 0), (4, 4), (2, -1), (0, 4)]
    with pytest.raises(InputError, match="self-intersecting"):
        convex_decompose(bow)
    with pytest.raises(InputError, match="a: self-intersecting"):
        polygons_overlap(bow, SQUARE)


@pytest.mark.parametrize("call, words", [
    (lambda: ray_aabb((0, 0), (0, 0), (1, 1), (2, 2)), "direction: zero-length"),
    (lambda: ray_circle((0, 0), (0.0, 0.0), (1, 1), 1), "direction: zero-length"),
    (lambda: ray_segment((0, 0), (0, 0), (1, 1), (2, 2)), "direction: zero-length"),
    (lambda: ray_segment((0, 0), (1, 0), (1, 1), (1, 1)), "segment: zero length"),
    (lambda: ray_aabb((NAN, 0), (1, 0), (1, 1), (2, 2)), "origin.x: must be finite"),
    (lambda: ray_aabb((0, 0), (1, INF), (1, 1), (2, 2)), "direction.y: must be finite"),
    (lambda: ray_aabb((0, 0), (1, 0), (3, 1), (2, 2)), "min.x 3 is greater than max.x 2"),
    (lambda: ray_circle((0, 0), (1, 0), (1, 1), 0), "radius: must be > 0"),
    (lambda: aabb_overlap((0, 0), (1, 1), (0, NAN), (1, 1)), "b_min.y: must be finite"),
    (lambda: aabb_overlap((0, 0), (1, 1), (0, 0), "xy"), "b_max: expected an \\(x, y\\) pair"),
    (lambda: circle_overlap((0, 0), -1, (1, 1), 1), "a_radius: must be > 0"),
    (lambda: circle_overlap((0, 0), 1, (1, 1), NAN), "b_radius: must be finite"),
    (lambda: swept_aabb((0, 0), (1, 1), (NAN, 0), (2, 2), (3, 3)), "velocity.x: must be finite"),
    (lambda: swept_circle((0, 0), 1, (1, 0), (2, 2), 0), "other_radius: must be > 0"),
    (lambda: mask_overlap(np.zeros(3, bool), np.zeros((2, 2), bool), (0, 0)), "a: expected a 2-D mask"),
    (lambda: mask_overlap(np.zeros((2, 2), bool), np.zeros((2, 2), bool), (0.5, 0)), "offset.dx: must be an integer"),
    (lambda: mask_overlap(np.zeros((2, 2), bool), np.full((2, 2), 2), (0, 0)), "b: expected a bool mask"),
])
def test_bad_input_names_the_problem(call, words):
    with pytest.raises(InputError, match=words):
        call()


def test_errors_are_one_line():
    for call in (lambda: sat([(0, 0), (1, 0), (2, 0)], SQUARE), lambda: ray_aabb((0, 0), (0, 0), (0, 0), (1, 1))):
        with pytest.raises(InputError) as err:
            call()
        assert "\n" not in str(err.value)
