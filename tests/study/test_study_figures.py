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
