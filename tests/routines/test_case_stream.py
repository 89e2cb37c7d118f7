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


YIELDED = "tests/data/sweeps/mul8_yielded.toml"  # mul8 with a sweep function that yields its blocks: no count
PLANS = [("asm/mul8.toml", True, {}),  # boundary, a grid sweep (counted, entered anywhere), random
         (YIELDED, True, {}),  # boundary, a sweep function (no count), random
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
    sweep = _plan(YIELDED, True)
    grid = _plan("asm/mul8.toml", True)
    product = next(p for p in swept if p.name == "exhaustive")
    before = sum(p.count for p in swept[:swept.index(product)])
    assert product.seek is not None and case_sets.reachable(swept, before + 12_345)
    assert next(p for p in drawn if p.name == "exhaustive").seek is not None  # its drawn inputs: per block
    assert case_sets.reachable(drawn, 10_000) and case_sets.reachable(drawn, 70_000)  # product, random
    after_sweep = sum(p.count or 0 for p in sweep[:[p.name for p in sweep].index("sweep")])
    assert case_sets.reachable(sweep, after_sweep) and not case_sets.reachable(sweep, after_sweep + 1)
    assert next(p for p in sweep if p.name == "sweep").from_start
    assert next(p for p in grid if p.name == "sweep").count == 1 << 16 and case_sets.reachable(grid, after_sweep + 1)


SPLIT = [("examples/object_table/hit_slot.toml", {"random": 150_000}),  # drawn inputs over 8 blocks; random 3
         ("asm/mul8.toml", {"random": 140_000}),  # a grid sweep, a random_generator called per block
         (YIELDED, {"random": 140_000})]  # a sweep function


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
        # the random part: one CHUNK per drawn input, none before; the product makes its block at once: that
        # block's draws, none before
        made_at_once = case_sets.CHUNK if first > product.count else case_sets.SEEK_BLOCK
        assert drawn and sum(drawn) <= inputs * made_at_once


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
    made = mul8.random_generator(np.random.default_rng(3), 5_000)  # (a column block by input name)
    assert [tuple(int(v) for v in row) for row in zip(*_joined(random.blocks()))] == list(zip(*(made[n].tolist()
                                                                                            for n in mul8.input_names)))


def test_a_seek_makes_the_same_cases_as_counting_from_the_start():
    product = next(p for p in _plan("tests/data/entry/overlap8.toml", False) if p.name == "exhaustive")
    everything = _joined(product.blocks())
    for start in (0, 1, 4_000, 65_535):
        assert all(np.array_equal(a, b[start:]) for a, b in zip(_joined(product.seek(start)), everything))


def test_a_worker_makes_only_the_combinations_of_its_range_of_a_grid_sweep(monkeypatch):
    """A grid sweep (retro.routines.grid) is entered at the range's first case: no combination before it
    is made, whatever the range (inside a grid, at a grid's edge, in a later grid)."""
    from retro.routines.grid import Grid

    parts = _plan("asm/tile_box.toml", True, random=0)
    sweep = next(p for p in parts if p.name == "sweep")
    before = sum(p.count for p in parts[:parts.index(sweep)])
    assert sweep.count == 512 * 256 + 5 * 2 * 256 and not sweep.from_start
    everything = _joined(case_sets.stream(parts, 4_096))
    made = []
    real = Grid._axis_columns
    monkeypatch.setattr(Grid, "_axis_columns", lambda grid, lo, hi: made.append((grid.count, lo, hi)) or real(grid, lo, hi))
    for start in (70_001, 512 * 256, 512 * 256 + 700):
        made.clear()
        block = next(case_sets.stream(parts, 1_000, before + start))
        assert all(np.array_equal(a, b[before + start:before + start + 1_000]) for a, b in zip(block, everything))
        inside = start if start < 512 * 256 else start - 512 * 256
        assert made and made[0][1] == inside and all(lo >= inside for _, lo, _ in made), (start, made)


def test_a_grid_is_every_combination_in_order_and_its_faults_are_one_line(tmp_path):
    from retro.errors import InputError
    from retro.routines.grid import Grid

    grid = Grid({"a": [5, 7], "b": 3}, lambda a, b: {"x": a * 10 + b, "y": 1})
    assert grid.count == 6
    assert [list(c) for c in grid.block(0, 6).values()] == [[50, 51, 52, 70, 71, 72], [1] * 6]
    assert [list(b["x"]) for b in grid.blocks(1, size=4)] == [[51, 52, 70], [71, 72]]  # cut where a whole run cuts
    for axes, says in (({}, "non-empty"), ({"a b": 2}, "identifier"), ({"a": -1}, "negative"),
                       ({"a": [1.5]}, "whole numbers")):
        with pytest.raises(ValueError, match=says):
            Grid(axes)
    spec = (ROOT / YIELDED).read_text().replace('file = "../../../asm/mul8.s"', f'file = "{ROOT / "asm/mul8.s"}"')
    for number, (body, says) in enumerate((('return [Grid({"a": 256, "b": 256}), {"a": [1], "b": [2]}]', "not both"),
                       ('return Grid({"a": 256, "b": 256}, lambda a, b: a)', "make must return a dict"),
                       ('return Grid({"a": 256, "b": 256}, lambda a, b: {"a": a, "b": b + 1 // 0})',
                        "(Grid 1's make) raised ZeroDivisionError"),
                       ('return Grid({"a": 256, "c": 256})', "lacks 'b'"),
                       ('return Grid({"a": 256, "b": 257})', "does not fit"))):
        folder = tmp_path / str(number)  # (a module of its own each: none is cached under another's name)
        folder.mkdir()
        (folder / "yielded.py").write_text(f"from retro.routines.grid import Grid\ndef sweep():\n    {body}\n")
        (folder / "spec.toml").write_text(spec)
        with pytest.raises(InputError, match="cases.sweep") as caught:
            list(case_sets.stream(case_sets.plan(load_spec(folder / "spec.toml"), exhaustive=True, seed=1), 4_096))
        assert says in str(caught.value) and "\n" not in str(caught.value), str(caught.value)
