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


def test_only_a_product_of_swept_inputs_is_reached_without_making_the_cases_before():
    swept = _plan("tests/data/entry/overlap8.toml", False, random=3_000)
    drawn = _plan("examples/boxhit/boxhit.toml", False)
    sweep = _plan("asm/mul8.toml", True)
    product = next(p for p in swept if p.name == "exhaustive")
    before = sum(p.count for p in swept[:swept.index(product)])
    assert product.seek is not None and case_sets.reachable(swept, before + 12_345)
    assert next(p for p in drawn if p.name == "exhaustive").seek is None
    assert not case_sets.reachable(drawn, 10_000)
    assert case_sets.reachable(drawn, 0)
    after_sweep = sum(p.count or 0 for p in sweep[:[p.name for p in sweep].index("sweep")])
    assert case_sets.reachable(sweep, after_sweep) and not case_sets.reachable(sweep, after_sweep + 1)


def test_a_seek_makes_the_same_cases_as_counting_from_the_start():
    product = next(p for p in _plan("tests/data/entry/overlap8.toml", False) if p.name == "exhaustive")
    everything = _joined(product.blocks())
    for start in (0, 1, 4_000, 65_535):
        assert all(np.array_equal(a, b[start:]) for a, b in zip(_joined(product.seek(start)), everything))
