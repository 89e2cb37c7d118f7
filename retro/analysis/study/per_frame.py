"""Cost per frame: the 6502 cycles a game pays each frame to test N objects, per method and broad phase.

    frame(N) = prepare calls x the prepare routine's cycles
             + the broad phase's own cycles (its loops and one JSR per candidate pair)
             + candidate pairs x the method's cycles per test (its RTS included)

Every term is measured, none estimated:
- **per test**: the method's routine on the corpus (cost_runs.measure_costs: every case of every
  pair in `retro chart`), mean for the typical frame, maximum for the worst one;
- **prepare**: the method's `*_prepare` routine through `retro check` (its cases; every call's
  outputs checked against its reference), mean and maximum; run once per object (`prepare_per =
  "object"`) or once per pair of object kinds present (`"kind_pair"`, the radius sums of circle_r,
  charged every frame although a game may keep them longer);
- **broad phase and candidates**: the drivers of asm/broad/broad_phase.s run on generated object
  layouts (broad_phase.py): brute force (every pair) and sort-and-sweep along X, whose candidates are
  counted by the 6502 itself and checked against a Python count; the intervals are each method's
  `x_extent`, so a method with a wider hit shape gets more candidates.

Not counted: moving each pair's values into the test routine's registers and zero page (how a game
stores its objects decides it), and the game's other work. A method whose one call answers for the
whole frame (`once_per_frame`: the VIC-II latch read) costs that call whatever N is, up to its
`max_objects`; it does not say which pair collided.

Budgets: a PAL C64 frame (retro.chips.vic.constants.PAL.frame_cycles) and BUDGET_LINES raster lines
of it; `retro advise --objects N` uses the scene's own chip and standard.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction

from retro.analysis.study.broad_phase import (
    BRUTE,
    MAX_OBJECTS,
    PHASE_LABELS,
    PHASES,
    SORT_X,
    BroadSample,
    brute_sample,
    sweep_samples,
)
from retro.analysis.study.corpus import Shape
from retro.analysis.study.costs import CycleStats
from retro.progress import Progress, quiet
from retro.analysis.study.methods.base import KIND_PAIR, Method
from retro.chips.vic import constants as vic
from retro.errors import RunError
from retro.workers import Workers, only, run_in_order

BUDGET_LINES = 20  # "a typical budget of 20 raster lines"
OBJECT_COUNTS = tuple(range(1, MAX_OBJECTS + 1))
LAYOUTS = 3  # generated layouts per object count ...
FRAMES = 4  # ... each measured over this many frames after the first
REDUCED_LAYOUTS, REDUCED_FRAMES = 1, 2
PHASE_CROSSING = "phases"  # Crossing.phase of a method's two broad phases against each other
ONCE = "once"  # the phase of a method called once per frame (no broad phase)
PHASE_LABELS = {**PHASE_LABELS, ONCE: "one call a frame (hardware)"}


@dataclass(frozen=True)
class Budget:
    label: str  # the machine and standard, e.g. "C64 PAL (6569)"
    frame_cycles: Fraction  # CPU cycles of one frame
    line_cycles: Fraction  # CPU cycles of one raster line
    lines: int = BUDGET_LINES

    @property
    def lines_cycles(self) -> Fraction:
        return self.line_cycles * self.lines


def c64_budget(video: vic.Video = vic.PAL) -> Budget:
    return Budget(f"C64 {video.name.upper()} ({video.chip})", Fraction(video.frame_cycles), Fraction(video.cycles_per_line))


def nes_budget(standard) -> Budget:
    """An NES standard (retro.chips.ppu.constants.NTSC/PAL): CPU cycles from PPU dots."""
    from retro.chips.ppu.constants import DOTS_PER_LINE

    per_line = Fraction(DOTS_PER_LINE) / standard.dots_per_cpu_cycle
    return Budget(f"NES {standard.name.upper()}", per_line * standard.lines_per_frame, per_line)


PAL_BUDGET = c64_budget(vic.PAL)


# ---- the measured parts -------------------------------------------------------------------------

def prepare_costs(methods: Sequence[Method], engine: str = "auto") -> dict[str, CycleStats]:
    """{prepare spec: its cycles per call}, from `retro check`'s bounded run of the spec (every call's
    outputs checked against the spec's reference: a mismatch stops the study)."""
    from retro.analysis.check import check_routine
    from retro.routines.registry import spec_path

    out: dict[str, CycleStats] = {}
    for spec in dict.fromkeys(m.prepare for m in methods if m.prepare):
        check = check_routine(str(spec_path(spec)), jobs=1, engine=engine)
        t = check.totals
        if check.mismatches or t.run_errors or not t.cycles_count:
            raise RunError(f"{spec}: the preparation routine fails its check ({check.mismatches} mismatches): "
                           f"run `retro check {spec}`")
        out[spec] = CycleStats(mean=check.mean, min=t.cycles_min, max=t.cycles_max, samples=t.cycles_count)
    return out


