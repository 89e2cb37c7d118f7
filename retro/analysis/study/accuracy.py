"""Confusion counts and rates: how often each method is wrong, per shape pair and overall.

Counting rules (also in docs/study.md):
- A case is one (shape pair, offset) of the corpus; every case weighs the same.
- A method's verdict v in [0, 1] on a case counts v as a reported hit and 1 - v as a reported miss
  (v is 0 or 1 except for the tile method, whose v is the fraction of the 64 cell alignments that
  report a hit, so its counts are expected values and need not be whole).
- TP = sum of v over colliding cases, FN = sum of 1 - v over colliding cases,
  FP = sum of v over non-colliding cases, TN = sum of 1 - v over non-colliding cases.
- FP rate = FP / (FP + TN) (of the cases that do not collide, the share reported as hits);
  FN rate = FN / (TP + FN) (of the real collisions, the share missed); accuracy = (TP + TN) / cases.
  A rate whose denominator is zero is undefined (NaN, an empty CSV cell).
- Overall figures pool the counts of all pairs (each case once), then divide: pairs with more
  cases weigh more, and with equal sprite sizes every pair has the same number of cases.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Confusion:
    tp: float
    fp: float
    tn: float
    fn: float

    @property
    def cases(self) -> float:
        return self.tp + self.fp + self.tn + self.fn

    @property
    def fp_rate(self) -> float:
        negatives = self.fp + self.tn
        return self.fp / negatives if negatives else math.nan

    @property
    def fn_rate(self) -> float:
        positives = self.tp + self.fn
        return self.fn / positives if positives else math.nan

    @property
    def accuracy(self) -> float:
        return (self.tp + self.tn) / self.cases if self.cases else math.nan

    def __add__(self, other: "Confusion") -> "Confusion":
        return Confusion(self.tp + other.tp, self.fp + other.fp, self.tn + other.tn, self.fn + other.fn)


ZERO = Confusion(0.0, 0.0, 0.0, 0.0)


def confusion(verdict: np.ndarray, truth: np.ndarray) -> Confusion:
    """Counts for one method on one pair (verdict in [0, 1] per case, truth bool per case)."""
    v = np.asarray(verdict, dtype=float)
    t = np.asarray(truth, dtype=bool)
    if v.shape != t.shape:
        raise ValueError(f"verdict has {v.shape} cases, truth {t.shape}")
    if v.size and (v.min() < 0 or v.max() > 1):
        raise ValueError("verdict values must lie in [0, 1]")
    return Confusion(tp=float(v[t].sum()), fn=float((1 - v[t]).sum()),
                     fp=float(v[~t].sum()), tn=float((1 - v[~t]).sum()))


def pooled(items: list[Confusion]) -> Confusion:
    total = ZERO
    for item in items:
        total = total + item
    return total
