"""A grid's columns (retro.routines.grid) against a plain computation of the mixed-radix digits, one
combination at a time: any range (odd starts and lengths, ranges across block edges and across a run's or a
period's end), axes of any length and of listed values; and the checks of what a grid's `make` returns."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines.grid import GRID_BLOCK, Grid
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[2]


def _digits(lengths: list[int], index: int) -> list[int]:
    """The plain rule: combination `index`'s digit on each axis, the last axis varying fastest."""
    digits = []
    for length in reversed(lengths):
        index, digit = divmod(index, length)
        digits.append(digit)
    return digits[::-1]


def _expected(axes: dict, lo: int, hi: int) -> dict[str, list[int]]:
    """Each column's values over combinations lo..hi-1 (a dict axis: several columns, one digit)."""
    columns = [dict(a) if isinstance(a, dict) else {name: list(range(a)) if isinstance(a, int) else list(a)}
               for name, a in axes.items()]
    lengths = [len(next(iter(c.values()))) for c in columns]
    expected = {name: [] for c in columns for name in c}
    for i in range(lo, hi):
        for c, digit in zip(columns, _digits(lengths, i)):
            for name, values in c.items():
                expected[name].append(values[digit])
    return expected


GRIDS = [{"a": 3, "b": 5, "c": 7},  # no power of two: every run and period ends at an odd place
         {"x": [9, 4, 250, 4], "y": 2, "z": [100, 3, 77]},  # listed values (out of order, one repeated)
         {"ax": [0, 17], "bx": 256, "aw": 256, "bw": 256},  # aabb8's shape: runs longer than a block
         {"p": 1, "q": 70_001},  # an axis longer than a block, varying fastest
         {"u": 13, "v": 1, "w": 4_099},  # a one-value axis between
         {"d": {"x1": [0, 0, 5, 9], "x2": [3, 1, 0, 0]}, "r": 256, "k": {"r1": [7], "r2": [8]}},  # columns together
         {"dx": 511, "dy": {"y1": range(511), "y2": range(510, -1, -1)}, "r": 256}]  # circle's: dy's period (130,816)
# spans blocks and is laid out once (grid.PERIODIC_LIMIT): each block a view into it


