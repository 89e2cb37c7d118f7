"""A seekable sweep: every combination of a few axes' values, made into a spec's inputs.

A spec's `sweep` function may return a `Grid` (or a list of them) instead of yielding its cases. A grid
says how many cases it makes (the product of its axes' lengths) and makes any range of them without the
ones before it (mixed-radix counting, the last axis varying fastest), so a check's tasks are a range
of case indices and each worker makes only its own (docs/dask.md). `make` turns the axes' columns into
a column block of the routine's inputs (constants allowed: they are broadcast); without it the axes are
the inputs themselves. An axis may also be several inputs whose values go together (a dict of equal-length
value lists by input name: one value of the axis is one row); a one-value axis is a constant.

    def sweep():
        return Grid({"x": 512, "y": 256}, lambda x, y: {"x": x & 0xFF, "xh": x >> 8, "y": y})

    def sweep():  # the same cases, made without a make: its columns are kept from block to block
        x = np.arange(512)
        return Grid({"x": {"x": x & 0xFF, "xh": x >> 8}, "y": 256})

`make` is called per block of combinations (its columns read-only: they may be shared between blocks),
and must make each case from that case's own values alone: where the blocks are cut is not fixed.

Only numpy here: the specs' own modules import it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

GRID_BLOCK = 1 << 16  # combinations made at once (one call of `make`)


class Grid:
    """Every combination of `axes` (name -> a count n for 0..n-1, the values themselves in order, or a dict
    of equal-length value lists by column name: columns whose values go together), the last axis varying
    fastest; `make(**columns)` gives the column block of the routine's inputs by name (numpy arrays, one
    element or row per combination, or single numbers), or None: the axes' columns are the inputs."""

    def __init__(self, axes: Mapping[str, int | Sequence[int] | Mapping[str, Sequence[int]]],
                 make: Callable[..., Mapping] | None = None) -> None:
        if not isinstance(axes, Mapping) or not axes:
            raise ValueError("Grid: axes must be a non-empty dict of name -> count or values")
        if make is not None and not callable(make):
            raise ValueError(f"Grid: make must be a function, got {type(make).__name__}")
        self.names = tuple(axes)
        self.axis_columns = tuple(_axis(name, axis) for name, axis in axes.items())  # per axis: (column, values)
        self.lengths = tuple(_length(columns[0][1]) for columns in self.axis_columns)
        names = [name for columns in self.axis_columns for name, _ in columns]
        twice = next((name for name in names if names.count(name) > 1), None)
        if twice is not None:
            raise ValueError(f"Grid: column {twice} is on two axes")
        self.make = make
        self.count = int(np.prod(self.lengths, dtype=object))
        self._kept: dict[tuple[int, int, int], _Column] = {}  # periodic columns by (axis, column, block length)
        self._kept_bytes = 0
        self._writes_inputs = False  # make writes into its columns: it gets copies

    def __repr__(self) -> str:
        return f"Grid({', '.join(f'{n}: {length}' for n, length in zip(self.names, self.lengths))})"

    def columns(self, lo: int, hi: int) -> dict[str, np.ndarray]:
        """The axes' columns of combinations lo..hi-1, by axis name (read-only views: a column may be shared
        with other blocks)."""
        return {name: _read_only(column.array) for name, column in self._axis_columns(lo, hi)}

    def block(self, lo: int, hi: int, make: Callable[..., Mapping] | None = None) -> dict[str, np.ndarray]:
        """The column block of combinations lo..hi-1: `make` (default: the grid's own, which a caller may
        pass guarded) over the axes' columns, constants broadcast to the block's length."""
        return self.made_block(lo, hi, make)[0]

    def made_block(self, lo: int, hi: int, make: Callable[..., Mapping] | None = None
                   ) -> tuple[dict[str, np.ndarray], dict[str, tuple[int, int]]]:
        """`block`, and the least and greatest value of each of its columns that holds only values the grid
        chose (an axis's column passed through `make` unchanged, or a constant): the values of the other
        columns are the caller's to check. `make` gets read-only columns (shared between blocks); one that
        writes into them gets its own writable copies from then on (called again for this block)."""
        made_columns = self._axis_columns(lo, hi)
        make = make or self.make
        if make is None:
            return ({name: axis.array for name, axis in made_columns}, {name: axis.extremes for name, axis in made_columns})
        given = {}  # id of the array make got -> (that array, the column it stands for)
        if not self._writes_inputs:
            arguments = {}
            for name, axis in made_columns:
                view = _read_only(axis.array)
                arguments[name] = view
                given[id(view)] = (view, axis)
            try:
                made = make(**arguments)
            except Exception as exc:  # (a guarded make raises UserCodeError)
                if "read-only" not in str(exc):
                    raise
                self._writes_inputs = True
        if self._writes_inputs:
            given = {}
            made = make(**{name: axis.array.copy() for name, axis in made_columns})
        if not isinstance(made, Mapping):
            raise ValueError(f"Grid: make must return a dict of columns by input name, got {type(made).__name__}")
        n = hi - lo
        block, known = {}, {}
        for name, value in made.items():
            entry = given.get(id(value))
            if entry is not None and entry[0] is value:  # an axis's column, unchanged (make could not write it)
                block[name], known[name] = entry[1].array, entry[1].extremes
            elif np.ndim(value) == 0:
                constant = _constant(value, n)
                if constant is None:
                    block[name] = np.full(n, value)
                else:
                    block[name], known[name] = constant, (int(value), int(value))
            else:
                block[name] = np.asarray(value)
        return block, known

    def blocks(self, start: int = 0, size: int = GRID_BLOCK) -> Iterator[dict[str, np.ndarray]]:
        """Column blocks of combinations start..count-1, `size` at a time (cut at multiples of `size`,
        so the blocks are the same whatever the start)."""
        lo = start
        while lo < self.count:
            hi = min(self.count, (lo // size + 1) * size)
            yield self.block(lo, hi)
            lo = hi

    def _axis_columns(self, lo: int, hi: int) -> list[tuple[str, _Column]]:
        """Each axis's columns of combinations lo..hi-1, by name, in axis order. Axis k's digit of combination
        i is (i // s) % r, s the product of the later axes' lengths (its stride), r its own length: over a
        range of i, runs of s equal digits, the digits counting up modulo r; the column repeats every r * s
        combinations. A column whose period is short enough (PERIODIC_LIMIT) and repeats in the grid (one
        that fits a block, or REPEATS_LAID_OUT periods in all; the later axes first, within half of
        KEPT_BYTES for a block length) is a view into its periods laid out once (kept: every block reads its
        own stretch of them, made by none); another one is made from its runs."""
        n = hi - lo
        if not 0 <= lo <= hi <= self.count:
            raise ValueError(f"Grid: combinations {lo}..{hi - 1} are not within 0..{self.count - 1}")
        if not n:
            return [(name, _Column(np.zeros(0, dtype=np.int64), (0, 0))) for columns in self.axis_columns
                    for name, _ in columns]
        made = []
        stride = 1
        budget = KEPT_BYTES // 2  # what this block length's laid-out columns may hold (no churn in the kept ones)
        for index in reversed(range(len(self.axis_columns))):
            radix = self.lengths[index]
            period = radix * stride
            laid_out = (period + n - 1) * 8 * len(self.axis_columns[index])
            if period + n - 1 <= PERIODIC_LIMIT and (period <= n or REPEATS_LAID_OUT * period <= self.count) \
                    and laid_out <= budget:
                budget -= laid_out
                made.append([(name, self._periodic(index, k, stride, lo % period, n))
                             for k, (name, _) in enumerate(self.axis_columns[index])])
            else:
                first, last = lo // stride, (hi - 1) // stride  # the runs' numbers (Python ints: no overflow)
                digits = (first % radix + np.arange(last - first + 1, dtype=np.int64)) % radix
                runs = np.full(len(digits), min(stride, n), dtype=np.int64)  # (a middle run: stride < n)
                runs[0] = min((first + 1) * stride, hi) - lo
                runs[-1] = hi - max(last * stride, lo)
                made.append([(name, _runs(_at(values, digits), runs, n)) for name, values in self.axis_columns[index]])
            stride = period
        return [column for columns in made[::-1] for column in columns]

    def _periodic(self, index: int, column: int, stride: int, phase: int, n: int) -> _Column:
        """Axis `index`'s `column` over n combinations from `phase` into its period: a view into the period
        repeated over period + n - 1 combinations (every phase's n fit in it), made once per block length."""
        key = (index, column, n)
        kept = self._kept.get(key)
        if kept is None:
            values = _at(self.axis_columns[index][column][1], np.arange(self.lengths[index], dtype=np.int64))
            period = np.repeat(values, stride) if stride > 1 else values
            array = np.empty(len(period) + n - 1, dtype=np.int64)
            filled = min(len(array), len(period))
            array[:filled] = period[:filled]
            while filled < len(array):  # doubling: whole periods copied from the start
                more = min(filled, len(array) - filled)
                array[filled:filled + more] = array[:more]
                filled += more
            kept = _Column(array, (int(values.min()), int(values.max())) if len(values) else (0, 0))
            with _keeping:
                if key not in self._kept:
                    self._kept[key] = kept
                    self._kept_bytes += array.nbytes
                while self._kept_bytes > KEPT_BYTES and len(self._kept) > 1:
                    self._kept_bytes -= self._kept.pop(next(iter(self._kept))).array.nbytes
        return _Column(kept.array[phase:phase + n], kept.extremes)


def _runs(held: np.ndarray, runs: np.ndarray, n: int) -> _Column:
    """The column of `held`'s values, each repeated its run's length (n in all)."""
    if len(held) == 1:
        return _Column(_constant_column(int(held[0]), n), (int(held[0]),) * 2)
    return _Column(np.repeat(held, runs) if len(held) < n else held, (int(held.min()), int(held.max())))


@dataclass(frozen=True)
class _Column:
    array: np.ndarray  # int64; shared with other blocks (kept, or a constant): read, never written
    extremes: tuple[int, int]  # its least and greatest value


KEPT_BYTES = 16 << 20  # a grid's periodic columns kept for the blocks after (several axes and columns)
PERIODIC_LIMIT = 1 << 18  # combinations of a periodic column laid out (2 MiB): a longer period is made from its
# runs per block (circle's dy columns, a period of 511 x 256 over blocks of 65,536, are views: no np.repeat a block)
REPEATS_LAID_OUT = 4  # ... when the grid holds this many of its periods (else laying it out costs more than the runs
# its few blocks make: tile_box's X, whose one period is the whole grid of two blocks)
CONSTANTS_KEPT = 16  # constant columns kept (a make's constants, an axis held for a block: the same in the next ones)
_constants: dict[tuple[int, int], np.ndarray] = {}
_keeping = threading.Lock()  # the kept columns' dicts (a worker may make blocks on several threads)


def _constant(value, n: int) -> np.ndarray | None:
    """The int64 column of n copies of `value`, when it is a whole number within int64 (else None: made as
    numpy makes it, for the caller's checks to report)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        return None
    if not -(1 << 63) <= int(value) < 1 << 63:
        return None
    return _constant_column(int(value), n)


def _constant_column(value: int, n: int) -> np.ndarray:
    key = (value, n)
    with _keeping:
        column = _constants.pop(key, None)  # (put back last: the most recently used go last)
        if column is not None:
            _constants[key] = column
            return column
    column = np.full(n, value, dtype=np.int64)
    with _keeping:
        while len(_constants) >= CONSTANTS_KEPT:
            _constants.pop(next(iter(_constants)))
        _constants[key] = column
    return column


def repeated_row(row, n: int) -> np.ndarray:
    """n copies of one row as an (n, len(row)) int64 table column without copying it (a read-only view
    of the row with a zero stride): a block whose cases all hold the same table (pixel's sweep, one
    mask pair a block). `one_row` finds the row again, so the column's readers do its work once."""
    row = np.asarray(row, dtype=np.int64)
    return np.broadcast_to(row, (n, len(row)))


def one_row(column: np.ndarray) -> np.ndarray | None:
    """The row every row of a table column is, when the column is one row repeated by a zero stride
    (`repeated_row`, or a slice of it); else None, whatever its rows hold (not looked at)."""
    if column.ndim != 2 or not len(column) or column.strides[0] != 0:
        return None
    return column[0]


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view of `array`."""
    view = array.view()
    view.flags.writeable = False
    return view


def _axis(name: str, axis) -> tuple[tuple[str, np.ndarray], ...]:
    """An axis's columns: (name, values as int64) for each."""
    if isinstance(axis, Mapping):
        if not axis:
            raise ValueError(f"Grid: axis {name} has no columns")
        columns = tuple((column, _values(column, values)) for column, values in axis.items())
        if len({_length(values) for _, values in columns}) > 1:
            raise ValueError(f"Grid: axis {name}'s columns have different lengths "
                             f"({', '.join(f'{c}: {_length(v)}' for c, v in columns)})")
        return columns
    return ((name, _values(name, axis)),)


def _values(name: str, axis: int | Sequence[int]) -> np.ndarray | int:
    """An axis column's values as int64, or its count n when they are 0..n-1 (never made: a count may be huge)."""
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"Grid: axis name {name!r} is not an identifier (make takes the axes as keywords)")
    if isinstance(axis, (int, np.integer)) and not isinstance(axis, bool):
        if axis < 0:
            raise ValueError(f"Grid: axis {name} has a negative count {axis}")
        if axis > COUNT_LIMIT:
            raise ValueError(f"Grid: axis {name} has {int(axis):,} values, more than a case's int64 column holds")
        return int(axis)
    try:
        values = np.asarray(list(axis) if not isinstance(axis, np.ndarray) else axis)
    except TypeError:
        raise ValueError(f"Grid: axis {name} must be a count or a sequence of whole numbers, got "
                         f"{type(axis).__name__}") from None
    if values.ndim != 1 or (values.size and (values.dtype == bool or not np.issubdtype(values.dtype, np.integer))):
        raise ValueError(f"Grid: axis {name} must be a count or a sequence of whole numbers")
    return values.astype(np.int64)


COUNT_LIMIT = 1 << 62  # an axis counted 0..n-1: its digits stay within int64


def _length(values: np.ndarray | int) -> int:
    return values if isinstance(values, int) else len(values)


def _at(values: np.ndarray | int, digits: np.ndarray) -> np.ndarray:
    """An axis column's values at `digits` (a counted axis's values are its digits)."""
    return digits if isinstance(values, int) else values[digits]
