"""A task's cases made from its description (retro.routines.cases.stream): from any case index, the same
cases in the same blocks as the whole run's, whether a part is entered by its seek, passed over by its
count or made and dropped."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from retro.routines import cases as case_sets
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[2]


def _joined(blocks) -> list[np.ndarray]:
    blocks = list(blocks)
    return [np.concatenate(columns) for columns in zip(*blocks)]


def _plan(name: str, exhaustive: bool, **kwargs):
    return case_sets.plan(load_spec(ROOT / name), exhaustive=exhaustive, seed=7, **kwargs)


PLANS = [("asm/mul8.toml", True, {}),  # boundary, a sweep function (no count), random
         ("examples/boxhit/boxhit.toml", False, {}),  # a product with inputs drawn per case: no seek
         ("tests/data/entry/overlap8.toml", False, {"random": 3_000})]  # every input swept: a seek


@pytest.mark.parametrize("name, exhaustive, kwargs", PLANS)
@pytest.mark.parametrize("size", [1_000, 4_096])
def test_a_stream_from_any_case_gives_the_cases_of_the_whole_run(name, exhaustive, kwargs, size):
    parts = _plan(name, exhaustive, **kwargs)
    whole = list(case_sets.stream(parts, size))
    assert all(len(b[0]) == size for b in whole[:-1])
    everything = _joined(whole)
    assert all(np.array_equal(a, b) for a, b in zip(everything, _joined(case_sets.batches(parts, size))))
    total = len(everything[0])
    for first in sorted({size, 3 * size, (total // size) * size, total}):
        tail = list(case_sets.stream(parts, size, first))
        if first >= total:
            assert tail == []
            continue
        assert all(len(b[0]) == size for b in tail[:-1])
        assert all(np.array_equal(a, b[first:]) for a, b in zip(_joined(tail), everything))


def test_every_part_but_a_sweep_function_is_reached_without_making_the_cases_before():
    swept = _plan("tests/data/entry/overlap8.toml", False, random=3_000)
    drawn = _plan("examples/boxhit/boxhit.toml", False)
    sweep = _plan("asm/mul8.toml", True)
    product = next(p for p in swept if p.name == "exhaustive")
    before = sum(p.count for p in swept[:swept.index(product)])
    assert product.seek is not None and case_sets.reachable(swept, before + 12_345)
    assert next(p for p in drawn if p.name == "exhaustive").seek is not None  # its drawn inputs: per block
    assert case_sets.reachable(drawn, 10_000) and case_sets.reachable(drawn, 70_000)  # product, random
    after_sweep = sum(p.count or 0 for p in sweep[:[p.name for p in sweep].index("sweep")])
    assert case_sets.reachable(sweep, after_sweep) and not case_sets.reachable(sweep, after_sweep + 1)
    assert next(p for p in sweep if p.name == "sweep").from_start


SPLIT = [("examples/object_table/hit_slot.toml", {"random": 150_000}),  # drawn inputs over 8 blocks; random 3
         ("asm/mul8.toml", {"random": 140_000})]  # a sweep function, a random_generator called per block


@pytest.mark.parametrize("name, kwargs", SPLIT)
def test_the_cases_do_not_depend_on_where_a_run_is_split(name, kwargs):
    """Past the first SEEK_BLOCK of a part, every block draws from its own generator: a stream entered
    anywhere (a block's start, its middle, a part's edge) makes the cases of the whole run there."""
    parts = _plan(name, True, **kwargs)
    everything = _joined(case_sets.stream(parts, 65_536))
    total = len(everything[0])
    assert total > 3 * case_sets.SEEK_BLOCK
    edges = np.cumsum([p.count if p.count is not None else len(_joined(p.blocks())[0]) for p in parts])
    for first in sorted({1, case_sets.SEEK_BLOCK, 3 * case_sets.SEEK_BLOCK + 17, *edges[:-1], *(edges[:-1] - 1),
                         total - 5}):
        tail = _joined(case_sets.stream(parts, 4_000, first))
        assert all(np.array_equal(a, b[first:]) for a, b in zip(tail, everything)), first
    random = _joined(parts[-1].blocks())  # its blocks draw from streams of their own: no block repeats another
    block = case_sets.SEEK_BLOCK
    assert not all(np.array_equal(c[:block // 2], c[block:block + block // 2]) for c in random)


def test_a_worker_draws_only_the_cases_of_its_range(monkeypatch):
    """Entering the random part and a product with drawn inputs far in draws no case before the block
    the range starts in."""
    parts = _plan("examples/object_table/hit_slot.toml", True, random=200_000)
    drawn = []
    real = case_sets._random_column
    monkeypatch.setattr(case_sets, "_random_column", lambda port, rng, n: drawn.append(n) or real(port, rng, n))
    product = next(p for p in parts if p.name == "exhaustive")
    for first in (5 * case_sets.SEEK_BLOCK + 100, product.count + 2 * case_sets.SEEK_BLOCK + 100):
        drawn.clear()
        block = next(case_sets.stream(parts, 1_000, first))
        assert len(block[0]) == 1_000
        inputs = 5 if first > product.count else 2  # the random part draws every input, the product y, player_y
        assert drawn and sum(drawn) <= inputs * case_sets.CHUNK  # one CHUNK per drawn input, none before


def test_a_part_of_at_most_one_block_draws_the_cases_it_always_drew():
    """The first block's generator is the part's seeded one, drawn as before blocks existed: per CHUNK
    and input in order (uniform draws), the spec's generator called once for all the cases."""
    routine = load_spec(ROOT / "examples/object_table/hit_slot.toml")
    parts = case_sets.plan(routine, exhaustive=False, seed=7, random=9_000)
    rng = np.random.default_rng(7)
    ports = routine.part_inputs("random")
    expected = []
    for at in range(0, 9_000, case_sets.CHUNK):
        m = min(case_sets.CHUNK, 9_000 - at)
        expected.append([rng.integers(p.values.lo, p.values.hi + 1, size=m, dtype=np.int64) for p in ports])
    random = next(p for p in parts if p.name == "random")
    assert all(np.array_equal(a, b) for a, b in zip(_joined(random.blocks()), _joined(expected)))
    mul8 = load_spec(ROOT / "asm/mul8.toml")
    random = next(p for p in case_sets.plan(mul8, exhaustive=True, seed=3, random=5_000) if p.name == "random")
    made = mul8.random_generator(np.random.default_rng(3), 5_000)
    assert [tuple(int(v) for v in row) for row in zip(*_joined(random.blocks()))] == made


def test_a_seek_makes_the_same_cases_as_counting_from_the_start():
    product = next(p for p in _plan("tests/data/entry/overlap8.toml", False) if p.name == "exhaustive")
    everything = _joined(product.blocks())
    for start in (0, 1, 4_000, 65_535):
        assert all(np.array_equal(a, b[start:]) for a, b in zip(_joined(product.seek(start)), everything))
