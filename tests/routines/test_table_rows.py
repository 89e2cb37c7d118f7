"""Table columns that are one row repeated (retro.routines.grid.repeated_row: a zero-stride view, what
pixel's sweep makes for its blocks of one mask pair) and the readers that take them at one row: each must
give what the same column copied row by row gives, and a column whose rows are not all one row must still
be read row by row."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from retro.errors import InputError
from retro.routines import builtin_cases, reference
from retro.routines import cases as case_sets
from retro.routines.grid import one_row, repeated_row
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[2]
PIXEL = str(ROOT / "asm/pixel.toml")


def _signed(byte: int) -> int:
    return byte - 256 if byte & 0x80 else byte


def _pixel_by_case(dx, dy, mask_a, mask_b) -> list[bool]:
    """The plain rule: reference.pixel on each case's own masks."""
    return [reference.pixel(_signed(int(x)), _signed(int(y)), reference.mask_bits(bytes(a.tolist())),
                            reference.mask_bits(bytes(b.tolist())))
            for x, y, a, b in zip(dx, dy, mask_a, mask_b)]


def _offsets(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Offset bytes, most of them where two masks can meet."""
    return rng.integers(-26, 27, size=n) & 0xFF, rng.integers(-23, 24, size=n) & 0xFF


def test_one_row_finds_a_repeated_row_and_nothing_else():
    row = np.arange(63)
    column = repeated_row(row, 1000)
    assert column.shape == (1000, 63) and column.dtype == np.int64 and not column.flags.writeable
    assert one_row(column).tolist() == row.tolist()
    assert one_row(column[10:20]).tolist() == row.tolist()  # a slice of it is still one row
    equal = np.tile(row, (1000, 1))  # every row equal, but rows of their own: read row by row
    assert one_row(equal) is None
    assert one_row(column[[0, 5, 9]]) is None  # picked rows are copies
    assert one_row(column[:0]) is None and one_row(np.arange(5)) is None


def test_pixel_mask_columns_of_one_pair_are_its_rows_repeated_and_of_several_the_rows_picked():
    masks = builtin_cases.pixel_masks(0)
    table = np.asarray(masks, dtype=np.int64)
    one = np.full(300, 4)
    mask_a, mask_b = builtin_cases._mask_columns(0, one)
    assert one_row(mask_a).tolist() == list(masks[4][0]) and one_row(mask_b).tolist() == list(masks[4][1])
    assert np.array_equal(mask_a, table[one, 0]) and np.array_equal(mask_b, table[one, 1])
    mixed = np.full(300, 4)
    mixed[150] = 9  # the ends are one pair, one case between is another
    mask_a, mask_b = builtin_cases._mask_columns(0, mixed)
    assert one_row(mask_a) is None and mask_a.dtype == np.int64 and mask_a.flags.c_contiguous
    assert np.array_equal(mask_a, table[mixed, 0]) and np.array_equal(mask_b, table[mixed, 1])


@pytest.mark.parametrize("layout", ["one pair", "one pair copied", "several pairs", "only the first repeated",
                                    "only the second repeated"])
def test_pixel_reference_on_arrays_is_the_reference_case_by_case(layout):
    masks = builtin_cases.pixel_masks(0)
    rng = np.random.default_rng(len(layout))
    n = 2_000
    dx, dy = _offsets(rng, n)
    first, second = masks[3]  # ring and dot: hits and misses near each other
    if layout.startswith("one pair"):
        mask_a, mask_b = repeated_row(first, n), repeated_row(second, n)
        if layout.endswith("copied"):
            mask_a, mask_b = mask_a.copy(), mask_b.copy()
    elif layout == "several pairs":
        mask_a, mask_b = builtin_cases._mask_columns(0, rng.integers(0, len(masks), size=n))
    else:  # one column one row repeated, the other's rows of several masks
        other = np.asarray([masks[k][0] for k in rng.integers(0, len(masks), size=n)], dtype=np.int64)
        mask_a, mask_b = ((repeated_row(first, n), other) if layout == "only the first repeated"
                          else (other, repeated_row(second, n)))
    got = builtin_cases.pixel_reference(dx, dy, mask_a, mask_b)
    expected = _pixel_by_case(dx, dy, mask_a, mask_b)
    assert got.tolist() == expected
    assert 0 < sum(expected) < n  # both answers occur


def test_the_compiled_engine_s_table_bytes_of_a_repeated_row_are_those_of_its_copy():
    from retro.analysis.check.engines import runner_for
    from retro.routines.batch_runs import _lane_bytes

    runner = runner_for(PIXEL, 0)
    masks = builtin_cases.pixel_masks(0)
    n = 100
    dx, dy = _offsets(np.random.default_rng(1), n)
    repeated = [dx, dy, repeated_row(masks[2][0], n), repeated_row(masks[2][1], n)]
    addresses, lanes = _lane_bytes(runner.plan, repeated, n)
    copied_addresses, copied = _lane_bytes(runner.plan, [c.copy() for c in repeated], n)
    assert np.array_equal(addresses, copied_addresses) and np.array_equal(lanes[:, :n], copied[:, :n])
    assert lanes.shape[0] == 126 and lanes[:, 0].tolist() == [*masks[2][0], *masks[2][1]]
    assert (lanes[:, :n] == lanes[:, :1]).all()


def test_lane_byte_rows_are_an_odd_number_of_cache_lines_wide():
    from retro.routines.batch_runs import CACHE_LINE, lane_row_width

    for n in (*range(0, 300), 4_000, 4_096, 8_000, 8_192, 65_536):
        width = lane_row_width(n)
        assert n <= width < n + 2 * CACHE_LINE and width % CACHE_LINE == 0 and (width // CACHE_LINE) % 2 == 1, n


@pytest.mark.parametrize("engine", ["batch", "compiled"])
def test_a_block_of_one_pair_tallies_as_its_copy_on_both_array_engines(engine):
    """pixel's sweep blocks come through the check's stream as one row repeated; tallied (entry-state reruns
    included), each is the same as its columns copied row by row."""
    from retro.analysis.check.run import array_block

    parts = [p for p in case_sets.plan(load_spec(PIXEL), exhaustive=True, seed=0) if p.name == "sweep"]
    blocks = case_sets.stream(parts, 8_192, 8_192 * 7)  # the last blocks of pair 0, the first of pair 1
    for first, block in zip(range(8_192 * 7, 8_192 * 10, 8_192), blocks):
        assert all(one_row(column) is not None for column in block[2:])
        ours, ours_entry = array_block(PIXEL, 0, block, first, 97, engine, None)
        theirs, theirs_entry = array_block(PIXEL, 0, [c.copy() for c in block], first, 97, engine, None)
        assert repr(sorted(vars(ours).items())) == repr(sorted(vars(theirs).items()))
        assert repr(ours_entry) == repr(theirs_entry)


def test_a_repeated_row_block_is_passed_on_whole_and_its_values_checked(tmp_path):
    row = np.arange(63)
    block = [np.arange(4_096), repeated_row(row, 4_096)]
    (made,) = list(case_sets.rechunked([block], 4_096))
    assert made[0] is block[0] and made[1] is block[1]
    routine = load_spec(PIXEL)
    bad = {"dx": np.zeros(10, dtype=np.int64), "dy": np.zeros(10, dtype=np.int64),
           "mask_a": repeated_row([*range(62), 256], 10), "mask_b": repeated_row(row, 10)}
    with pytest.raises(InputError, match="column mask_a holds 256"):
        case_sets._block_columns(routine, bad, "here")


def test_pixel_reference_on_mask_pairs_whose_hashes_collide_sorts_the_rows_themselves(monkeypatch):
    """Every row hashed alike (the hash's weights all 0): the check of each row against its pair's finds it,
    and the pairs come from the rows themselves."""
    monkeypatch.setattr(builtin_cases, "ROW_HASH", np.zeros_like(builtin_cases.ROW_HASH))
    masks = builtin_cases.pixel_masks(0)
    rng = np.random.default_rng(11)
    n = 1_000
    dx, dy = _offsets(rng, n)
    mask_a, mask_b = builtin_cases._mask_columns(0, rng.integers(0, len(masks), size=n))
    pairs, which = builtin_cases._mask_pairs(mask_a, mask_b)
    assert len(pairs) == len({(tuple(a), tuple(b)) for a, b in zip(mask_a.tolist(), mask_b.tolist())})
    assert np.array_equal(pairs[which], np.concatenate([mask_a, mask_b], axis=1))
    assert builtin_cases.pixel_reference(dx, dy, mask_a, mask_b).tolist() == _pixel_by_case(dx, dy, mask_a, mask_b)
