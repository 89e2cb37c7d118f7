"""Run every method on every pair of the corpus (in parallel over pairs) and count its errors."""

from __future__ import annotations

import os
from dataclasses import dataclass

from retro.analysis.study.accuracy import Confusion, confusion, pooled
from retro.analysis.study.corpus import Shape, make_pair
from retro.analysis.study.methods import METHODS, Method
from retro.progress import Progress, quiet
from retro.workers import worker_pool


@dataclass(frozen=True)
class PairResult:
    pair: str
    cases: int
    colliding: int
    counts: dict[str, Confusion]  # method key -> counts


@dataclass(frozen=True)
class AccuracyTable:
    methods: tuple[Method, ...]
    pairs: list[PairResult]

    def overall(self, key: str) -> Confusion:
        return pooled([p.counts[key] for p in self.pairs])

    @property
    def cases(self) -> int:
        return sum(p.cases for p in self.pairs)


def _evaluate_pair(a: Shape, b: Shape, methods: tuple[Method, ...]) -> PairResult:
    pair = make_pair(a, b)
    counts = {m.key: confusion(m.verdict(pair), pair.truth) for m in methods}
    return PairResult(pair=pair.name, cases=pair.cases, colliding=int(pair.truth.sum()), counts=counts)


def default_workers() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def evaluate(shapes: list[Shape], methods: tuple[Method, ...] = METHODS, workers: int | None = None,
             progress: Progress = quiet, pair_list: list[tuple[Shape, Shape]] | None = None) -> AccuracyTable:
    """Confusion counts of each method on each unordered pair of shapes (self-pairs included)."""
    from itertools import combinations_with_replacement

    jobs = pair_list if pair_list is not None else list(combinations_with_replacement(shapes, 2))
    methods = tuple(methods)
    workers = default_workers() if workers is None else workers
    results: list[PairResult] = []
    if workers <= 1 or len(jobs) <= 1:
        for i, (a, b) in enumerate(jobs, 1):
            results.append(_evaluate_pair(a, b, methods))
            progress(f"accuracy: pair {i}/{len(jobs)} {a.name}+{b.name}")
    else:
        with worker_pool(workers) as pool:
            futures = [pool.submit(_evaluate_pair, a, b, methods) for a, b in jobs]
            for i, future in enumerate(futures, 1):
                results.append(future.result())
                progress(f"accuracy: pair {i}/{len(jobs)} {results[-1].pair}")
    return AccuracyTable(methods=methods, pairs=results)
