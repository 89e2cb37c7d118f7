"""The tally of one block (`count_block`) against a plain case-by-case count of the same block: its
shortcuts (a block whose cases all lie inside the domain, whose answers are all right, whose first
extreme lies inside) must give what counting every case one at a time gives, wherever in the block the
one mismatch, the one case outside the domain, the new extreme or the tie sits."""

from __future__ import annotations

import numpy as np
import pytest

from retro.analysis.check.engines import CallBlock
from retro.analysis.check.reference import expected_outputs
from retro.analysis.check.tally import EXAMPLES_KEPT, count_block
from retro.routines import cases as case_sets
from retro.routines.registry import get

N = 200
POSITIONS = (0, 1, N // 2, N - 2, N - 1)


@pytest.fixture(scope="module")
def aabb8():
    return get("aabb8")


def _columns(seed: int, outside: tuple[int, ...] = ()) -> list[np.ndarray]:
    """N cases of aabb8 inside its domain (every width and height at least 1), but at `outside`, where
    one of the four is 0 (a different one by position)."""
    rng = np.random.default_rng(seed)
    columns = [rng.integers(0, 256, N, dtype=np.int64) for _ in range(8)]
    for k in (2, 3, 6, 7):  # aw, ah, bw, bh
        columns[k] = np.maximum(columns[k], 1)
    for i in outside:
        columns[(2, 3, 6, 7)[i % 4]][i] = 0
    return columns


def _block(aabb8, columns: list, seed: int) -> CallBlock:
    """What a right routine gives: the reference's answers, cycles at random from 20 to 40."""
    cases = case_sets.columns_to_cases(columns)
    hit = np.asarray([expected_outputs(aabb8, case, {})[0] for case in cases], dtype=np.int64)
    cycles = np.random.default_rng(seed + 1).integers(20, 41, N, dtype=np.int64)
    return CallBlock([hit], cycles, np.zeros(N, dtype=np.int64), None, N)


def _one_by_one(aabb8, block: CallBlock, columns: list) -> dict:
    """The figures counted case by case, each rule written out plainly."""
    cases = case_sets.columns_to_cases(columns)
    figures = {"result_mismatches": 0, "outside": 0, "outside_wrong": 0, "cycles_sum": 0, "cycles_count": 0,
               "cycles_min": None, "cycles_max": None, "min_case": None, "max_case": None, "failure": None,
               "constraint_cases": {c.text: 0 for c in aabb8.domain},
               "constraint_wrong": {c.text: 0 for c in aabb8.domain}, "wrong_cases": [], "outside_wrong_cases": []}
    for i, case in enumerate(cases):
        broken = [c.text for c in aabb8.domain if not c.test(*case)]
        right = block.outputs[0][i] == expected_outputs(aabb8, case, {})[0]
        cycles = int(block.cycles[i])
        if broken:
            figures["outside"] += 1
            for text in broken:
                figures["constraint_cases"][text] += 1
                figures["constraint_wrong"][text] += not right
            if not right:
                figures["outside_wrong"] += 1
                figures["outside_wrong_cases"].append(case)
            continue
        if not right:
            figures["result_mismatches"] += 1
            figures["wrong_cases"].append(case)
            figures["failure"] = figures["failure"] or case
        figures["cycles_sum"] += cycles
        figures["cycles_count"] += 1
        if figures["cycles_min"] is None or cycles < figures["cycles_min"]:
            figures["cycles_min"], figures["min_case"] = cycles, case
        if figures["cycles_max"] is None or cycles > figures["cycles_max"]:
            figures["cycles_max"], figures["max_case"] = cycles, case
    return figures


def _assert_same(aabb8, block: CallBlock, columns: list) -> None:
    want = _one_by_one(aabb8, block, columns)
    got = count_block(aabb8, block, columns, None, {})
    for name in ("result_mismatches", "outside", "outside_wrong", "cycles_sum", "cycles_count", "cycles_min",
                 "cycles_max", "min_case", "max_case", "constraint_cases", "constraint_wrong"):
        assert getattr(got, name) == want[name], name
    assert got.cases == N
    assert (got.failure.case if got.failure else None) == want["failure"]
    named = [example.split(": ")[0] for example in got.examples]
    assert named == [f"aabb8({_described(aabb8, case)})" for case in want["wrong_cases"][:EXAMPLES_KEPT]]
    named = [example.split(": ")[0] for example in got.outside_examples]
    assert named == [f"aabb8({_described(aabb8, case)})" for case in want["outside_wrong_cases"][:EXAMPLES_KEPT]]


def _described(routine, case) -> str:
    from retro.analysis.check.results import describe_case

    return describe_case(routine, case)


@pytest.mark.parametrize("outside", [(), (3, 77, 150)], ids=["all-inside", "some-outside"])
def test_a_right_block(aabb8, outside):
    columns = _columns(1, outside)
    _assert_same(aabb8, _block(aabb8, columns, 1), columns)


@pytest.mark.parametrize("outside", [(), (3, 77, 150)], ids=["all-inside", "some-outside"])
@pytest.mark.parametrize("position", POSITIONS)
def test_one_wrong_answer_anywhere_in_the_block(aabb8, position, outside):
    columns = _columns(2, outside)
    block = _block(aabb8, columns, 2)
    block.outputs[0][position] ^= 1
    _assert_same(aabb8, block, columns)


@pytest.mark.parametrize("position", POSITIONS)
def test_one_case_outside_the_domain_anywhere_in_the_block(aabb8, position):
    columns = _columns(3, (position,))
    _assert_same(aabb8, _block(aabb8, columns, 3), columns)
    block = _block(aabb8, columns, 3)
    block.outputs[0][position] ^= 1  # and the routine wrong there: outside, so no mismatch
    _assert_same(aabb8, block, columns)


@pytest.mark.parametrize("outside", [(), (3, 77, 150)], ids=["all-inside", "some-outside"])
@pytest.mark.parametrize("position", POSITIONS)
@pytest.mark.parametrize("cycles", [5, 90], ids=["fastest", "slowest"])
def test_a_new_extreme_anywhere_in_the_block(aabb8, position, outside, cycles):
    columns = _columns(4, outside)
    block = _block(aabb8, columns, 4)
    block.cycles[position] = cycles
    _assert_same(aabb8, block, columns)


@pytest.mark.parametrize("position", POSITIONS)
@pytest.mark.parametrize("cycles", [5, 90], ids=["fastest", "slowest"])
def test_an_extreme_outside_the_domain_is_not_the_blocks(aabb8, position, cycles):
    """The block's own extreme lies outside: the extreme inside comes from the other cases."""
    columns = _columns(5, (position,))
    block = _block(aabb8, columns, 5)
    block.cycles[position] = cycles
    _assert_same(aabb8, block, columns)
    got = count_block(aabb8, block, columns, None, {})
    assert cycles not in (got.cycles_min, got.cycles_max)


@pytest.mark.parametrize("first,second", [(0, N - 1), (10, 11), (N // 2, N - 1)])
def test_ties_give_the_first_case_inside(aabb8, first, second):
    """Two cases tie for the extreme: the first inside is named; when it lies outside, the second."""
    for outside in ((), (first,)):
        columns = _columns(6, outside)
        block = _block(aabb8, columns, 6)
        block.cycles[[first, second]] = 5
        _assert_same(aabb8, block, columns)
        block.cycles[[first, second]] = 90
        _assert_same(aabb8, block, columns)


def test_several_wrong_answers_keep_the_first_examples_in_order(aabb8):
    columns = _columns(7, (4, 9))
    block = _block(aabb8, columns, 7)
    block.outputs[0][[2, 4, 9, 30, 31, 60, 61, 62, 199]] ^= 1
    _assert_same(aabb8, block, columns)
