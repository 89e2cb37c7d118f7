"""A seekable sweep: every combination of a few axes' values, made into a spec's inputs.

A spec's `sweep` function may return a `Grid` (or a list of them) instead of yielding its cases. A grid
says how many cases it makes (the product of its axes' lengths) and makes any range of them without the
ones before it (mixed-radix counting, the last axis varying fastest), so a check's tasks are a range
of case indices and each worker makes only its own (docs/dask.md). `make` turns the axes' columns into
a column block of the routine's inputs (constants allowed: they are broadcast); without it the axes are
the inputs themselves.

    def sweep():
        return Grid({"x": 512, "y": 256}, lambda x, y: {"x": x & 0xFF, "xh": x >> 8, "y": y})

Only numpy here: the specs' own modules import it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence

import numpy as np

GRID_BLOCK = 1 << 16  # combinations made at once (one call of `make`)


class Grid:
    """Every combination of `axes` (name -> a count n for 0..n-1, or the values themselves, in order), the
    last axis varying fastest; `make(**columns)` gives the column block of the routine's inputs by name
    (numpy arrays, one element or row per combination, or single numbers), or None: the axes are the inputs."""

    def __init__(self, axes: Mapping[str, int | Sequence[int]], make: Callable[..., Mapping] | None = None) -> None:
        if not isinstance(axes, Mapping) or not axes:
            raise ValueError("Grid: axes must be a non-empty dict of name -> count or values")
        if make is not None and not callable(make):
            raise ValueError(f"Grid: make must be a function, got {type(make).__name__}")
        self.names = tuple(axes)
        self.values = tuple(_axis(name, axis) for name, axis in axes.items())
        self.make = make
        self.count = int(np.prod([len(v) for v in self.values], dtype=object))

    def __repr__(self) -> str:
        return f"Grid({', '.join(f'{n}: {len(v)}' for n, v in zip(self.names, self.values))})"

    def columns(self, lo: int, hi: int) -> dict[str, np.ndarray]:
        """The axes' columns of combinations lo..hi-1, by axis name."""
        rest = np.arange(lo, hi, dtype=np.uint64)
        columns = {}
        for name, values in zip(reversed(self.names), reversed(self.values)):
            radix = np.uint64(len(values))
            columns[name] = values[(rest % radix).astype(np.int64)]
            rest //= radix
        return {name: columns[name] for name in self.names}

    def block(self, lo: int, hi: int, make: Callable[..., Mapping] | None = None) -> dict[str, np.ndarray]:
        """The column block of combinations lo..hi-1: `make` (default: the grid's own, which a caller may
        pass guarded) over the axes' columns, constants broadcast to the block's length."""
        columns = self.columns(lo, hi)
        make = make or self.make
        made = columns if make is None else make(**columns)
        if not isinstance(made, Mapping):
            raise ValueError(f"Grid: make must return a dict of columns by input name, got {type(made).__name__}")
        return {name: np.full(hi - lo, value) if np.ndim(value) == 0 else np.asarray(value)
                for name, value in made.items()}

    def blocks(self, start: int = 0, size: int = GRID_BLOCK) -> Iterator[dict[str, np.ndarray]]:
        """Column blocks of combinations start..count-1, `size` at a time (cut at multiples of `size`,
        so the blocks are the same whatever the start)."""
        lo = start
        while lo < self.count:
            hi = min(self.count, (lo // size + 1) * size)
            yield self.block(lo, hi)
            lo = hi


def _axis(name: str, axis: int | Sequence[int]) -> np.ndarray:
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"Grid: axis name {name!r} is not an identifier (make takes the axes as keywords)")
    if isinstance(axis, (int, np.integer)) and not isinstance(axis, bool):
        if axis < 0:
            raise ValueError(f"Grid: axis {name} has a negative count {axis}")
        return np.arange(int(axis), dtype=np.int64)
    try:
        values = np.asarray(list(axis) if not isinstance(axis, np.ndarray) else axis)
    except TypeError:
        raise ValueError(f"Grid: axis {name} must be a count or a sequence of whole numbers, got "
                         f"{type(axis).__name__}") from None
    if values.ndim != 1 or (values.size and (values.dtype == bool or not np.issubdtype(values.dtype, np.integer))):
        raise ValueError(f"Grid: axis {name} must be a count or a sequence of whole numbers")
    return values.astype(np.int64)
