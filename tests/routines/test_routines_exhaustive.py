"""Exhaustive sweeps (bounded by default; RETRO_EXHAUSTIVE=1 runs them in full) and the check API."""

from __future__ import annotations

import os

import pytest

from retro.analysis.check import run_checks, static_bounds
from retro.routines import reference
from retro.routines.registry import builtin_names, get

FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"


@pytest.mark.exhaustive
def test_mul8_every_product(runners):
    runner = runners["mul8"]
    step = 1 if FULL else 17  # bounded: every 17th a against every b (3,840 products)
    for a in range(0, 256, step):
        for b in range(256):
            assert runner.answer((a, b)) == a * b, (a, b)


@pytest.mark.exhaustive
def test_tile_every_pixel_position_and_beyond(runners):
    runner = runners["tile"]
    screen, props = runner.memory_values["screen"], runner.memory_values["props"]
    y_step = 1 if FULL else 7
    for x in range(0, 512, 1 if FULL else 3):
        for y in range(0, 256, y_step):
            assert runner.answer((x & 0xFF, x >> 8, y)) == reference.tile(x & 0xFF, x >> 8, y, screen, props)


@pytest.mark.exhaustive
@pytest.mark.parametrize("name", builtin_names())
def test_check_of_each_routine_finds_no_mismatch(name):
    result = run_checks([name], exhaustive=FULL, random_count=None if FULL else 300, jobs=1)[0]
    assert result.mismatches == 0, result.totals.examples + result.bounds_violations
    assert result.static.best <= result.totals.cycles_min <= result.totals.cycles_max <= result.static.worst


def test_domain_conditions_are_shown_to_be_needed():
    result = run_checks(["circle"], random_count=200, jobs=1)[0]
    assert result.totals.constraint_wrong["r1 + r2 <= 255"] > 0


def test_static_worst_case_is_reached_by_the_straight_line_routines():
    for name in ("aabb8", "mul8", "tile", "circle"):
        result = run_checks([name], random_count=500, jobs=1)[0]
        assert result.worst_reached, name
        assert static_bounds(get(name)).worst == result.totals.cycles_max
