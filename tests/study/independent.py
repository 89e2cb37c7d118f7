"""The study's rules computed a second way, in plain Python, for the tests to compare against.

Nothing here calls the study's code: boxes come from loops over the pixels, overlaps from interval
lengths and pixel sets, circles from a search that grows the radius one pixel at a time, tile cells
from brute force over the 64 alignments, hulls from shapely. A change of a rule in the study (a
touching box or a tangent circle counted as a hit, another circle fit, another cell rule) makes the
study disagree with these.
"""

from __future__ import annotations

import math

import numpy as np

Offsets = list[tuple[int, int]]


def pixels(mask: np.ndarray) -> set[tuple[int, int]]:
    """The opaque pixels as (x, y)."""
    return {(x, y) for y, row in enumerate(mask.tolist()) for x, on in enumerate(row) if on}


def bounds(mask: np.ndarray) -> tuple[int, int, int, int]:
    """Tight box (x0, y0, x1, y1), x1/y1 one past the last opaque column/row."""
    found = pixels(mask)
    xs, ys = [x for x, _ in found], [y for _, y in found]
    return min(xs), min(ys), max(xs) + 1, max(ys) + 1


def shared(a0: int, a1: int, b0: int, b1: int) -> int:
    """How many pixel columns [a0, a1) and [b0, b1) have in common."""
    return max(0, min(a1, b1) - max(a0, b0))


def box_hits(a: tuple, b: tuple, offsets: Offsets) -> list[bool]:
    """Boxes share at least one pixel (boxes that only touch share none)."""
    return [shared(a[0], a[2], b[0] + dx, b[2] + dx) > 0 and shared(a[1], a[3], b[1] + dy, b[3] + dy) > 0
            for dx, dy in offsets]


def smallest_circle(mask: np.ndarray, tangent_inside: bool = False) -> tuple[int, int, int]:
    """(cx, cy, r): among the integer centres from floor(mid) - 1 to ceil(mid) + 1 around the tight
    box's middle pixel, the one needing the smallest integer radius that has every opaque pixel
    strictly inside (or inside or on, with `tangent_inside`); ties go to the smallest (cx, cy)."""
    x0, y0, x1, y1 = bounds(mask)
    mid_x, mid_y = (x0 + x1 - 1) / 2, (y0 + y1 - 1) / 2
    found = pixels(mask)
    best = []
    for cx in range(math.floor(mid_x) - 1, math.ceil(mid_x) + 2):
        for cy in range(math.floor(mid_y) - 1, math.ceil(mid_y) + 2):
            r = 0
            while not all((x - cx) ** 2 + (y - cy) ** 2 <= r * r if tangent_inside else
                          (x - cx) ** 2 + (y - cy) ** 2 < r * r for x, y in found):
                r += 1
            best.append((r, cx, cy))
    r, cx, cy = min(best)
    return cx, cy, r


def circle_hits(a: tuple, b: tuple, offsets: Offsets, tangent_hits: bool = False) -> list[bool]:
    (ax, ay, ar), (bx, by, br) = a, b
    out = []
    for dx, dy in offsets:
        d2, reach = (bx + dx - ax) ** 2 + (by + dy - ay) ** 2, (ar + br) ** 2
        out.append(d2 <= reach if tangent_hits else d2 < reach)
    return out


def tangent_offsets(a: tuple, b: tuple, offsets: Offsets) -> list[tuple[int, int]]:
    (ax, ay, ar), (bx, by, br) = a, b
    return [(dx, dy) for dx, dy in offsets if (bx + dx - ax) ** 2 + (by + dy - ay) ** 2 == (ar + br) ** 2]


def pixel_hits(mask_a: np.ndarray, mask_b: np.ndarray, offsets: Offsets) -> list[bool]:
    pa, pb = pixels(mask_a), pixels(mask_b)
    return [any((x + dx, y + dy) in pa for x, y in pb) for dx, dy in offsets]


def cells(x0: int, y0: int, x1: int, y1: int) -> set[tuple[int, int]]:
    """The 8x8 cells (column, row) that the pixels x0..x1-1, y0..y1-1 fall in."""
    return {(cx, cy) for cx in range(x0 // 8, (x1 - 1) // 8 + 1) for cy in range(y0 // 8, (y1 - 1) // 8 + 1)}


def tile_shares(a: tuple, b: tuple, offsets: Offsets) -> list[float]:
    """Share of the 64 placements on the 8x8 grid in which the cells under box a meet those under b."""
    out = []
    for dx, dy in offsets:
        hits = sum(bool(cells(ox + a[0], oy + a[1], ox + a[2], oy + a[3])
                        & cells(ox + dx + b[0], oy + dy + b[1], ox + dx + b[2], oy + dy + b[3]))
                   for ox in range(8) for oy in range(8))
        out.append(hits / 64)
    return out


def hull_hits(mask_a: np.ndarray, mask_b: np.ndarray, offsets: Offsets) -> list[bool]:
    """shapely: the convex hulls of the opaque pixel squares overlap with a positive area."""
    from shapely import affinity
    from shapely.geometry import MultiPoint

    def hull(mask):
        return MultiPoint([(x + cx, y + cy) for x, y in pixels(mask) for cx in (0, 1) for cy in (0, 1)]).convex_hull

    ha, hb = hull(mask_a), hull(mask_b)
    return [ha.intersection(affinity.translate(hb, dx, dy)).area > 0 for dx, dy in offsets]


def all_offsets(mask_a: np.ndarray, mask_b: np.ndarray) -> Offsets:
    """Every offset where the two sprite boxes share a pixel, rows of dy, dx increasing."""
    (ha, wa), (hb, wb) = mask_a.shape, mask_b.shape
    return [(dx, dy) for dy in range(-(hb - 1), ha) for dx in range(-(wb - 1), wa)]


def counts(verdicts: list[float], truth: list[bool]) -> tuple[float, float, float, float]:
    """(TP, FP, TN, FN) with a verdict v counting v as a hit and 1 - v as a miss."""
    tp = sum(v for v, t in zip(verdicts, truth) if t)
    fn = sum(1 - v for v, t in zip(verdicts, truth) if t)
    fp = sum(v for v, t in zip(verdicts, truth) if not t)
    tn = sum(1 - v for v, t in zip(verdicts, truth) if not t)
    return tp, fp, tn, fn
