"""Each method's accuracy rule against the same rule computed independently (tests/study/independent.py).

Every verdict of every built-in method is compared case by case on whole pairs; a change of a rule
(a touching box or a tangent circle counted as a hit, another circle fit, another cell rule, a
different hull test) fails here. The pairs are chosen so that the edge cases exist in them: the
tests assert that touching boxes and tangent circles occur.
"""

from __future__ import annotations

import numpy as np
import pytest

import independent as ind
from retro.analysis.study.corpus import Shape, make_pair
from retro.analysis.study.methods import BUILTIN, method, sub_pair


def _offsets(pair) -> list[tuple[int, int]]:
    return list(zip(pair.dx.tolist(), pair.dy.tolist()))


@pytest.fixture(scope="module")
def pairs(sprite_shapes, hand_shapes):
    ball, bar, gem = sprite_shapes
    block, diagonal = hand_shapes
    return [make_pair(ball, bar), make_pair(gem, ball), make_pair(block, diagonal), make_pair(ball, ball)]


def test_offsets_are_the_meeting_sprite_boxes_in_row_order(pairs):
    for pair in pairs:
        assert _offsets(pair) == ind.all_offsets(pair.a.mask, pair.b.mask)


@pytest.mark.parametrize("key", ["tight", "tight_edges", "sprite_edges"])
def test_tight_box_rule(pairs, key):
    m = method(key)
    touching = 0
    for pair in pairs:
        a, b = ind.bounds(pair.a.mask), ind.bounds(pair.b.mask)
        expected = ind.box_hits(a, b, _offsets(pair))
        assert (m.verdict(pair) > 0).tolist() == expected, pair.name
        touching += sum(1 for dx, dy in _offsets(pair)
                        if (a[2] == b[0] + dx or b[2] + dx == a[0]) and ind.shared(a[1], a[3], b[1] + dy, b[3] + dy))
    assert touching > 0  # the pairs hold boxes that touch: counting them as hits would fail above


def test_full_box_rule(pairs):
    m = method("box")
    for pair in pairs:
        (ha, wa), (hb, wb) = pair.a.mask.shape, pair.b.mask.shape
        expected = ind.box_hits((0, 0, wa, ha), (0, 0, wb, hb), _offsets(pair))
        assert all(expected)  # the corpus holds exactly the offsets where the sprite boxes meet
        assert (m.verdict(pair) > 0).tolist() == expected
    # one offset further the full boxes only touch: no hit
    block = pairs[0]
    outside = block.__class__(a=block.a, b=block.b, dx=np.array([24, -24, 0]), dy=np.array([0, 0, 21]),
                              overlap=np.zeros(3, dtype=int))
    assert m.verdict(outside).tolist() == [0.0, 0.0, 0.0]


@pytest.mark.parametrize("key", ["circle", "circle_r"])
def test_circle_rule(pairs, key):
    m = method(key)
    tangent = 0
    for pair in pairs:
        ca, cb = ind.smallest_circle(pair.a.mask), ind.smallest_circle(pair.b.mask)
        expected = ind.circle_hits(ca, cb, _offsets(pair))
        assert (m.verdict(pair) > 0).tolist() == expected, pair.name
        tangent += len(ind.tangent_offsets(ca, cb, _offsets(pair)))
    assert tangent > 0  # tangent circles occur: counting them as hits would fail above


def test_circle_radii_by_hand(sprite_shapes):
    """The ball covers columns 2-21 and rows 1-19. Centred at (11, 9), its farthest opaque pixel is at
    distance^2 117, so the smallest integer radius with every pixel strictly inside is 11 (121 > 117);
    no centre nearby needs less. Two balls are tangent at d = 22."""
    ball = sprite_shapes[0]
    assert ind.bounds(ball.mask) == (2, 1, 22, 20)
    assert ind.smallest_circle(ball.mask) == (11, 9, 11)
    pair = make_pair(ball, ball)
    v = method("circle").verdict(sub_pair(pair, [int(np.flatnonzero((pair.dx == 22) & (pair.dy == 0))[0]),
                                                 int(np.flatnonzero((pair.dx == 21) & (pair.dy == 0))[0])]))
    assert v.tolist() == [0.0, 1.0]  # d = 22 = r1 + r2: tangent, no hit; d = 21: hit


def test_tile_rule(hand_shapes, sprite_shapes):
    block, _ = hand_shapes
    for pair in (make_pair(block, block), make_pair(block, sprite_shapes[1])):
        expected = ind.tile_shares(ind.bounds(pair.a.mask), ind.bounds(pair.b.mask), _offsets(pair))
        assert method("tile").verdict(pair) == pytest.approx(expected), pair.name


