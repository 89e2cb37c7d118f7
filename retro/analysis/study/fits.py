"""What each method keeps of a shape: its boxes, its fitted circle, its convex hull, its bit rows.

Pixel (x, y) is the unit square [x, x+1) x [y, y+1); for circles, a pixel is represented by the
integer point (x, y), so two sprites share a pixel exactly when those points coincide.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from retro.geometry import convex_hull
from retro.geometry.masks import mask_bounds

Box = tuple[int, int, int, int]  # x0, y0, x1, y1 with x1, y1 exclusive (half-open pixel box)


def full_box(mask: np.ndarray) -> Box:
    """The whole sprite box, transparent border included: what a game gets with no hitbox data."""
    return 0, 0, int(mask.shape[1]), int(mask.shape[0])


def tight_box(mask: np.ndarray) -> Box:
    """The bounding box of the opaque pixels (the usual hand-tuned hitbox, at its tightest)."""
    bounds = mask_bounds(mask)
    if bounds is None:
        raise ValueError("tight_box: mask has no opaque pixel")
    (x0, y0), (x1, y1) = bounds
    return x0, y0, x1, y1


@dataclass(frozen=True)
class Circle:
    cx: int
    cy: int
    r: int


def fitted_circle(mask: np.ndarray, touching_hits: bool = False) -> Circle:
    """The smallest integer circle around the opaque pixels, with an integer centre.

    The centre is chosen among the integer points within one pixel of the tight box's centre to
    minimise the radius; the radius is the smallest integer that puts every opaque pixel's point
    strictly inside (`touching_hits=False`, for a test `d^2 < (r1+r2)^2`) or inside or on the
    circle (`touching_hits=True`, for `d^2 <= (r1+r2)^2`). Either way, a shared pixel p gives
    |c1-c2| <= |c1-p| + |p-c2| and so a hit: a fitted circle never misses a real collision.
    """
    ys, xs = np.nonzero(mask)
    x0, y0, x1, y1 = tight_box(mask)
    mid_x, mid_y = (x0 + x1 - 1) / 2, (y0 + y1 - 1) / 2
    best: Circle | None = None
    for cx in range(math.floor(mid_x) - 1, math.ceil(mid_x) + 2):
        for cy in range(math.floor(mid_y) - 1, math.ceil(mid_y) + 2):
            far2 = int(((xs - cx) ** 2 + (ys - cy) ** 2).max())
            r = math.isqrt(far2)
            if touching_hits:
                r += r * r < far2
            else:
                r += 1  # r*r > far2 whether or not far2 is a perfect square
            if best is None or r < best.r:
                best = Circle(cx, cy, r)
    assert best is not None
    return best


def pixel_hull(mask: np.ndarray) -> list[tuple[int, int]]:
    """Convex hull of the opaque pixels as unit squares (all four corners of every pixel).

    Two sprites sharing a pixel have hulls whose interiors share that pixel's square, so SAT on
    these hulls never misses a collision; it only adds the concave parts (a ring's hole) as area.
    """
    ys, xs = np.nonzero(mask)
    corners = np.concatenate([np.stack([xs + ox, ys + oy], axis=1) for ox in (0, 1) for oy in (0, 1)])
    return convex_hull(corners)


def bit_rows(mask: np.ndarray) -> list[int]:
    """Each row of the mask as an integer, leftmost pixel in the most significant bit (the sprite
    data layout the 6502 pixel routine ANDs)."""
    width = mask.shape[1]
    weights = [1 << (width - 1 - i) for i in range(width)]
    return [sum(w for w, on in zip(weights, row) if on) for row in mask.tolist()]
