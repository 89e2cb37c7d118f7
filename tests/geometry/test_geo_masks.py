"""Pixel masks against a direct per-pixel loop."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from retro.geometry import (
    mask_bounds,
    mask_from_rows,
    mask_overlap,
    mask_overlap_area,
    mask_overlap_mask,
)


def per_pixel(a: np.ndarray, b: np.ndarray, dx: int, dy: int) -> np.ndarray:
    """The definition: pixel (x, y) of a is hit when b's pixel (x - dx, y - dy) exists and is set."""
    out = np.zeros_like(a)
    for y in range(a.shape[0]):
        for x in range(a.shape[1]):
            bx, by = x - dx, y - dy
            if a[y, x] and 0 <= by < b.shape[0] and 0 <= bx < b.shape[1] and b[by, bx]:
                out[y, x] = True
    return out


masks = arrays(bool, st.tuples(st.integers(1, 9), st.integers(1, 9)))


@given(masks, masks, st.integers(-11, 11), st.integers(-11, 11))
@settings(max_examples=300, deadline=None)
def test_masks_match_per_pixel_loop(a, b, dx, dy):
    expected = per_pixel(a, b, dx, dy)
    assert np.array_equal(mask_overlap_mask(a, b, (dx, dy)), expected)
    assert mask_overlap_area(a, b, (dx, dy)) == int(expected.sum())
    assert mask_overlap(a, b, (dx, dy)) == bool(expected.any())
    # Symmetry: b seen from a at +offset is a seen from b at -offset.
    assert mask_overlap_area(b, a, (-dx, -dy)) == int(expected.sum())


def test_sprite_by_hand():
    ship = mask_from_rows(["..#..",
                           ".###.",
                           "#####"])
    bullet = mask_from_rows(["#"])
    assert mask_overlap(ship, bullet, (2, 0))        # the nose
    assert not mask_overlap(ship, bullet, (1, 0))    # the empty corner beside it
    assert not mask_overlap(ship, bullet, (5, 2))    # just right of the ship
    assert mask_overlap_area(ship, ship, (0, 1)) == 3 + 1  # row 1 under row 0, row 2 under row 1
    assert mask_bounds(ship) == ((0, 0), (5, 3))
    assert mask_bounds(np.zeros((2, 2), bool)) is None
