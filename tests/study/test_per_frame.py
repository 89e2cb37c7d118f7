"""Cost per frame: the broad-phase drivers' cycles from their instructions by hand, their pairs from an
independent count, the frame model's parts, crossings and budget exits recomputed from the
formula, and each method's X extent checked against its own verdicts (a broad phase must never
drop a pair the method would call a hit)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from retro.analysis.study import broad_phase as bp
from retro.analysis.study import per_frame as pf
from retro.analysis.study.costs import CycleStats
from retro.analysis.study.methods import BUILTIN, method

PAL_FRAME = 312 * 63  # a PAL 6569 frame: 312 lines of 63 cycles
TWENTY_LINES = 20 * 63
JSR, RTS = 6, 6


def pairs(n: int) -> int:
    return n * (n - 1) // 2


# ---- the drivers, by hand ---------------------------------------------------------------------------
#
# pairs_all (asm/broad/broad_phase.s) with `narrow` a bare RTS:
#   entry: lda #0, sta, sta, ldx #0                      2+3+3+2 = 10
#   per a: stx, txa, tay                                 3+2+2 = 7
#   per pair: iny, cpy, bcs (no), sty, jsr, rts, ldy, jmp 2+3+2+3+6+6+3+3 = 28
#   leaving a's loop: iny, cpy, bcs (taken)              2+3+3 = 8
#   next a: ldx, inx, cpx, bcc (taken; 2 the last time)  3+2+3+3 = 11
#   rts                                                  6
# n >= 1: 10 + 26n - 1 + 6 + 28 pairs = 15 + 26n + 28 pairs.

@pytest.mark.parametrize("n", [0, 1, 2, 3, 7, 16, 40, 64])
def test_pairs_all_cycles_by_hand(n):
    sample = bp.brute_sample(n)
    assert sample.candidates == pairs(n)
    expected = 41 if n == 0 else 15 + 26 * n + 28 * pairs(n)  # n = 0 still runs one a and one b check
    assert sample.cycles == expected - RTS * pairs(n)  # the model adds each test's cycles with its RTS


# sweep_x with a bare RTS:
#   entry 10; per object after the first, already in place: cpy, bcs, sty, ldx, stx, lda,
#   [ldx, cmp, bcs taken], ldx, stx, ldy, iny, bne = 3+2+3+4+3+4+4+4+3+3+4+3+2+3 = 45; leaving the
#   sort: cpy, bcs taken = 6; ldy #0 = 2; per a: sty, ldx, stx, lda, clc, adc, sta = 23, then a b that
#   starts past a's end: iny, cpy, bcs, ldx, lda, cmp, bcs taken = 21 (the last a: iny, cpy, bcs
#   taken = 8), then ldy, iny, cpy, bcc = 11 (10 the last time); rts 6.
#   Sorted, no pair: 10 + 45(n-1) + 6 + 2 + (23 + 21 + 11)(n-1) + 23 + 8 + 10 + 6 = 65 + 100(n-1).
#   Each object overlapping the next (a chain): each a but the last gets one pair, 2+3+2+4+4+3+2 +
#   stx, sty, jsr, rts, ldy, jmp (3+3+6+6+3+3) = 44, and the last pair's a then ends on the 8-cycle
#   check instead of the 21-cycle one: 65 + 144(n-1) - 13.
#   Reversed, no pair: the object at position y shifts y times (ldx, cmp, bcs, stx, dey, bne = 19, the
#   last bne not taken, 18) and skips the final compare (11): 45 - 11 + 19y - 1 = 33 + 19y.

def _spread(n: int) -> list[int]:
    return [4 * k for k in range(n)]


@pytest.mark.parametrize("n", [1, 2, 5, 17, 64])
def test_sweep_cycles_by_hand(n):
    runner = bp.BroadRunner()
    sorted_cycles, _, _ = runner.run(bp.SORT_X, _spread(n), [4] * n, list(range(n)), counting=False)
    assert sorted_cycles == 65 + 100 * (n - 1)
    chain, _, _ = runner.run(bp.SORT_X, _spread(n), [5] * n, list(range(n)), counting=False)
    assert chain == (65 if n == 1 else 65 + 144 * (n - 1) - 13)
    reversed_cycles, _, order = runner.run(bp.SORT_X, _spread(n), [4] * n, list(range(n - 1, -1, -1)), counting=False)
    assert order == list(range(n))
    assert reversed_cycles == 65 + 100 * (n - 1) - 45 * (n - 1) + sum(33 + 19 * y for y in range(1, n))


def _overlapping(xs, ws, objects) -> int:
    return sum(1 for a, b in itertools.combinations(objects, 2) if len(set(range(xs[a], xs[a] + ws[a]))
                                                                      & set(range(xs[b], xs[b] + ws[b]))))


def test_sweep_pairs_and_order_against_pixel_sets():
    """On random layouts the 6502 counts the pairs whose pixel columns meet, and leaves the objects in
    order of left edge, ties in their previous order."""
    rng = np.random.default_rng(7)
    runner = bp.BroadRunner()
    for _ in range(40):
        n = int(rng.integers(0, 65))
        ws = [int(w) for w in rng.integers(1, 40, n)]
        xs = [int(rng.integers(0, 256 - w)) for w in ws]
        order = [int(v) for v in rng.permutation(n)]
        _, counted, result = runner.run(bp.SORT_X, xs, ws, order, counting=True)
        assert counted == _overlapping(xs, ws, list(range(n)))
        assert result == [o for _, _, o in sorted((xs[o], k, o) for k, o in enumerate(order))]
        cycles, _, again = runner.run(bp.SORT_X, xs, ws, order, counting=False)
        assert again == result


def test_sweep_samples_match_the_drivers():
    """The model's samples are the bare driver minus one RTS per pair, with the pairs the counting run
    found; a second call gives the same figures."""
    extents = ((0, 24), (5, 9))
    samples = bp.sweep_samples(extents, 20, 2, 3)
    assert len(samples) == 2 * 3
    assert samples == bp.sweep_samples(extents, 20, 2, 3)
    assert all(0 <= s.candidates <= pairs(20) for s in samples)
    assert all(s.cycles >= 65 + 100 * 19 - 2000 for s in samples)  # never below the sorted, pair-free cost minus shifts


# ---- the model --------------------------------------------------------------------------------------

def _table(counts, sweep: bp.BroadSample = bp.BroadSample(100, 0)) -> pf.BroadTable:
    brute = {n: bp.brute_sample(n) for n in counts}
    return pf.BroadTable(brute=brute, sweep=_AnySweep(sweep), layouts=1, frames=1)


class _AnySweep(dict):
    """Every (extents, n) gets the same synthetic sweep sample."""

    def __init__(self, sample):
        super().__init__()
        self.sample = sample

    def __getitem__(self, key):
        return [self.sample]


def _stats(mean: float, most: int) -> CycleStats:
    return CycleStats(mean=mean, min=most, max=most, samples=1)


@pytest.fixture(scope="module")
def shapes():
    from retro.analysis.study.corpus import load_shapes

    return load_shapes(["ball", "bar"])


def test_prepare_calls_per_object_and_per_pair_of_kinds(shapes):
    """aabb_edges_prepare and sprite_edges_prepare once per object; circle_r_prepare once per pair of
    the kinds present (two shapes: 1 kind for one object, then 3 pairs of kinds); the others none."""
    for n in (1, 2, 5, 64):
        assert pf.prepare_calls(method("tight_edges"), n, 2) == n
        assert pf.prepare_calls(method("sprite_edges"), n, 2) == n
        assert pf.prepare_calls(method("circle_r"), n, 2) == (1 if n == 1 else 3)
        assert pf.prepare_calls(method("tight"), n, 2) == 0
    assert pf.prepare_calls(method("circle_r"), 64, 8) == 36


def test_frame_cost_from_its_parts(shapes):
    counts = (1, 2, 10, 64)
    tests = {"tight": _stats(29, 34), "tight_edges": _stats(23, 27), "latch": _stats(19, 19)}
    prepares = {"aabb_edges_prepare": _stats(44, 44)}
    methods = [method("tight"), method("tight_edges"), method("latch")]
    rows = pf.frame_rows(methods, tests, prepares, shapes, _table(counts, bp.BroadSample(500, 7)), counts)
    by = {(r.method, r.phase, r.objects): r for r in rows}
    for n in counts:
        brute = 15 + 26 * n + 22 * pairs(n) if n else 41
        assert by[("tight", bp.BRUTE, n)].frame_cycles == brute + 29 * pairs(n)
        assert by[("tight_edges", bp.BRUTE, n)].frame_cycles == 44 * n + brute + 23 * pairs(n)
        assert by[("tight_edges", bp.BRUTE, n)].frame_worst == 44 * n + brute + 27 * pairs(n)
        assert by[("tight", bp.SORT_X, n)].frame_cycles == 500 + 7 * 29
        assert by[("tight_edges", bp.SORT_X, n)].frame_cycles == 44 * n + 500 + 7 * 23
        assert by[("tight", bp.BRUTE, n)].frame_share == pytest.approx(by[("tight", bp.BRUTE, n)].frame_cycles / PAL_FRAME)
    # the latch: one read a frame, for at most its 8 sprites
    assert [r.objects for r in rows if r.method == "latch"] == [1, 2]
    assert all(r.frame_cycles == 19 and r.phase == pf.ONCE for r in rows if r.method == "latch")


def test_budgets_are_the_pal_frame_and_twenty_lines():
    assert pf.PAL_BUDGET.frame_cycles == PAL_FRAME
    assert pf.PAL_BUDGET.lines_cycles == TWENTY_LINES
    from retro.chips.ppu.constants import NTSC

    nes = pf.nes_budget(NTSC)
    assert nes.frame_cycles * 3 == 341 * 262  # 3 dots per CPU cycle
    assert nes.lines_cycles * 3 == 341 * 20


def test_crossing_of_prepared_edges_by_hand(shapes):
    """Brute force: preparing edges (44 per object) saves 29 - 23 = 6 cycles per pair, so it pays once
    6 n(n-1)/2 > 44 n, i.e. n - 1 > 88 / 6: from n = 16."""
    counts = tuple(range(1, 33))
    tests = {"tight": _stats(29, 34), "tight_edges": _stats(23, 27)}
    rows = pf.frame_rows([method("tight"), method("tight_edges")], tests, {"aabb_edges_prepare": _stats(44, 44)},
                         shapes, _table(counts), counts)
    first = next(n for n in counts if 6 * pairs(n) > 44 * n)
    assert first == 16
    found = [c for c in pf.crossings(rows) if c.phase == bp.BRUTE]
    assert [(c.objects, c.cheaper, c.dearer) for c in found] == [(16, "tight_edges", "tight")]


def test_budget_exits_by_hand(shapes):
    counts = tuple(range(1, 65))
    rows = pf.frame_rows([method("tight")], {"tight": _stats(29, 34)}, {}, shapes, _table(counts), counts)
    (brute,) = [e for e in pf.exits(rows) if e.phase == bp.BRUTE]

    def first_over(limit, per_test):
        return next(n for n in counts if 15 + 26 * n + 22 * pairs(n) + per_test * pairs(n) > limit)
    assert brute.frame_typical == first_over(PAL_FRAME, 29) == 28
    assert brute.frame_worst == first_over(PAL_FRAME, 34)
    assert brute.lines_typical == first_over(TWENTY_LINES, 29) == 7  # 15 + 182 + 51 x 21 = 1268
    (swept,) = [e for e in pf.exits(rows) if e.phase == bp.SORT_X]
    assert swept.frame_typical is None and swept.served == 64  # the synthetic sweep costs 100 whatever n is


def test_cheapest_ties_go_to_the_more_accurate(shapes):
    counts = (1, 2)
    rows = pf.frame_rows([method("box"), method("pixel")], {"box": _stats(33, 34), "pixel": _stats(700, 3000)}, {},
                         shapes, _table(counts, bp.BroadSample(100, 1)), counts)
    runs = pf.cheapest(rows, accuracy={"box": 0.4, "pixel": 1.0})
    assert runs[0][2].method == "pixel" and runs[0][:2] == (1, 1)  # one object: no test, the same cost
    assert runs[-1][2].method == "box"  # a test to pay: the cheaper one


# ---- x extents: a broad phase keeps every pair the method calls a hit --------------------------------

def test_x_extents_keep_every_hit(sprite_shapes, hand_shapes):
    """For every pair and case the method calls a hit (in part, for the tile cells), the two X
    intervals meet; for the boxes and circles the intervals are exactly the hit shape's columns."""
    import independent as ind
    from retro.analysis.study.corpus import make_pair

    shapes = sprite_shapes + hand_shapes
    for m in BUILTIN:
        for a, b in itertools.combinations_with_replacement(shapes, 2):
            pair = make_pair(a, b)
            (alo, ahi), (blo, bhi) = m.x_extent(a), m.x_extent(b)
            hits = m.verdict(pair) > 0
            meet = (np.maximum(alo, blo + pair.dx) < np.minimum(ahi, bhi + pair.dx))
            assert not (hits & ~meet).any(), (m.key, pair.name)
    for s in shapes:
        x0, _, x1, _ = ind.bounds(s.mask)
        assert method("tight").x_extent(s) == method("pixel").x_extent(s) == (x0, x1)
        assert method("box").x_extent(s) == (0, s.width)
        assert method("tile").x_extent(s) == (x0 - 3, x1 + 4)  # 7 = 8 - 1 columns of a cell in all
        cx, _, r = ind.smallest_circle(s.mask)
        assert method("circle").x_extent(s) == method("circle_r").x_extent(s) == (cx - r, cx + r)


