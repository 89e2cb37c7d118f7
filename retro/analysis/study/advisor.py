"""`retro advise`: the cheapest method (in 6502 cycles) that meets an accuracy target on a scene's shapes.

The scene's enabled sprites give the shapes (multicolor and expansion as the scene sets them). Every
unordered pair of enabled sprites is one shape pair of the study's corpus (all offsets where their
boxes meet); identical shape pairs are evaluated once and weighted by how many sprite pairs they
stand for. Accuracy is pooled over those cases (the counting rules of accuracy.py). Cycles are
measured in the emulator on the same pairs.

A method qualifies when its accuracy is at least the target, it has a 6502 cost and it can serve
the scene (`Method.advice_note`: the hardware latch only with exactly two enabled sprites, since with
more its bits cannot say which pair collided; see the stability study's latch pitfalls). SAT has no
6502 routine and is listed only. A user's methods (`--method FILE.toml`) are compared alongside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations

from retro.analysis.study.accuracy import Confusion, pooled
from retro.analysis.study.corpus import Shape
from retro.analysis.study.costs import CycleStats
from retro.analysis.study.evaluate import Progress, evaluate, quiet
from retro.analysis.study.methods import METHODS, Method
from retro.errors import InputError

ADVICE_COST_SAMPLES = 48


@dataclass(frozen=True)
class MethodFigures:
    key: str
    label: str
    counts: Confusion
    cycles: CycleStats
    qualifies: bool
    note: str


@dataclass(frozen=True)
class Advice:
    source: str
    sprites: list[int]
    sprite_pairs: int
    cases: float
    target: float
    figures: list[MethodFigures]  # cheapest first, unmeasured last
    chosen: MethodFigures | None
    runner_up: MethodFigures | None


def scene_shapes(path: str) -> list[tuple[int, Shape]]:
    """(sprite index, shape) for each enabled sprite of a VIC-II scene (at least two)."""
    from retro.analysis.study.sprites_io import scene_shapes as shapes_of_scene

    return shapes_of_scene(path, minimum=2)


def _shape_key(shape: Shape) -> tuple:
    return shape.data, shape.multicolor, shape.expand_x, shape.expand_y


def advise(path: str, target: float, workers: int | None = None, progress: Progress = quiet,
           samples: int = ADVICE_COST_SAMPLES, methods: tuple[Method, ...] = METHODS) -> Advice:
    if not 0 < target <= 1:
        raise InputError(f"--accuracy: {target} is outside (0, 1] (e.g. 0.99 for 99%)")
    from retro.analysis.study.cost_runs import measure_costs

    indexed = scene_shapes(path)
    # Identical shape pairs (same data and flags, either order) are one job with a weight.
    weights: dict[tuple, int] = {}
    jobs: dict[tuple, tuple[Shape, Shape]] = {}
    for (_, a), (_, b) in combinations(indexed, 2):
        key = tuple(sorted((_shape_key(a), _shape_key(b)), key=repr))
        weights[key] = weights.get(key, 0) + 1
        jobs.setdefault(key, (a, b))
    keys = list(jobs)
    table = evaluate([], methods, workers=workers, progress=progress, pair_list=[jobs[k] for k in keys])
    costs = measure_costs([], samples=samples, workers=workers, progress=progress, pair_list=[jobs[k] for k in keys],
                          methods=methods)
    sprite_count = len(indexed)
    figures = []
    for m in methods:
        counts = pooled([_scaled(p.counts[m.key], weights[k]) for p, k in zip(table.pairs, keys)])
        cycles = costs[m.key].overall if m.key in costs else CycleStats.of([])
        note = ""
        qualifies = counts.accuracy >= target
        unusable = m.advice_note(sprite_count)
        if m.host_only or cycles.samples == 0:
            qualifies, note = False, costs[m.key].counted if m.key in costs else "no 6502 cost"
        elif unusable:
            qualifies, note = False, unusable
        elif not qualifies:
            note = "below the target"
        elif m.prepare:
            note = f"per test; {m.prepare} once per object besides"
        figures.append(MethodFigures(m.key, m.label, counts, cycles, qualifies, note))
    figures.sort(key=lambda f: (math.isnan(f.cycles.mean), f.cycles.mean if not math.isnan(f.cycles.mean) else 0))
    eligible = [f for f in figures if f.qualifies]
    return Advice(source=str(path), sprites=[n for n, _ in indexed], sprite_pairs=sum(weights.values()),
                  cases=figures[0].counts.cases, target=target, figures=figures,
                  chosen=eligible[0] if eligible else None, runner_up=eligible[1] if len(eligible) > 1 else None)


def _scaled(c: Confusion, weight: int) -> Confusion:
    return Confusion(c.tp * weight, c.fp * weight, c.tn * weight, c.fn * weight)


def _describe(f: MethodFigures) -> str:
    c = f.counts
    cycles = ("no 6502 cost" if math.isnan(f.cycles.mean)
              else f"{f.cycles.mean:.1f} cycles per test ({f.cycles.min}-{f.cycles.max})")
    return (f"{f.label}: {cycles}, accuracy {100 * c.accuracy:.2f}% "
            f"(FP rate {100 * c.fp_rate:.2f}%, FN rate {100 * c.fn_rate:.2f}%)")


def advice_lines(advice: Advice) -> list[str]:
    lines = [f"scene {advice.source}: sprites {', '.join(map(str, advice.sprites))} enabled, "
             f"{advice.sprite_pairs} sprite pairs, {advice.cases:.0f} cases; target accuracy {100 * advice.target:.2f}%"]
    for f in advice.figures:
        mark = "ok " if f.qualifies else "-- "
        lines.append(f"  {mark}{_describe(f)}" + (f"  [{f.note}]" if f.note else ""))
    if advice.chosen is None:
        best = max(advice.figures, key=lambda f: f.counts.accuracy if not math.isnan(f.cycles.mean) else -1)
        lines.append(f"advice: no method with a 6502 cost meets {100 * advice.target:.2f}%; "
                     f"the most accurate is {_describe(best)}")
    else:
        lines.append(f"advice: {_describe(advice.chosen)}")
        lines.append(f"runner-up: {_describe(advice.runner_up)}" if advice.runner_up
                     else "runner-up: none (no other method meets the target)")
    return lines