Extents = tuple[tuple[int, int], ...]  # per shape of the layouts: (lo, hi) along X


def method_extents(m: Method, shapes: Sequence[Shape]) -> Extents:
    return tuple(tuple(int(v) for v in m.x_extent(s)) for s in shapes)


@dataclass(frozen=True)
class BroadTable:
    """Measured broad phases: per object count, brute force; per (extents, object count), the sweep's
    samples over the layouts and frames."""

    brute: dict[int, BroadSample]
    sweep: dict[tuple[Extents, int], list[BroadSample]]
    layouts: int
    frames: int

    def samples(self, phase: str, extents: Extents, n: int) -> list[BroadSample]:
        return [self.brute[n]] if phase == BRUTE else self.sweep[(extents, n)]


def _sweep_task(extents: Extents, n: int, layouts: int, frames: int) -> tuple[Extents, int, list[BroadSample]]:
    return extents, n, sweep_samples(extents, n, layouts, frames)


def measure_broad(extent_sets: Sequence[Extents], counts: Sequence[int], layouts: int = LAYOUTS, frames: int = FRAMES,
                  workers: Workers | int | None = None, progress: Progress = quiet) -> BroadTable:
    """Both drivers for every object count; the sweep on each distinct set of extents, over `workers`
    (retro.workers) when more than one."""
    brute = {n: brute_sample(n) for n in counts}
    tasks = [(e, n) for e in dict.fromkeys(extent_sets) for n in counts]
    sweep: dict[tuple[Extents, int], list[BroadSample]] = {}

    def report(result: tuple[Extents, int, list[BroadSample]]) -> None:
        e, n, samples = result
        sweep[(e, n)] = samples
        if len(sweep) % len(counts) == 0:
            progress(f"per frame: sort and sweep measured for {len(counts)} object counts "
                     f"({len(sweep) // len(counts)} of {len(tasks) // len(counts)} hitbox widths)")
    run_in_order(_sweep_task, ((e, n, layouts, frames) for e, n in tasks), only(workers, len(tasks) > 1), report)
    return BroadTable(brute=brute, sweep=sweep, layouts=layouts, frames=frames)


# ---- the model ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class FrameRow:
    method: str
    label: str
    phase: str  # BRUTE, SORT_X, or ONCE
    objects: int
    prepare_calls: int
    prepare_cycles: float  # all prepare calls of the frame, mean
    broad_cycles: float  # the driver's own cycles, mean over the layouts
    candidates: float  # pairs tested, mean over the layouts
    candidates_max: int
    test_cycles: float  # per test, mean
    test_cycles_max: int
    frame_cycles: float  # the typical frame: means throughout
    frame_worst: float  # maxima: the dearest prepare call, per layout the dearest test, the dearest layout
    frame_share: float  # frame_cycles / the budget's frame

    @property
    def software(self) -> bool:
        return self.phase != ONCE


def prepare_calls(m: Method, n: int, kinds: int) -> int:
    if not m.prepare:
        return 0
    if m.prepare_per == KIND_PAIR:
        present = min(n, kinds)
        return present * (present + 1) // 2
    return n