# ---- the measured run ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def measured(shapes):
    from retro.analysis.study.cost_runs import measure_costs

    costs = measure_costs(shapes, samples=12, workers=1)
    tests = {k: c.overall for k, c in costs.items()}
    return tests, pf.per_frame(BUILTIN, tests, shapes, counts=(1, 2, 8, 9, 16), reduced=True, workers=1)


def test_measured_model(measured):
    tests, result = measured
    assert result.prepares["aabb_edges_prepare"].max == 2 * (3 + 3 + 2 + 3 + 3 + 2 + 3) + 6  # its 14 instructions, by hand
    assert (result.prepares["circle_r_prepare"].max, result.prepares["sprite_edges_prepare"].max) == (13, 68)
    by = {(r.method, r.phase, r.objects): r for r in result.rows}
    for (key, phase, n), r in by.items():
        assert r.test_cycles == pytest.approx(tests[key].mean)
        if phase == bp.BRUTE:
            assert (r.broad_cycles, r.candidates) == (15 + 26 * n + 22 * pairs(n), pairs(n))
        if phase == bp.SORT_X:
            assert r.candidates <= pairs(n) and r.frame_cycles <= r.frame_worst
    assert {r.method for r in result.rows} == {m.key for m in BUILTIN if not m.host_only}
    assert [n for (k, p, n) in by if k == "latch"] == [1, 2, 8]  # not past the 8 sprites
    # the same extents give the same sweep: the tight-box methods share their candidates
    for n in (8, 9, 16):
        assert by[("tight", bp.SORT_X, n)].candidates == by[("pixel", bp.SORT_X, n)].candidates


