"""The Pareto front of (cycles, accuracy): the methods no other method beats on both at once."""

from __future__ import annotations

import math
from collections.abc import Sequence


def dominates(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """a = (cycles, accuracy) dominates b when it costs no more, is no less accurate, and is
    strictly better in at least one of the two."""
    return a[0] <= b[0] and a[1] >= b[1] and (a[0] < b[0] or a[1] > b[1])


def pareto_front(points: Sequence[tuple[float, float]]) -> list[bool]:
    """For each (cycles, accuracy) point, whether it is on the front. Points with an undefined
    coordinate (NaN: no 6502 cycles, e.g. SAT) are never on it and never dominate."""
    valid = [not (math.isnan(c) or math.isnan(a)) for c, a in points]
    return [valid[i] and not any(valid[j] and dominates(points[j], points[i]) for j in range(len(points)) if j != i)
            for i in range(len(points))]
