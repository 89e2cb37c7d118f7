"""Each method's verdicts against an independent per-case derivation, and the study's invariants."""

from __future__ import annotations

import math

import numpy as np
import pytest

from retro.analysis.study.accuracy import confusion
from retro.analysis.study.corpus import make_pair
from retro.analysis.study.evaluate import evaluate
from retro.analysis.study.fits import fitted_circle, pixel_hull, tight_box
from retro.analysis.study.methods import METHODS, method
from retro.geometry.aabb import aabb_overlap
from retro.geometry.circle import circle_overlap


@pytest.fixture(scope="module")
def table(sprite_shapes, hand_shapes):
    return evaluate(sprite_shapes + hand_shapes, workers=1)


def test_pixel_perfect_and_latch_have_zero_error(table):
    for p in table.pairs:
        for key in ("pixel", "latch"):
            c = p.counts[key]
            assert c.fp == 0 and c.fn == 0, (p.pair, key)
            assert c.tp == p.colliding


@pytest.mark.parametrize("key", ["box", "tight", "tight_edges", "sprite_edges", "sat", "circle", "circle_r", "tile"])
def test_enclosing_methods_never_miss(table, key):
    """Boxes, hulls, enclosing circles and the cells they touch all contain every opaque pixel."""
    for p in table.pairs:
        assert p.counts[key].fn == 0, p.pair


def test_rates_lie_in_unit_interval_and_follow_the_counts(table):
    for p in table.pairs:
        for key, c in p.counts.items():
            assert c.cases == pytest.approx(p.cases)
            assert c.tp + c.fn == pytest.approx(p.colliding)
            for rate in (c.fp_rate, c.fn_rate, c.accuracy):
                assert math.isnan(rate) or 0 <= rate <= 1
            if c.fp + c.tn:
                assert c.fp_rate == pytest.approx(c.fp / (p.cases - p.colliding))
            assert c.accuracy == pytest.approx((c.tp + c.tn) / p.cases)


def test_full_box_reports_every_case(table):
    """The corpus holds only offsets where the sprite boxes meet: the box method says hit on all."""
    for p in table.pairs:
        c = p.counts["box"]
        assert c.tp + c.fp == p.cases


def test_tight_box_and_circle_match_the_geometry_reference(sprite_shapes):
    a, b = sprite_shapes[0], sprite_shapes[2]
    pair = make_pair(a, b)
    tight = method("tight").verdict(pair)
    circle = method("circle").verdict(pair)
    ta, tb = tight_box(a.mask), tight_box(b.mask)
    ca, cb = fitted_circle(a.mask), fitted_circle(b.mask)
    for i in range(0, pair.cases, 7):
        dx, dy = int(pair.dx[i]), int(pair.dy[i])
        box_hit = aabb_overlap(ta[:2], ta[2:], (tb[0] + dx, tb[1] + dy), (tb[2] + dx, tb[3] + dy))
        assert tight[i] == box_hit
        assert circle[i] == circle_overlap((ca.cx, ca.cy), ca.r, (cb.cx + dx, cb.cy + dy), cb.r)


def test_tile_method_is_the_average_over_64_alignments(hand_shapes, sprite_shapes):
    """Brute force: place a at every (ax, ay) in 0..7, list the 8x8 cells each tight box touches."""
    a, b = hand_shapes[0], sprite_shapes[0]
    pair = make_pair(a, b)
    verdict = method("tile").verdict(pair)
    (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = tight_box(a.mask), tight_box(b.mask)

    def cells(x0, y0, x1, y1):
        return {(x // 8, y // 8) for x in range(x0, x1) for y in range(y0, y1)}

    for i in range(0, pair.cases, 53):
        dx, dy = int(pair.dx[i]), int(pair.dy[i])
        hits = sum(bool(cells(ox + ax0, oy + ay0, ox + ax1, oy + ay1)
                        & cells(ox + dx + bx0, oy + dy + by0, ox + dx + bx1, oy + dy + by1))
                   for ox in range(8) for oy in range(8))
        assert verdict[i] == pytest.approx(hits / 64)


def test_fitted_circle_encloses_every_opaque_pixel_strictly(sprite_shapes):
    for s in sprite_shapes:
        c = fitted_circle(s.mask)
        ys, xs = np.nonzero(s.mask)
        assert ((xs - c.cx) ** 2 + (ys - c.cy) ** 2 < c.r ** 2).all()
        assert not ((xs - c.cx) ** 2 + (ys - c.cy) ** 2 < (c.r - 1) ** 2).all()  # and no bigger than needed


def test_hull_contains_every_pixel_square(sprite_shapes):
    from shapely.geometry import Polygon, box

    for s in sprite_shapes:
        hull = Polygon(pixel_hull(s.mask))
        assert hull.is_valid
        for y, x in zip(*np.nonzero(s.mask)):
            assert hull.covers(box(x, y, x + 1, y + 1))


def test_methods_disagree_with_truth_somewhere(table):
    """The approximate methods really are approximate on this corpus (a test that could fail)."""
    for key in ("box", "tight", "circle", "tile", "sat"):
        assert any(p.counts[key].fp > 0 for p in table.pairs), key


def test_confusion_counts_by_hand():
    c = confusion(np.array([1, 0, 1, 0, 0.25]), np.array([True, True, False, False, False]))
    assert (c.tp, c.fn, c.fp, c.tn) == (1, 1, 1.25, 1.75)
    assert c.fp_rate == pytest.approx(1.25 / 3) and c.fn_rate == 0.5 and c.accuracy == pytest.approx(2.75 / 5)


def test_every_method_is_listed_once():
    assert len({m.key for m in METHODS}) == len(METHODS) == 10
