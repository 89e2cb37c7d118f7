"""Pixel-perfect collision of bit masks (sprites are masks too), vectorised with numpy.

A mask is a 2-D numpy bool array indexed [y, x] (row 0 at the top, as on screen). Offsets are
integer (dx, dy): the position of mask b's top-left pixel relative to mask a's top-left pixel, so
pixel (x, y) of b lands on pixel (x + dx, y + dy) of a. Two masks collide when at least one pixel
is set in both; the pixels are the cells themselves, so there is no "touching" case.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence

import numpy as np

from retro.errors import InputError


def as_mask(mask: object, name: str = "mask") -> np.ndarray:
    """A 2-D bool array. Accepts bool arrays, or integer arrays holding only 0 and 1."""
    array = np.asarray(mask)
    if array.ndim != 2:
        raise InputError(f"{name}: expected a 2-D mask (rows of pixels), got {array.ndim} dimensions")
    if array.dtype == bool:
        return array
    if not np.issubdtype(array.dtype, np.integer) or array.size and not np.isin(array, (0, 1)).all():
        raise InputError(f"{name}: expected a bool mask (or 0/1 integers), got dtype {array.dtype}")
    return array.astype(bool)


def mask_from_rows(rows: Sequence[str], on: str = "#") -> np.ndarray:
    """Build a mask from strings, one per row: `on` characters are set, anything else clear."""
    if not rows:
        raise InputError("rows: need at least one row")
    width = len(rows[0])
    for i, row in enumerate(rows):
        if len(row) != width:
            raise InputError(f"rows[{i}]: length {len(row)} differs from row 0 length {width}")
    return np.array([[c == on for c in row] for row in rows], dtype=bool)


def _offset(offset: object) -> tuple[int, int]:
    try:
        dx, dy = offset  # type: ignore[misc]
    except (TypeError, ValueError):
        raise InputError(f"offset: expected an integer (dx, dy) pair, got {offset!r}") from None
    for name, v in (("offset.dx", dx), ("offset.dy", dy)):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral):
            raise InputError(f"{name}: must be an integer pixel offset, got {v!r}")
    return int(dx), int(dy)


def _windows(a: np.ndarray, b: np.ndarray, dx: int, dy: int) -> tuple[slice, slice, slice, slice] | None:
    """Row/column slices of a and b covering their common rectangle, or None if it is empty."""
    ha, wa = a.shape
    hb, wb = b.shape
    x0, x1 = max(0, dx), min(wa, dx + wb)
    y0, y1 = max(0, dy), min(ha, dy + hb)
    if x0 >= x1 or y0 >= y1:
        return None
    return slice(y0, y1), slice(x0, x1), slice(y0 - dy, y1 - dy), slice(x0 - dx, x1 - dx)


def mask_overlap_mask(a: object, b: object, offset: object) -> np.ndarray:
    """Bool mask of a's shape: the pixels of a that are also set in b placed at `offset`."""
    ma, mb = as_mask(a, "a"), as_mask(b, "b")
    dx, dy = _offset(offset)
    out = np.zeros_like(ma)
    w = _windows(ma, mb, dx, dy)
    if w is not None:
        ay, ax, by, bx = w
        out[ay, ax] = ma[ay, ax] & mb[by, bx]
    return out


def mask_overlap_area(a: object, b: object, offset: object) -> int:
    """Number of pixels set in both masks with b at `offset`."""
    ma, mb = as_mask(a, "a"), as_mask(b, "b")
    w = _windows(ma, mb, *_offset(offset))
    if w is None:
        return 0
    ay, ax, by, bx = w
    return int(np.count_nonzero(ma[ay, ax] & mb[by, bx]))


def mask_overlap(a: object, b: object, offset: object) -> bool:
    """True when at least one pixel is set in both masks with b at `offset`."""
    ma, mb = as_mask(a, "a"), as_mask(b, "b")
    w = _windows(ma, mb, *_offset(offset))
    if w is None:
        return False
    ay, ax, by, bx = w
    return bool(np.any(ma[ay, ax] & mb[by, bx]))


def mask_bounds(mask: object) -> tuple[tuple[int, int], tuple[int, int]] | None:
    """Tight (min, max) box of the set pixels with max exclusive (x + 1, y + 1), or None if empty.
    This is the box to pass to aabb_overlap for a cheap pre-test."""
    m = as_mask(mask)
    ys, xs = np.nonzero(m)
    if len(xs) == 0:
        return None
    return (int(xs.min()), int(ys.min())), (int(xs.max()) + 1, int(ys.max()) + 1)
