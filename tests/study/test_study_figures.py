"""Pareto front, CSV round trip, cost measurement consistency, tunnelling against its formula."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from retro.analysis.study.corpus import Shape
from retro.analysis.study.pareto import dominates, pareto_front
from retro.analysis.study.report import rows_from_csv, rows_to_csv


def test_pareto_by_hand():
    points = [(10, 0.5), (20, 0.9), (30, 0.8), (40, 1.0), (math.nan, 0.99), (20, 0.9)]
    assert pareto_front(points) == [True, True, False, True, False, True]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(1, 50), st.integers(0, 20)), min_size=1, max_size=8))
def test_front_members_are_not_dominated_and_the_rest_are(raw):
    points = [(float(c), a / 20) for c, a in raw]
    front = pareto_front(points)
    for i, on in enumerate(front):
        beaten = any(dominates(points[j], points[i]) for j in range(len(points)) if j != i)
        assert on == (not beaten)
    assert any(front)


@pytest.fixture(scope="module")
def chart_output(tmp_path_factory):
    from retro.analysis.study.chart_run import run_chart

    out = tmp_path_factory.mktemp("chart")
    return out, run_chart(out, shape_names=("ball", "bar"), workers=1, cost_samples=12)


def test_chart_writes_its_files_and_the_csv_round_trips(chart_output):
    out, output = chart_output
    for name in ("study.csv", "study.md", "study_overall.png", "study_pairs.png"):
        assert (out / name).stat().st_size > 0
    text = (out / "study.csv").read_text()
    again = rows_from_csv(text)
    assert rows_to_csv(again) == text
    for a, b in zip(again, output.rows):
        for field in a.__dataclass_fields__:
            x, y = getattr(a, field), getattr(b, field)
            assert (isinstance(x, float) and math.isnan(x) and math.isnan(y)) or x == y, field


def test_figures_are_consistent(chart_output):
    _, output = chart_output
    rows = output.rows
    by_scope = {}
    for r in rows:
        by_scope.setdefault(r.scope, []).append(r)
        assert r.tp + r.fp + r.tn + r.fn == pytest.approx(r.cases)
        assert r.tp + r.fn == pytest.approx(r.colliding)
        if not math.isnan(r.cycles_mean):
            assert r.cycles_min <= r.cycles_mean <= r.cycles_max
        assert not (r.host_only and r.pareto)
    for scope, group in by_scope.items():
        for r in group:
            if r.pareto:
                assert not any(o is not r and not math.isnan(o.cycles_mean)
                               and dominates((o.cycles_mean, o.accuracy), (r.cycles_mean, r.accuracy)) for o in group)
    overall = by_scope["ALL"]
    assert overall[0].cases == sum(g[0].cases for s, g in by_scope.items() if s != "ALL")


def test_measured_routines_agree_with_the_study_verdicts(sprite_shapes):
    """measure_costs raises if a routine's answer differs from the method's verdict on any case."""
    from retro.analysis.study.cost_runs import measure_costs

    costs = measure_costs(sprite_shapes[:2], samples=40, workers=1)
    assert costs["latch"].overall.min == costs["latch"].overall.max  # a straight-line routine
    assert costs["sat"].overall.samples == 0 and "host-only" in costs["sat"].counted
    assert costs["pixel"].overall.max > costs["tight"].overall.max


@pytest.mark.parametrize("length,thickness", [(4, 1), (4, 8), (2, 3)])
def test_tunnelling_matches_the_closed_form(length, thickness):
    from retro.analysis.study.methods import PIXEL
    from retro.analysis.study.stability.tunnelling import (
        miss_rate_from_hits,
        static_hits_by_dx,
        swept_miss_rate,
        wall,
    )

    mask = np.zeros((21, 24), dtype=bool)
    mask[9:11, 3:3 + length] = True
    mover = Shape(name="mover", mask=mask)
    obstacle = wall(thickness)
    dxs, hits = static_hits_by_dx(PIXEL, mover, obstacle)
    for v in range(1, 30):
        expected = max(0.0, 1 - (thickness + length - 1) / v)
        assert miss_rate_from_hits(dxs, hits, v) == pytest.approx(expected)
        assert swept_miss_rate(mover, obstacle, v) == 0


# ---- the chart's data, pinned by the rules computed independently -----------------------------------

def _expected_verdicts(m, a, b, offsets):
    import independent as ind

    if m.key == "box":
        return [1.0] * len(offsets)
    if m.key in ("tight", "tight_edges", "sprite_edges"):
        return [float(v) for v in ind.box_hits(ind.bounds(a.mask), ind.bounds(b.mask), offsets)]
    if m.key in ("circle", "circle_r"):
        return [float(v) for v in ind.circle_hits(ind.smallest_circle(a.mask), ind.smallest_circle(b.mask), offsets)]
    if m.key == "tile":
        return ind.tile_shares(ind.bounds(a.mask), ind.bounds(b.mask), offsets)
    if m.key in ("pixel", "latch"):
        return [float(v) for v in ind.pixel_hits(a.mask, b.mask, offsets)]
    assert m.key == "sat", m.key
    return [float(v) for v in ind.hull_hits(a.mask, b.mask, offsets)]


def test_chart_counts_are_the_rules(chart_output):
    """Every CSV row's counts, from the rules computed a second way (tests/study/independent.py)."""
    import independent as ind
    from retro.analysis.study.corpus import load_shapes
    from retro.analysis.study.methods import BUILTIN

    _, output = chart_output
    ball, bar = load_shapes(["ball", "bar"])
    by = {(r.scope, r.method): r for r in output.rows}
    pooled = {}
    for a, b in ((ball, ball), (ball, bar), (bar, bar)):
        offsets = ind.all_offsets(a.mask, b.mask)
        truth = ind.pixel_hits(a.mask, b.mask, offsets)
        for m in BUILTIN:
            tp, fp, tn, fn = ind.counts(_expected_verdicts(m, a, b, offsets), truth)
            r = by[(f"{a.name}+{b.name}", m.key)]
            assert (r.cases, r.colliding) == (len(offsets), sum(truth))
            assert (r.tp, r.fp, r.tn, r.fn) == pytest.approx((tp, fp, tn, fn)), (r.scope, m.key)
            total = pooled.setdefault(m.key, [0, 0, 0, 0])
            for i, v in enumerate((tp, fp, tn, fn)):
                total[i] += v
    for key, (tp, fp, tn, fn) in pooled.items():
        r = by[("ALL", key)]
        assert (r.tp, r.fp, r.tn, r.fn) == pytest.approx((tp, fp, tn, fn))
        assert r.accuracy == pytest.approx((tp + tn) / (tp + fp + tn + fn))
        assert r.fp_rate == pytest.approx(fp / (fp + tn)) and (math.isnan(r.fn_rate) or r.fn_rate == pytest.approx(fn / (tp + fn)))