def test_tile_shares_by_hand(hand_shapes):
    """Two 4x4 blocks side by side (dx = 4, touching): they share a cell column unless block a's last
    column is the last of a cell, i.e. in 7 of the 8 x alignments; rows always share a cell."""
    block = hand_shapes[0]
    pair = make_pair(block, block)
    one = sub_pair(pair, [int(np.flatnonzero((pair.dx == 4) & (pair.dy == 0))[0])])
    assert method("tile").verdict(one).tolist() == [7 / 8]


@pytest.mark.parametrize("key", ["pixel", "latch"])
def test_exact_rules(pairs, key):
    m = method(key)
    for pair in pairs:
        assert (m.verdict(pair) > 0).tolist() == ind.pixel_hits(pair.a.mask, pair.b.mask, _offsets(pair)), pair.name


def test_sat_rule(pairs):
    for pair in pairs:
        expected = ind.hull_hits(pair.a.mask, pair.b.mask, _offsets(pair))
        assert (method("sat").verdict(pair) > 0).tolist() == expected, pair.name


def test_diagonal_by_hand(hand_shapes):
    """The diagonal (10 pixels at (i, i), i even) against itself: the pixels meet only when dx == dy
    and the offset is even with |dx| <= 18: 19 offsets (dx = dy = -18, -16, ..., 18)."""
    diagonal = hand_shapes[1]
    pair = make_pair(diagonal, diagonal)
    hits = method("pixel").verdict(pair) > 0
    assert sorted(zip(pair.dx[hits].tolist(), pair.dy[hits].tolist())) == [(d, d) for d in range(-18, 19, 2)]


def test_every_verdict_works_on_any_subset_of_cases(pairs):
    """A caller may ask for some cases only (the cost runs, the tunnelling line): same answers."""
    pair = pairs[1]
    chosen = [1900, 3, 777, 960, 0]
    for m in BUILTIN:
        assert m.verdict(sub_pair(pair, chosen)).tolist() == m.verdict(pair)[chosen].tolist(), m.key


def test_the_methods_and_their_keys():
    keys = [m.key for m in BUILTIN]
    assert len(set(keys)) == len(keys)
    assert keys == ["box", "tight", "tight_edges", "sprite_edges", "circle", "circle_r", "tile", "pixel", "latch", "sat"]
    assert [m.key for m in BUILTIN if m.hardware] == ["latch"]
    assert [m.key for m in BUILTIN if m.host_only] == ["sat"]
    assert [m.key for m in BUILTIN if m.averaged] == ["tile"]
    assert {m.key: m.prepare for m in BUILTIN if m.prepare} == {
        "tight_edges": "aabb_edges_prepare", "sprite_edges": "sprite_edges_prepare", "circle_r": "circle_r_prepare"}


def test_shapes_for_the_hand_cases_are_what_they_say(hand_shapes):
    block, diagonal = hand_shapes
    assert ind.bounds(block.mask) == (5, 6, 9, 10)
    assert len(ind.pixels(diagonal.mask)) == 10
    assert isinstance(block, Shape)


def test_fitted_circles_of_every_corpus_shape():
    """The fit itself (centre window, tie order, radius), shape by shape, both edge conventions; a
    lopsided shape whose far pixel sets the radius from the middle column."""
    from retro.analysis.study.corpus import DEFAULT_SHAPES, load_shapes
    from retro.analysis.study.fits import fitted_circle

    lopsided = np.zeros((21, 24), dtype=bool)
    lopsided[10, [2, 3, 4, 5, 20]] = True  # tight box 2-20, middle 11: r = 10 from x = 11, 11 from x = 12
    shapes = load_shapes(DEFAULT_SHAPES) + [Shape(name="lopsided", mask=lopsided)]
    for shape in shapes:
        for touching in (False, True):
            c = fitted_circle(shape.mask, touching)
            assert (c.cx, c.cy, c.r) == ind.smallest_circle(shape.mask, touching), (shape.name, touching)
    assert ind.smallest_circle(lopsided) == (11, 9, 10)


def test_user_box_inset_keeps_the_left_middle_pixel(tmp_path):
    """A 2-px-wide shape with 1 px off each side: nothing would be left; the box keeps the left one of
    the two middle columns (rounded down)."""
    from retro.analysis.study.methods.user import load_method_file

    path = tmp_path / "m.toml"
    path.write_text('[hitbox]\nshape = "box"\ninset = 1\n')
    mask = np.zeros((21, 24), dtype=bool)
    mask[5:15, 10:12] = True
    assert load_method_file(str(path)).box(Shape(name="two", mask=mask)) == (10, 6, 11, 14)
