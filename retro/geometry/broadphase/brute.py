"""Brute force: test every pair. The reference every other broad phase must agree with."""

from __future__ import annotations

import numpy as np

from retro.geometry.broadphase.boxes import BoxSet, PairResult


def brute_force_pairs(boxes: BoxSet) -> PairResult:
    """All N(N-1)/2 pairs, one at a time, in plain Python (the same style as the other methods)."""
    x0, y0, x1, y1, layers, masks = boxes.columns()
    n = len(x0)
    pairs = []
    for i in range(n):
        ax0, ay0, ax1, ay1, la, ma = x0[i], y0[i], x1[i], y1[i], layers[i], masks[i]
        for j in range(i + 1, n):
            if (ax0 < x1[j] and x0[j] < ax1 and ay0 < y1[j] and y0[j] < ay1
                    and la & masks[j] and layers[j] & ma):
                pairs.append((i, j))
    return PairResult(pairs, n * (n - 1) // 2)


def brute_force_pairs_numpy(boxes: BoxSet) -> PairResult:
    """All pairs, one row at a time vectorised with numpy: the same tests, far less interpreter
    overhead per test. Shows how much of a method's speed is the algorithm and how much is Python."""
    lo, hi, layers, masks = boxes.mins, boxes.maxs, boxes.layers, boxes.masks
    n = len(lo)
    pairs: list[tuple[int, int]] = []
    for i in range(n - 1):
        rest = slice(i + 1, n)
        hit = ((lo[i, 0] < hi[rest, 0]) & (lo[rest, 0] < hi[i, 0]) & (lo[i, 1] < hi[rest, 1])
               & (lo[rest, 1] < hi[i, 1]) & ((layers[i] & masks[rest]) != 0) & ((layers[rest] & masks[i]) != 0))
        pairs.extend((i, int(j)) for j in np.nonzero(hit)[0] + i + 1)
    return PairResult(pairs, n * (n - 1) // 2)
