"""Uniform grid as a spatial hash: each box is listed in every cell it covers, and only boxes
sharing a cell are tested. The hash (a dict keyed by cell coordinates) makes the grid unbounded and
costs memory only for occupied cells."""

from __future__ import annotations

import math

import numpy as np

from retro.errors import InputError
from retro.geometry.broadphase.boxes import BoxSet, PairResult


def choose_cell_size(boxes: BoxSet) -> float:
    """Cell size from object size: the largest box extent, so every box covers at most 2 x 2
    cells; but if a few boxes are much larger than the typical one (over 4x the median extent),
    twice the median instead, so that the many small boxes are not lumped into huge cells."""
    if len(boxes) == 0:
        return 1.0
    extents = (boxes.maxs - boxes.mins).max(axis=1)
    largest, typical = float(extents.max()), float(np.median(extents))
    cell = largest if largest <= 4 * typical else 2 * typical
    return cell if cell > 0 else 1.0


def grid_pairs(boxes: BoxSet, cell_size: float | None = None) -> PairResult:
    """Candidate pairs via a uniform grid of square cells (default size: `choose_cell_size`)."""
    cell = choose_cell_size(boxes) if cell_size is None else float(cell_size)
    if not (math.isfinite(cell) and cell > 0):
        raise InputError(f"cell_size: must be a finite number > 0, got {cell_size}")
    x0, y0, x1, y1, layers, masks = boxes.columns()
    cells: dict[tuple[int, int], list[int]] = {}
    floor = math.floor
    for i in range(len(x0)):
        for cx in range(floor(x0[i] / cell), floor(x1[i] / cell) + 1):
            for cy in range(floor(y0[i] / cell), floor(y1[i] / cell) + 1):
                cells.setdefault((cx, cy), []).append(i)  # ascending i within each cell
    seen: set[tuple[int, int]] = set()
    pairs = []
    for members in cells.values():
        for a in range(len(members) - 1):
            i = members[a]
            for b in range(a + 1, len(members)):
                j = members[b]
                if (i, j) in seen:  # two boxes sharing several cells are tested once
                    continue
                seen.add((i, j))
                if (x0[i] < x1[j] and x0[j] < x1[i] and y0[i] < y1[j] and y0[j] < y1[i]
                        and layers[i] & masks[j] and layers[j] & masks[i]):
                    pairs.append((i, j))
    pairs.sort()
    return PairResult(pairs, len(seen))
