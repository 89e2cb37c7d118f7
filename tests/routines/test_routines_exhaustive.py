"""Exhaustive sweeps (bounded by default; RETRO_EXHAUSTIVE=1 runs them in full) and the check API."""

from __future__ import annotations

import os

import numpy as np
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


@pytest.mark.exhaustive
def test_aabb8_sweep_is_every_input_of_each_axis_and_agrees_with_the_reference():
    """The sweep's three sections: every (w, other w) per block, box A's position from `starts`, every
    position of box B; the axis not swept held where the boxes overlap (and, for y, after each way the x
    test goes). Its blocks on the compiled engine (the batched core without numba) against the
    reference inside the domain (sizes >= 1): the full 3 x 2^32 runs with RETRO_EXHAUSTIVE=1 (`retro check aabb8 --exhaustive`), a
    slice here (one block in 64, of two positions of box A without it: 786,432 calls)."""
    from aabb8_slice import sweep_slice_mismatches

    from retro.routines.builtin_cases import AABB8_OVERLAPPING

    x_held, a_first, b_first = (AABB8_OVERLAPPING[k] for k in ("x", "y_a_first", "y_b_first"))
    assert reference.aabb8(10, x_held[0], 5, x_held[1], 12, x_held[2], 5, x_held[3])  # y overlaps
    assert a_first[0] < a_first[2] and b_first[0] >= b_first[2]  # each way of the x test's CMP
    assert all(reference.aabb8(h[0], 10, h[1], 5, h[2], 12, h[3], 5) for h in (a_first, b_first))
    starts = range(256) if FULL else (0, 255)
    step = 64  # the full sweep: test_check_of_each_routine_finds_no_mismatch with RETRO_EXHAUSTIVE=1
    wrong, seen = sweep_slice_mismatches(get("aabb8"), starts, step)
    assert not wrong, wrong
    assert seen == 3 * len(starts) * 256 * (1 << 16) // step


MUL16_ROWS = (0, 1, 0x00FF, 0x0100, 0x5555, 0x8000, 0xAAAA, 0xFFFF)  # values of a whose every b is run here


@pytest.mark.exhaustive
def test_mul16_sweep_is_every_product_and_costs_what_its_header_says():
    """The sweep is every (a, b) once, b fastest (a grid of 2^32, entered at any row of a); rows of it run
    on the compiled engine (the batched core without numba) give a * b in $14-$17 in 437 + 17 x (one bits
    of b) cycles, the cost asm/mul16.s states. The whole 2^32 runs with RETRO_EXHAUSTIVE=1 through
    test_check_of_each_routine_finds_no_mismatch (`retro check mul16 --exhaustive`); here 8 rows of
    65,536."""
    from retro.cpu.compiled import numba_problem
    from retro.routines.builtin_cases import mul16_sweep
    from retro.routines.runner import RoutineRunner

    grid = mul16_sweep()
    assert grid.count == 1 << 32 and grid.names == ("a", "b")
    runner = RoutineRunner(get("mul16"))
    run = runner.run_batch if numba_problem() else runner.run_compiled
    b = np.arange(1 << 16, dtype=np.int64)
    ones = np.array([bin(v).count("1") for v in range(1 << 16)])
    for a in MUL16_ROWS:
        block = grid.block(a << 16, (a + 1) << 16)
        assert (block["a"] == a).all() and np.array_equal(block["b"], b)
        outcome = run([block["a"], block["b"]])
        assert not outcome.error.any()
        assert np.array_equal(outcome.outputs[0], a * b), a
        assert np.array_equal(outcome.cycles, 437 + 17 * ones), a


def test_mul16_exhaustive_plans_the_whole_space_and_auto_takes_the_compiled_engine():
    """Planned, never made: boundary, the 2^32 sweep, 100,000 random; "auto" sends that many calls to the
    compiled engine (numba importable) and a check without --exhaustive to neither (a few thousand)."""
    from retro.analysis.check.engines import AUTO_BATCH_CASES, array_engine
    from retro.cpu.compiled import numba_problem
    from retro.routines import cases as case_sets

    routine = get("mul16")
    parts = case_sets.plan(routine, exhaustive=True)
    assert [(p.name, p.count) for p in parts] == [("boundary", 13 * 13), ("sweep", 1 << 32), ("random", 100_000)]
    calls = sum(p.count for p in parts)
    assert array_engine("auto", calls, 557 * calls) == (("batch", numba_problem()) if numba_problem() else
                                                        ("compiled", f"auto: {calls:,} planned calls, about "
                                                                     f"{557 * calls / 1e6:,.0f} M cycles"))
    assert sum(p.count for p in case_sets.plan(routine, exhaustive=False)) < AUTO_BATCH_CASES