@pytest.mark.parametrize("axes", GRIDS)
def test_a_grid_s_columns_are_the_mixed_radix_digits_of_any_range(axes):
    grid = Grid(axes)
    edges = [0, 1, grid.count - 1, grid.count] + [k * GRID_BLOCK + d for k in (1, 2) for d in (-3, 0, 5)]
    rng = np.random.default_rng(11)
    ranges = [(lo, min(grid.count, lo + n)) for lo in edges if lo <= grid.count for n in (0, 1, 2, 37, 1_000, 70_000)]
    ranges += [tuple(sorted(rng.integers(0, grid.count + 1, size=2))) for _ in range(6)]
    for lo, hi in ranges:
        if hi - lo > 5_000:  # (the plain rule over a few stretches of a long range: its ends and its middle)
            made = grid.columns(lo, hi)
            for at in (lo, (lo + hi) // 2, hi - 1_000):
                expected = _expected(axes, at, at + 1_000)
                assert {n: made[n][at - lo:at - lo + 1_000].tolist() for n in expected} == expected, (axes, lo, hi, at)
        else:
            assert {n: c.tolist() for n, c in grid.columns(lo, hi).items()} == _expected(axes, lo, hi), (axes, lo, hi)


def test_a_grid_of_huge_counts_makes_any_range_without_its_axes_values():
    """Counted axes are never made whole (an axis of 2^40 values costs nothing); the digits are right past
    2^64 combinations."""
    lengths = [3, 1 << 40, 1 << 30]
    grid = Grid(dict(zip("abc", lengths)))
    assert grid.count == 3 << 70
    for lo in (0, (1 << 30) - 2, (1 << 70) + 5, grid.count - 7):
        hi = min(grid.count, lo + 9)
        made = grid.columns(lo, hi)
        assert [list(row) for row in zip(*(made[n].tolist() for n in "abc"))] == [_digits(lengths, i) for i in range(lo, hi)]
    with pytest.raises(ValueError, match="more than a case's int64 column holds"):
        Grid({"a": 1 << 63})


def test_a_grid_s_blocks_are_the_same_made_again_and_in_any_order():
    """The columns a grid keeps for the next blocks (a period, a constant) are the same as made anew."""
    axes = {"a": 3, "b": [5, 6], "c": 1_000}
    kept = Grid(axes)
    order = [(0, 6_000), (6_000, 6_000), (1, 4), (2_999, 3_001), (0, 6_000), (1_000, 3_000), (1, 4), (5_999, 6_000)]
    for lo, hi in order:
        assert {n: c.tolist() for n, c in kept.columns(lo, hi).items()} == _expected(axes, lo, hi)
    fresh = Grid(axes)
    assert [c.tolist() for c in fresh.columns(1_000, 3_000).values()] == [c.tolist() for c in kept.columns(1_000, 3_000).values()]


def test_make_gets_read_only_columns_and_one_that_writes_into_them_gets_copies():
    """Columns are shared between blocks: a make that writes into its own gets writable copies (the same
    cases as before), and the next blocks' columns are unchanged."""
    calls = []

    def writes(a, b):
        calls.append(a.flags.writeable)
        a += 1
        return {"a": a, "b": b}
    grid = Grid({"a": 4, "b": 3}, writes)
    assert [c.tolist() for c in grid.block(0, 12).values()] == [[1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4], [0, 1, 2] * 4]
    assert [c.tolist() for c in grid.block(0, 12).values()] == [[1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4], [0, 1, 2] * 4]
    assert calls == [False, True, True]
    seen = Grid({"a": 4, "b": 3}, lambda a, b: {"a": a, "b": b, "w": a.flags.writeable})
    assert not seen.block(0, 12)["w"].any()
    assert seen.columns(0, 12)["b"].flags.writeable is False


def test_a_block_s_columns_are_each_axis_s_values_and_constants_of_every_kind():
    grid = Grid({"a": [7, 3], "b": 3}, lambda a, b: {"x": a, "y": b * 2, "k": 5, "u": np.uint8(200), "big": 2 ** 70})
    block = grid.block(1, 5)
    assert block["x"].tolist() == [7, 7, 3, 3] and block["y"].tolist() == [2, 4, 0, 2]
    assert block["k"].tolist() == [5] * 4 and block["u"].tolist() == [200] * 4
    assert block["big"].dtype == object  # (not a whole number within int64: made as numpy makes it, checked later)
    for axes, says in (({"a": {"x": [1, 2], "y": [3]}}, "different lengths"), ({"a": {}}, "no columns"),
                       ({"a": {"x": [1]}, "x": 2}, "column x is on two axes"), ({"a": {"x y": [1]}}, "identifier")):
        with pytest.raises(ValueError, match=says):
            Grid(axes)


def _spec(tmp_path: Path, name: str, body: str) -> Path:
    spec = (ROOT / "tests/data/sweeps/mul8_yielded.toml").read_text().replace(
        'file = "../../../asm/mul8.s"', f'file = "{ROOT / "asm/mul8.s"}"')
    folder = tmp_path / name  # (a module of its own each: none is cached under another's name)
    folder.mkdir()
    (folder / "yielded.py").write_text(f"import numpy as np\nfrom retro.routines.grid import Grid\ndef sweep():\n    {body}\n")
    (folder / "spec.toml").write_text(spec)
    return folder / "spec.toml"


@pytest.mark.parametrize("body, says", [
    # an axis's own column, passed on: its values in the block are checked (the block holding 256 is named)
    ('return Grid({"b": 2, "a": [*range(250), 256, 3]}, lambda a, b: {"a": a, "b": b})',
     "(Grid 1, cases 0..503): column a holds 256"),
    ('return Grid({"b": 1, "a": [*range(70_000), 4]}, lambda a, b: {"a": a % 256, "b": np.where(a == 69_999, 300, b)})',
     "(Grid 1, cases 65,472..70,000): column b holds 300"),  # a column make computed: every value (the block
    # named as the check cuts it: where its stream's blocks end, after the spec's 64 boundary cases)
    ('return Grid({"a": 256}, lambda a: {"a": a, "b": -1})', "column b holds -1"),  # a constant
    ('return Grid({"a": 256}, lambda a: {"a": a, "b": 1.5})', "column b must hold whole numbers"),
    ('return Grid({"a": 256}, lambda a: {"a": a, "b": 2 ** 70})', "column b must hold whole numbers"),
    ('return Grid({"a": 300}, lambda a: {"a": np.where(a == 299, -5, a % 256), "b": a % 256})', "column a holds -5"),
    ('return Grid({"a": 3, "b": 3}, lambda a, b: {"a": a, "b": b[:2]})', "column b has 2 cases"),
])
def test_every_value_a_grid_makes_is_checked_with_a_one_line_error(tmp_path, body, says):
    spec = _spec(tmp_path, "bad", body)
    with pytest.raises(InputError, match="cases.sweep") as caught:
        list(case_sets.stream(case_sets.plan(load_spec(spec), exhaustive=True, seed=1), GRID_BLOCK))
    assert says in str(caught.value) and "\n" not in str(caught.value), str(caught.value)


def test_a_grid_sweep_s_blocks_are_its_combinations_through_the_check_s_stream(tmp_path, monkeypatch):
    """The blocks a check makes of a grid hold each combination once, in order, from any case on; the grid
    makes them where the stream cuts its blocks (counted over every part), so that they pass on whole."""
    spec = _spec(tmp_path, "good", 'return Grid({"a": [5, 200, 9], "b": 256, "c": 131}, '
                                   'lambda a, b, c: {"a": (a + c) % 256, "b": b})')
    parts = [p for p in case_sets.plan(load_spec(spec), exhaustive=True, seed=1) if p.name == "sweep"]
    axes = {"a": [5, 200, 9], "b": 256, "c": 131}
    for first, size in ((0, GRID_BLOCK), (65_535, 4_096), (70_001, GRID_BLOCK)):
        blocks = list(case_sets.stream(parts, size, first))
        made = [np.concatenate(c).tolist() for c in zip(*blocks)]
        expected = _expected(axes, first, parts[0].count)
        assert made[0] == [(a + c) % 256 for a, c in zip(expected["a"], expected["c"])] and made[1] == expected["b"]
    every = case_sets.plan(load_spec(spec), exhaustive=True, seed=1)
    before = sum(p.count for p in every[:[p.name for p in every].index("sweep")])
    made = []
    real = Grid._axis_columns
    monkeypatch.setattr(Grid, "_axis_columns", lambda grid, lo, hi: made.append((lo, hi)) or real(grid, lo, hi))
    for first in (0, 4_096 * 20):
        made.clear()
        blocks = list(case_sets.stream(every, 4_096, first))
        assert made[0][0] == max(0, first - before) and all((before + lo) % 4_096 == 0 for lo, _ in made[1:]), made[:3]
        assert all(hi - lo == 4_096 for lo, hi in made[1:-1])


# ---- the built-in random generators: column blocks, the cases the per-case form made ---------------------

def _circle_random_per_case(rng: np.random.Generator, n: int) -> list[tuple]:
    """circle_random as it was written, one case at a time (the plain rule)."""
    import math
    cases = rng.integers(0, 256, size=(n, 6))
    tight = rng.random(n) < 0.5
    for i in np.flatnonzero(tight):
        x1, y1, _, x2, y2, _ = (int(v) for v in cases[i])
        radius_sum = math.isqrt((x1 - x2) ** 2 + (y1 - y2) ** 2) + int(rng.integers(0, 2))
        if radius_sum <= 255:
            cases[i, 2] = radius_sum // 2
            cases[i, 5] = radius_sum - radius_sum // 2
    return [tuple(int(v) for v in row) for row in cases]


def _aabb_sprite_random_per_case(rng: np.random.Generator, n: int) -> list[tuple]:
    x1 = rng.integers(0, 512, size=n)
    x2 = np.where(rng.random(n) < 0.6, (x1 + rng.integers(-48, 48, size=n)) % 512, rng.integers(0, 512, size=n))
    y1 = rng.integers(0, 256, size=n)
    y2 = np.where(rng.random(n) < 0.6, (y1 + rng.integers(-42, 42, size=n)) % 256, rng.integers(0, 256, size=n))
    small = rng.random(n) < 0.7
    boxes = np.where(small[:, None], rng.integers(0, 48, size=(n, 8)), rng.integers(0, 256, size=(n, 8)))
    return [(int(x1[i]) & 0xFF, int(x1[i]) >> 8, int(y1[i]), *map(int, boxes[i, :4]), int(x2[i]) & 0xFF, int(x2[i]) >> 8,
             int(y2[i]), *map(int, boxes[i, 4:])) for i in range(n)]


@pytest.mark.parametrize("name, per_case", [("circle", _circle_random_per_case), ("aabb_sprite", _aabb_sprite_random_per_case)])
def test_a_built_in_random_generator_s_columns_are_the_cases_drawn_one_at_a_time(name, per_case):
    from retro.routines import builtin_cases
    generator = getattr(builtin_cases, f"{name}_random")
    names = load_spec(ROOT / f"asm/{name}.toml").input_names
    for seed, n in ((0, 1), (1, 7), (2, 4_000), (3, 65_536)):
        made = generator(np.random.default_rng(seed), n)
        assert tuple(made) == names and all(c.dtype == np.int64 and c.flags.c_contiguous for c in made.values())
        assert list(zip(*(c.tolist() for c in made.values()))) == per_case(np.random.default_rng(seed), n), (seed, n)


def test_the_whole_square_root_of_every_sum_of_two_squared_byte_differences():
    import math
    from retro.routines.builtin_cases import _isqrt
    values = np.concatenate([np.arange(2 * 255 ** 2 + 2), np.arange(1, 3000) ** 2 - 1, [2 ** 50 - 1, 2 ** 50]])
    assert _isqrt(values).tolist() == [math.isqrt(int(v)) for v in values]


# ---- the exhaustive product: every combination of the swept inputs, in order ------------------------------

def _product_spec(tmp_path: Path) -> Path:
    """circle_r with its exhaustive inputs given odd values: a list out of order and a range not from 0."""
    text = (ROOT / "asm/circle_r.toml").read_text().replace('file = "circle_r.s"', f'file = "{ROOT / "asm/circle_r.s"}"')
    text = text.replace('exhaustive = ["x1", "radius_sum"]',
                        'exhaustive = { x1 = [9, 3, 200, 4, 77], y2 = "5..11", radius_sum = "1..255" }')
    spec = tmp_path / "product.toml"
    spec.write_text(text)
    return spec


def test_an_exhaustive_product_is_every_combination_in_order_and_its_draws_per_chunk(tmp_path):
    from itertools import product
    routine = load_spec(_product_spec(tmp_path))
    part = next(p for p in case_sets.plan(routine, exhaustive=True, seed=5, random=0) if p.name == "exhaustive")
    ports = routine.part_inputs("exhaustive")
    swept = [i for i, port in enumerate(ports) if port.name in routine.exhaustive]
    values = [list(ports[i].values.listed) if ports[i].values.listed else list(range(ports[i].values.lo, ports[i].values.hi + 1))
              for i in swept]
    combinations = list(product(*values))  # the plain rule: the last swept input varies fastest
    assert part.count == len(combinations) == 5 * 7 * 255
    made = [np.concatenate(c) for c in zip(*case_sets.rechunked(part.blocks(), 4_096))]
    assert list(zip(*(made[i].tolist() for i in swept))) == combinations
    rng = np.random.default_rng(5 + case_sets.EXHAUSTIVE_RNG_OFFSET)  # one block: the part's own generator
    drawn = {i: [] for i in range(len(ports)) if i not in swept}
    for at in range(0, part.count, case_sets.CHUNK):  # per CHUNK, input by input
        for i in drawn:
            drawn[i].append(case_sets._random_column(ports[i], rng, min(case_sets.CHUNK, part.count - at)))
    assert all(made[i].tolist() == np.concatenate(d).tolist() for i, d in drawn.items())
    for start in (1, 4_001, part.count - 3):
        assert [np.concatenate(c).tolist() for c in zip(*part.seek(start))] == [c[start:].tolist() for c in made]


def test_a_check_never_writes_into_a_grid_s_shared_columns():
    """A grid's columns are shared between blocks (kept periods, constants): the engines, the reference, the
    domain and the tally only read them."""
    from retro.analysis.check.run import array_block

    spec = str(ROOT / "asm/tile_box.toml")
    parts = [p for p in case_sets.plan(load_spec(spec), exhaustive=True, seed=0) if p.name == "sweep"]
    blocks = list(case_sets.stream(parts, 4_096))[:3]
    before = [[c.copy() for c in block] for block in blocks]
    for first, block in zip((0, 4_096, 8_192), blocks):
        array_block(spec, 0, block, first, 1, "batch", None)
    assert all(np.array_equal(a, b) for block, kept in zip(blocks, before) for a, b in zip(block, kept))
    again = list(case_sets.stream(parts, 4_096))[:3]
    assert all(np.array_equal(a, b) for block, kept in zip(again, before) for a, b in zip(block, kept))
