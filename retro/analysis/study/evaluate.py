"""Run every method on every pair of the corpus (in parallel over pairs) and count its errors."""

from __future__ import annotations

from dataclasses import dataclass

from retro.analysis.study.accuracy import Confusion, confusion, pooled
from retro.analysis.study.corpus import Shape, make_pair
from retro.analysis.study.methods import METHODS, Method
from retro.progress import Progress, quiet
from retro.workers import Workers, only, run_in_order


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


def evaluate(shapes: list[Shape], methods: tuple[Method, ...] = METHODS, workers: Workers | int | None = None,
             progress: Progress = quiet, pair_list: list[tuple[Shape, Shape]] | None = None) -> AccuracyTable:
    """Confusion counts of each method on each unordered pair of shapes (self-pairs included), the pairs
    over `workers` (retro.workers) when more than one."""
    from itertools import combinations_with_replacement

    jobs = pair_list if pair_list is not None else list(combinations_with_replacement(shapes, 2))
    methods = tuple(methods)
    results: list[PairResult] = []

    def report(result: PairResult) -> None:
        results.append(result)
        progress(f"accuracy: pair {len(results)}/{len(jobs)} {result.pair}")
    run_in_order(_evaluate_pair, ((a, b, methods) for a, b in jobs), only(workers, len(jobs) > 1), report)
    return AccuracyTable(methods=methods, pairs=results)
