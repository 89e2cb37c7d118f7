"""Swept tests against dense time sampling, and no tunnelling through thin objects."""

from __future__ import annotations

import numpy as np
import pytest

from retro.geometry import (
    aabb_overlap,
    circle_overlap,
    swept_aabb,
    swept_aabb_hit,
    swept_circle,
)

TS = np.linspace(0, 1, 4001)


def test_swept_aabb_against_sampling():
    rng = np.random.default_rng(15)
    seen_hits = 0
    for _ in range(300):
        lo = rng.uniform(-10, 10, 2)
        hi = lo + rng.uniform(0.2, 4, 2)
        olo = rng.uniform(-10, 10, 2)
        ohi = olo + rng.uniform(0.2, 4, 2)
        v = rng.normal(0, 12, 2)
        if rng.random() < 0.2:
            v[rng.integers(2)] = 0
        t = swept_aabb(lo, hi, v, olo, ohi)
        # The definition, sampled: strict overlap of the moved box on both axes.
        mx0, mx1 = lo[0] + TS * v[0], hi[0] + TS * v[0]
        my0, my1 = lo[1] + TS * v[1], hi[1] + TS * v[1]
        overlapping = TS[(mx0 < ohi[0]) & (olo[0] < mx1) & (my0 < ohi[1]) & (olo[1] < my1)]
        if t is None:
            assert len(overlapping) == 0
            continue
        seen_hits += 1
        assert 0 <= t <= 1
        if len(overlapping):
            assert overlapping.min() >= t - 1e-9
            assert overlapping.min() - t < 2 * (TS[1] - TS[0]) or t == 0
        if t > 0:  # at the time of contact they touch, a moment later they overlap (or the frame ends)
            assert not aabb_overlap(lo + t * v * (1 - 1e-9), hi + t * v * (1 - 1e-9), olo, ohi)
    assert seen_hits > 30


def test_swept_circle_against_sampling():
    rng = np.random.default_rng(16)
    seen_hits = 0
    for _ in range(300):
        c, oc = rng.uniform(-10, 10, 2), rng.uniform(-10, 10, 2)
        r, orad = rng.uniform(0.3, 3), rng.uniform(0.3, 3)
        v = rng.normal(0, 12, 2)
        t = swept_circle(c, r, v, oc, orad)
        dx, dy = c[0] + TS * v[0] - oc[0], c[1] + TS * v[1] - oc[1]
        overlapping = TS[dx * dx + dy * dy < (r + orad) ** 2]
        if t is None:
            assert len(overlapping) == 0
            continue
        seen_hits += 1
        if len(overlapping):
            assert overlapping.min() >= t - 1e-9
            assert overlapping.min() - t < 2 * (TS[1] - TS[0]) or t == 0
        if t > 0:
            assert np.linalg.norm(c + t * v - oc) == pytest.approx(r + orad)
    assert seen_hits > 30


def test_no_tunnelling_through_a_thin_wall():
    wall_lo, wall_hi = (10.0, -50.0), (10.1, 50.0)
    box_lo, box_hi, v = (0.0, 0.0), (1.0, 1.0), (40.0, 0.0)
    # A discrete test at both ends of the frame sees nothing: the box jumped over the wall.
    assert not aabb_overlap(box_lo, box_hi, wall_lo, wall_hi)
    assert not aabb_overlap((40, 0), (41, 1), wall_lo, wall_hi)
    hit = swept_aabb_hit(box_lo, box_hi, v, wall_lo, wall_hi)
    assert hit.t == pytest.approx(9 / 40) and hit.normal == (-1, 0)
    assert not circle_overlap((0, 0), 0.5, (10, 0), 0.05) and not circle_overlap((40, 0), 0.5, (10, 0), 0.05)
    assert swept_circle((0, 0), 0.5, (40, 0), (10, 0), 0.05) == pytest.approx(9.45 / 40)


def test_edge_cases_by_hand():
    assert swept_aabb((0, 0), (1, 1), (0, 0), (0.5, 0.5), (2, 2)) == 0.0       # overlapping, not moving
    assert swept_aabb((0, 0), (1, 1), (0, 0), (1, 0), (2, 1)) is None          # touching, not moving
    assert swept_aabb((0, 0), (1, 1), (1, 0), (2, 0), (3, 1)) is None          # arrives exactly at t = 1
    assert swept_aabb((0, 0), (1, 1), (5, 0), (0, 1), (9, 2)) is None          # slides along an edge
    assert swept_aabb((0, 0), (1, 1), (-5, 0), (2, 0), (3, 1)) is None         # moving away
    assert swept_aabb_hit((0, 0), (1, 1), (0, 4), (0, 3), (1, 4)).normal == (0, -1)