def frame_costs(m: Method, test: CycleStats, prepare: CycleStats | None, samples: list[BroadSample], n: int,
                kinds: int) -> tuple[int, float, float, float, int, float, float]:
    """(prepare calls, their cycles, the broad phase's cycles, candidates (mean, most), the typical
    frame, the worst frame), over the layouts' samples."""
    calls = prepare_calls(m, n, kinds)
    prep_mean = calls * prepare.mean if calls else 0.0
    prep_max = calls * prepare.max if calls else 0
    broad = sum(s.cycles for s in samples) / len(samples)
    candidates = sum(s.candidates for s in samples) / len(samples)
    typical = prep_mean + broad + candidates * test.mean
    worst = prep_max + max(s.cycles + s.candidates * test.max for s in samples)
    return calls, prep_mean, broad, candidates, max(s.candidates for s in samples), typical, worst


def frame_rows(methods: Sequence[Method], tests: dict[str, CycleStats], prepares: dict[str, CycleStats],
               shapes: Sequence[Shape], broad: BroadTable, counts: Sequence[int],
               budget: Budget = PAL_BUDGET) -> list[FrameRow]:
    """Every method with measured cycles, every phase, every object count."""
    rows = []
    frame = float(budget.frame_cycles)
    for m in methods:
        test = tests.get(m.key)
        if m.host_only or test is None or test.samples == 0:
            continue
        if m.once_per_frame:
            for n in counts:
                if m.max_objects is None or n <= m.max_objects:
                    rows.append(FrameRow(m.key, m.label, ONCE, n, 0, 0.0, 0.0, 0.0, 0, test.mean, test.max, test.mean,
                                         float(test.max), test.mean / frame))
            continue
        extents = method_extents(m, shapes)
        prepare = prepares.get(m.prepare) if m.prepare else None
        for phase in PHASES:
            for n in counts:
                calls, prep, cycles, candidates, most, typical, worst = frame_costs(
                    m, test, prepare, broad.samples(phase, extents, n), n, len(shapes))
                rows.append(FrameRow(m.key, m.label, phase, n, calls, prep, cycles, candidates, most, test.mean,
                                     test.max, typical, float(worst), typical / frame))
    return rows


# ---- what the curves say ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Crossing:
    """From `objects` on, `cheaper` costs less per frame than `dearer` (typical frames): at objects - 1
    it cost as much or more."""

    phase: str  # the panel: BRUTE or SORT_X; PHASE_CROSSING for a method's sweep against its brute force
    objects: int
    cheaper: str  # a method key (with PHASE_CROSSING: the same key twice; `sweep_wins` says which phase)
    dearer: str
    sweep_wins: bool = False  # PHASE_CROSSING: from `objects` on the sweep is the cheaper phase


def _curve(rows: list[FrameRow], method: str, phase: str) -> dict[int, float]:
    return {r.objects: r.frame_cycles for r in rows if r.method == method and r.phase == phase}


def _sign(value: float) -> int:
    return (value > 0) - (value < 0)


def crossings(rows: list[FrameRow]) -> list[Crossing]:
    """For each two curves of a panel (and each method's two phases), the object count from which
    their order stays as it is at the largest count: the last strict change of sign of their
    difference (a tie, as with no pair tested yet, is no crossing). Curves that never change order
    give none."""
    methods = list(dict.fromkeys(r.method for r in rows if r.software))
    out = []

    def scan(phase: str, a: str, a_curve: dict, b: str, b_curve: dict) -> None:
        last, found = 0, None
        for n in sorted(set(a_curve) & set(b_curve)):
            sign = _sign(a_curve[n] - b_curve[n])
            if sign and last and sign != last:
                found = (Crossing(phase, n, a, b, sweep_wins=sign < 0) if phase == PHASE_CROSSING
                         else Crossing(phase, n, a, b) if sign < 0 else Crossing(phase, n, b, a))
            last = sign or last
        if found:
            out.append(found)
    for phase in PHASES:
        for i, a in enumerate(methods):
            for b in methods[i + 1:]:
                scan(phase, a, _curve(rows, a, phase), b, _curve(rows, b, phase))
    for m in methods:
        scan(PHASE_CROSSING, m, _curve(rows, m, SORT_X), m, _curve(rows, m, BRUTE))
    return sorted(out, key=lambda c: (c.phase != PHASE_CROSSING, c.phase, c.objects, c.cheaper))


