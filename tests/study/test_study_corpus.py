"""Corpus and ground truth against a per-offset definition (retro.geometry.masks)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from retro.analysis.study.corpus import Shape, make_pair, overlap_counts
from retro.geometry.masks import mask_overlap_area


def test_offsets_cover_exactly_the_meeting_sprite_boxes(sprite_shapes):
    a, b = sprite_shapes[0], sprite_shapes[1]
    pair = make_pair(a, b)
    assert pair.cases == (24 + 24 - 1) * (21 + 21 - 1)
    assert pair.dx.min() == -23 and pair.dx.max() == 23 and pair.dy.min() == -20 and pair.dy.max() == 20
    assert len(set(zip(pair.dx.tolist(), pair.dy.tolist()))) == pair.cases


def test_ground_truth_matches_the_per_offset_definition(sprite_shapes):
    for a in sprite_shapes:
        for b in sprite_shapes:
            pair = make_pair(a, b)
            for i in range(0, pair.cases, 37):
                assert pair.overlap[i] == mask_overlap_area(a.mask, b.mask, (int(pair.dx[i]), int(pair.dy[i])))


@settings(max_examples=40, deadline=None)
@given(arrays(bool, st.tuples(st.integers(1, 6), st.integers(1, 7))),
       arrays(bool, st.tuples(st.integers(1, 6), st.integers(1, 7))))
def test_overlap_counts_of_random_masks(a, b):
    counts = overlap_counts(a, b)
    hb, wb = b.shape
    for dy in range(-(hb - 1), a.shape[0]):
        for dx in range(-(wb - 1), a.shape[1]):
            assert counts[dy + hb - 1, dx + wb - 1] == mask_overlap_area(a, b, (dx, dy))


def test_multicolor_pairs_01_are_opaque_and_double_width(sprite_shapes):
    gem = next(s for s in sprite_shapes if s.name == "mc_gem")
    assert gem.multicolor
    from retro.sprites import decode

    pairs = decode(gem.data, multicolor=True)
    assert (pairs == 1).any(), "the gem's rim uses the 01 pair"
    expected = np.repeat(pairs != 0, 2, axis=1)  # 01, 10, 11 opaque; each pair two pixels wide
    assert np.array_equal(gem.mask, expected)


def test_shape_without_opaque_pixel_is_refused():
    import pytest

    from retro.errors import InputError

    with pytest.raises(InputError, match="no opaque pixel"):
        Shape(name="empty", mask=np.zeros((21, 24), dtype=bool))