def test_chart_pareto_flags_by_brute_force(chart_output):
    _, output = chart_output
    for scope in {r.scope for r in output.rows}:
        group = [r for r in output.rows if r.scope == scope]
        for r in group:
            def beaten(by):
                return any(o is not r and not math.isnan(o.cycles_mean) and o.cycles_mean <= r.cycles_mean
                           and o.accuracy >= r.accuracy and (o.cycles_mean < r.cycles_mean or o.accuracy > r.accuracy)
                           for o in by)
            measured = not math.isnan(r.cycles_mean)
            assert r.pareto == (measured and not beaten(group))
            assert r.pareto_software == (measured and not r.hardware and not beaten([o for o in group if not o.hardware]))


def test_chart_cycles_meet_the_routines_stated_figures(chart_output):
    """The latch read is 19 cycles every call (asm/latch_test.s: 4 + 3 + 3 + 3 + 6); the game-convention
    routines stay within issue 12's worst cases (aabb_edges 27, circle_r 63, sprite_edges 42); every
    routine method was measured on 12 cases of each of the 3 pairs."""
    _, output = chart_output
    overall = {r.method: r for r in output.rows if r.scope == "ALL"}
    assert (overall["latch"].cycles_min, overall["latch"].cycles_max) == (19, 19)
    assert overall["tight_edges"].cycles_max <= 27
    assert overall["circle_r"].cycles_max <= 63
    assert overall["sprite_edges"].cycles_max <= 42
    for r in overall.values():
        assert r.cycle_samples == (0 if r.host_only else 36), r.method
    assert overall["sat"].host_only and math.isnan(overall["sat"].cycles_mean)


def test_chart_figures_draw_the_rows(chart_output):
    from matplotlib.container import ErrorbarContainer

    from retro.analysis.study.chart import overall_figure, pairs_figure, styles_of
    from retro.analysis.study.methods import BUILTIN

    _, output = chart_output
    styles = styles_of(BUILTIN)
    ax = overall_figure(output.rows, styles).axes[0]
    drawn = sorted((float(c.lines[0].get_xdata()[0]), float(c.lines[0].get_ydata()[0]))
                   for c in ax.containers if isinstance(c, ErrorbarContainer))
    measured = sorted((r.cycles_mean, r.accuracy) for r in output.rows if r.scope == "ALL" and not r.host_only)
    assert [v for point in drawn for v in point] == pytest.approx([v for point in measured for v in point])
    sat = next(r for r in output.rows if r.scope == "ALL" and r.method == "sat")
    assert any(list(line.get_ydata()) == [sat.accuracy, sat.accuracy] for line in ax.get_lines())
    fig = pairs_figure(output.rows, styles)
    panels = [a for a in fig.axes if a.get_title()]
    assert [a.get_title() for a in panels] == ["ball+ball", "ball+bar", "bar+bar"]
    assert len({a.get_xlim() for a in panels}) == 1  # one x range for every pair