@dataclass(frozen=True)
class Exit:
    """The first object count at which a method's frame (typical or worst) is over a budget; None when
    every measured count fits."""

    method: str
    phase: str
    frame_typical: int | None
    frame_worst: int | None
    lines_typical: int | None
    lines_worst: int | None
    served: int  # the most objects the method serves (64, or the hardware's sprites)


def exits(rows: list[FrameRow], budget: Budget = PAL_BUDGET) -> list[Exit]:
    out = []
    for key in dict.fromkeys((r.method, r.phase) for r in rows):
        group = sorted((r for r in rows if (r.method, r.phase) == key), key=lambda r: r.objects)

        def first(limit: Fraction, worst: bool) -> int | None:
            return next((r.objects for r in group if (r.frame_worst if worst else r.frame_cycles) > limit), None)
        out.append(Exit(key[0], key[1], first(budget.frame_cycles, False), first(budget.frame_cycles, True),
                        first(budget.lines_cycles, False), first(budget.lines_cycles, True), group[-1].objects))
    return out


def cheapest(rows: list[FrameRow], methods: Sequence[str] | None = None,
             accuracy: dict[str, float] | None = None) -> list[tuple[int, int, FrameRow]]:
    """(first N, last N, row at the first N): runs of object counts with the same cheapest software
    method and phase (typical frames), over `methods` (default: all); a tie goes to the more
    accurate method (`accuracy` by key), then to the first."""
    accuracy = accuracy or {}
    chosen = [r for r in rows if r.software and (methods is None or r.method in methods)]
    best: dict[int, FrameRow] = {}
    for r in chosen:
        held = best.get(r.objects)
        if held is None or (r.frame_cycles, -accuracy.get(r.method, 0)) < (held.frame_cycles, -accuracy.get(held.method, 0)):
            best[r.objects] = r
    runs: list[tuple[int, int, FrameRow]] = []
    for n in sorted(best):
        r = best[n]
        if runs and (runs[-1][2].method, runs[-1][2].phase) == (r.method, r.phase) and runs[-1][1] == n - 1:
            runs[-1] = (runs[-1][0], n, runs[-1][2])
        else:
            runs.append((n, n, r))
    return runs


# ---- the whole study ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class PerFrame:
    rows: list[FrameRow]
    budget: Budget
    prepares: dict[str, CycleStats]
    broad: BroadTable
    shapes: tuple[str, ...]
    methods: tuple[Method, ...] = field(repr=False)

    @property
    def crossings(self) -> list[Crossing]:
        return crossings(self.rows)

    @property
    def exits(self) -> list[Exit]:
        return exits(self.rows, self.budget)


def per_frame(methods: Sequence[Method], tests: dict[str, CycleStats], shapes: Sequence[Shape],
              counts: Sequence[int] = OBJECT_COUNTS, reduced: bool = False, budget: Budget = PAL_BUDGET,
              workers: Workers | int | None = None, progress: Progress = quiet, engine: str = "auto") -> PerFrame:
    """The model for every method with measured cycles (`tests`: cycles per test by method key)."""
    used = [m for m in methods if not m.host_only and m.key in tests and tests[m.key].samples]
    prepares = prepare_costs(used, engine)
    progress(f"per frame: preparation routines checked ({', '.join(prepares) or 'none'})")
    extent_sets = [method_extents(m, shapes) for m in used if not m.once_per_frame]
    layouts, frames = (REDUCED_LAYOUTS, REDUCED_FRAMES) if reduced else (LAYOUTS, FRAMES)
    broad = measure_broad(extent_sets, counts, layouts, frames, workers, progress)
    rows = frame_rows(used, tests, prepares, shapes, broad, counts, budget)
    return PerFrame(rows, budget, prepares, broad, tuple(s.name for s in shapes), tuple(used))


def best_phase(rows: list[FrameRow], method: str, objects: int) -> FrameRow | None:
    """The cheaper broad phase (typical frame) of a method at an object count."""
    found = [r for r in rows if r.method == method and r.objects == objects]
    return min(found, key=lambda r: r.frame_cycles) if found else None


def share(value: float, whole: Fraction) -> str:
    return "n/a" if math.isnan(value) else f"{100 * value / float(whole):.1f}%"
