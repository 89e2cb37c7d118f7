"""Sort and sweep (sweep and prune) on one axis: sort the boxes by their minimum on that axis and
test each box only against the following boxes that start before it ends."""

from __future__ import annotations

import numpy as np

from retro.errors import InputError
from retro.geometry.broadphase.boxes import BoxSet, PairResult


def choose_axis(boxes: BoxSet) -> int:
    """The axis (0 = x, 1 = y) along which the box centres spread most: fewer overlaps there."""
    if len(boxes) < 2:
        return 0
    centres = (boxes.mins + boxes.maxs) / 2
    spread = centres.var(axis=0)
    return int(spread[1] > spread[0])


def sweep_and_prune_pairs(boxes: BoxSet, axis: int | None = None) -> PairResult:
    """Candidate pairs by sorting on `axis` (default: `choose_axis`)."""
    if axis is None:
        axis = choose_axis(boxes)
    if axis not in (0, 1):
        raise InputError(f"axis: must be 0 (x) or 1 (y), got {axis!r}")
    x0, y0, x1, y1, layers, masks = boxes.columns()
    starts, ends = (x0, x1) if axis == 0 else (y0, y1)
    order = np.argsort(boxes.mins[:, axis], kind="stable").tolist()
    n = len(order)
    tests = 0
    pairs = []
    for a in range(n):
        i = order[a]
        end = ends[i]
        for b in range(a + 1, n):
            j = order[b]
            if starts[j] >= end:
                break  # sorted by start: no later box can overlap i on this axis
            tests += 1
            if (x0[i] < x1[j] and x0[j] < x1[i] and y0[i] < y1[j] and y0[j] < y1[i]
                    and layers[i] & masks[j] and layers[j] & masks[i]):
                pairs.append((i, j) if i < j else (j, i))
    pairs.sort()
    return PairResult(pairs, tests)
