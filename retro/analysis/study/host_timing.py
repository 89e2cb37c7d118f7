"""Host microseconds per test of each method's Python reference (a secondary figure: the 6502
cycles are the primary cost). Median over repeated timings of the sampled cases, this host, one core."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import fitted_circle, full_box, pixel_hull, tight_box
from retro.analysis.study.methods import CELL, CIRCLE_TOUCHING_HITS

REPEATS = 5


def _time_per_call(calls: list[Callable[[], object]]) -> float:
    """Median over REPEATS of (time to run every call once) / number of calls, in microseconds."""
    runs = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        for call in calls:
            call()
        runs.append((time.perf_counter() - start) / len(calls) * 1e6)
    return statistics.median(runs)


def _cases(pair: Pair, indices: list[int]) -> list[tuple[int, int]]:
    return [(int(pair.dx[i]), int(pair.dy[i])) for i in indices]


def reference_calls(key: str, pair: Pair, indices: list[int]) -> list[Callable[[], object]]:
    """One zero-argument call per sampled case, running the method's Python reference."""
    from retro.geometry.aabb import aabb_overlap
    from retro.geometry.circle import circle_overlap
    from retro.geometry.masks import mask_overlap
    from retro.geometry.sat import sat

    cases = _cases(pair, indices)
    if key in ("box", "tight"):
        fit = full_box if key == "box" else tight_box
        ax0, ay0, ax1, ay1 = fit(pair.a.mask)
        bx0, by0, bx1, by1 = fit(pair.b.mask)
        return [lambda dx=dx, dy=dy: aabb_overlap((ax0, ay0), (ax1, ay1), (bx0 + dx, by0 + dy), (bx1 + dx, by1 + dy))
                for dx, dy in cases]
    if key == "circle":
        ca, cb = fitted_circle(pair.a.mask, CIRCLE_TOUCHING_HITS), fitted_circle(pair.b.mask, CIRCLE_TOUCHING_HITS)
        return [lambda dx=dx, dy=dy: circle_overlap((ca.cx, ca.cy), ca.r, (cb.cx + dx, cb.cy + dy), cb.r)
                for dx, dy in cases]
    if key == "tile":
        ax0, ay0, ax1, ay1 = tight_box(pair.a.mask)
        bx0, by0, bx1, by1 = tight_box(pair.b.mask)

        def cells_meet(dx: int, dy: int) -> bool:
            return (ax0 // CELL <= (bx1 - 1 + dx) // CELL and (bx0 + dx) // CELL <= (ax1 - 1) // CELL
                    and ay0 // CELL <= (by1 - 1 + dy) // CELL and (by0 + dy) // CELL <= (ay1 - 1) // CELL)
        return [lambda dx=dx, dy=dy: cells_meet(dx, dy) for dx, dy in cases]
    if key == "pixel":
        return [lambda dx=dx, dy=dy: mask_overlap(pair.a.mask, pair.b.mask, (dx, dy)) for dx, dy in cases]
    if key == "sat":
        hull_a, hull_b = pixel_hull(pair.a.mask), pixel_hull(pair.b.mask)
        return [lambda dx=dx, dy=dy: sat(hull_a, [(x + dx, y + dy) for x, y in hull_b]) for dx, dy in cases]
    if key == "latch":
        from retro.analysis.study.latch import frame_latch

        return [lambda dx=dx, dy=dy: frame_latch(pair, dx, dy) for dx, dy in cases]
    raise KeyError(key)


def host_microseconds(key: str, pairs: list[Pair], samples: int) -> float:
    calls: list[Callable[[], object]] = []
    for pair in pairs:
        step = max(1, pair.cases // samples)
        calls += reference_calls(key, pair, list(range(0, pair.cases, step))[:samples])
    return _time_per_call(calls) if calls else float("nan")
