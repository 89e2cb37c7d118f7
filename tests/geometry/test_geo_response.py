"""Response: momentum (and, for e = 1, energy) conservation; sliding; separation along the MTV."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from retro.geometry import bounce, sat, separate, slide

speeds = st.floats(-50, 50)
masses = st.floats(0.1, 100)
angles = st.floats(0, 2 * math.pi)


def _energy(m, v):
    return 0.5 * m * (v[0] ** 2 + v[1] ** 2)


@given(speeds, speeds, speeds, speeds, masses, masses, angles, st.sampled_from([0.0, 1.0, 0.5]))
@settings(max_examples=300, deadline=None)
def test_bounce_conserves_momentum_and_sets_the_separation_speed(ax, ay, bx, by, ma, mb, angle, e):
    n = (math.cos(angle), math.sin(angle))
    va, vb = bounce((ax, ay), (bx, by), n, e, ma, mb)
    before_p = (ma * ax + mb * bx, ma * ay + mb * by)
    after_p = (ma * va[0] + mb * vb[0], ma * va[1] + mb * vb[1])
    assert after_p == pytest.approx(before_p, abs=1e-7 * (1 + max(map(abs, before_p))))
    rel_before = (ax - bx) * n[0] + (ay - by) * n[1]
    rel_after = (va[0] - vb[0]) * n[0] + (va[1] - vb[1]) * n[1]
    tangent = (-n[1], n[0])
    scale = 1e-7 * (1 + abs(rel_before) + abs(ax) + abs(bx) + abs(ay) + abs(by))
    if rel_before >= 0:  # already separating: untouched
        assert (va, vb) == ((ax, ay), (bx, by))
        return
    assert rel_after == pytest.approx(-e * rel_before, abs=scale)
    for v_old, v_new in (((ax, ay), va), ((bx, by), vb)):  # no friction: tangential speed kept
        assert v_new[0] * tangent[0] + v_new[1] * tangent[1] == pytest.approx(
            v_old[0] * tangent[0] + v_old[1] * tangent[1], abs=scale)
    energy_before = _energy(ma, (ax, ay)) + _energy(mb, (bx, by))
    energy_after = _energy(ma, va) + _energy(mb, vb)
    if e == 1.0:
        assert energy_after == pytest.approx(energy_before, rel=1e-7, abs=1e-7)
    else:
        assert energy_after <= energy_before * (1 + 1e-9) + 1e-9


def test_equal_masses_swap_velocities_head_on():
    va, vb = bounce((3, 0), (-1, 0), (-1, 0), 1.0)  # a on the left moving right: normal from b to a is -x
    assert va == pytest.approx((-1, 0)) and vb == pytest.approx((3, 0))
    va, vb = bounce((3, 0), (-1, 0), (-1, 0), 0.0)
    assert va == pytest.approx((1, 0)) and vb == pytest.approx((1, 0))  # stick together


def test_wall_reflects():
    va, vb = bounce((2, -3), (0, 0), (0, 1), 1.0, 1.0, math.inf)
    assert va == pytest.approx((2, 3)) and vb == (0, 0)


@given(speeds, speeds, angles)
@settings(max_examples=200, deadline=None)
def test_slide_removes_only_the_inward_part(vx, vy, angle):
    n = (math.cos(angle), math.sin(angle))
    sx, sy = slide((vx, vy), n)
    into = vx * n[0] + vy * n[1]
    if into >= 0:
        assert (sx, sy) == (vx, vy)
    else:
        assert sx * n[0] + sy * n[1] == pytest.approx(0, abs=1e-9 * (1 + abs(vx) + abs(vy)))
        assert -sx * n[1] + sy * n[0] == pytest.approx(-vx * n[1] + vy * n[0])


def test_separate_along_mtv_leaves_shapes_touching():
    a = [(0, 0), (4, 0), (4, 4), (0, 4)]
    b = [(3, 1), (7, 1), (7, 5), (3, 5)]
    axis, depth = sat(a, b)
    (pa, pb) = separate((2, 2), (5, 3), axis, depth, 1.0, 3.0)
    moved_a = [(x + pa[0] - 2, y + pa[1] - 2) for x, y in a]
    moved_b = [(x + pb[0] - 5, y + pb[1] - 3) for x, y in b]
    assert sat(moved_a, moved_b) is None
    assert math.dist((2, 2), pa) == pytest.approx(depth * 0.75)  # the lighter body moves more
    with pytest.raises(Exception, match="unit vector"):
        separate((0, 0), (1, 1), (2, 0), 1)