def test_per_frame_csv_round_trips(measured):
    from retro.analysis.study.per_frame_report import rows_from_csv, rows_to_csv

    _, result = measured
    text = rows_to_csv(result.rows)
    again = rows_from_csv(text)
    assert rows_to_csv(again) == text and len(again) == len(result.rows)
    for a, b in zip(again, result.rows):
        assert a.frame_cycles == pytest.approx(b.frame_cycles, rel=1e-6) and a.method == b.method


def test_per_frame_figure_draws_the_rows(measured):
    from retro.analysis.study.per_frame_chart import per_frame_figure

    _, result = measured
    fig = per_frame_figure(result)
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == [pf.PHASE_LABELS[p] for p in bp.PHASES]
    assert len({ax.get_ylim() for ax in panels}) == 1  # one y range for both phases
    for ax, phase in zip(panels, bp.PHASES):
        drawn = sorted(tuple(line.get_ydata()) for line in ax.get_lines() if len(line.get_xdata()) > 2)
        curves = [sorted((r for r in result.rows if r.method == m.key and r.phase == p), key=lambda r: r.objects)
                  for m in result.methods for p in (phase, pf.ONCE)]
        expected = sorted(tuple(r.frame_cycles for r in curve) for curve in curves if len(curve) > 2)
        assert drawn == expected
        levels = sorted(line.get_ydata()[0] for line in ax.get_lines() if list(line.get_xdata()) == [0, 1])
        assert levels == [TWENTY_LINES, PAL_FRAME]
    assert not math.isnan(result.rows[0].frame_cycles)


def test_chart_per_frame_writes_its_files(tmp_path, capsys):
    """`retro chart --per-frame`: the three files beside the chart's, every method and phase for every
    object count 1-64, and the summary names where each method leaves the PAL frame."""
    from retro.analysis.study.per_frame_report import rows_from_csv
    from retro.cli import main

    out = tmp_path / "chart"
    assert main(["chart", "--reduced", "--per-frame", "--samples", "8", "--jobs", "1", "--quiet",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    for name in ("per_frame.csv", "per_frame.md", "per_frame.png", "study.csv"):
        assert (out / name).stat().st_size > 0
    rows = rows_from_csv((out / "per_frame.csv").read_text())
    software = {m.key for m in BUILTIN if not m.host_only and not m.once_per_frame}
    for key in software:
        for phase in bp.PHASES:
            assert sorted(r.objects for r in rows if r.method == key and r.phase == phase) == list(range(1, 65))
    assert "cost per frame (C64 PAL (6569): frame 19,656 cycles, 20 lines 1,260)" in printed
    text = (out / "per_frame.md").read_text()
    assert "## Where the curves cross" in text and "## Where each method leaves the budget" in text
