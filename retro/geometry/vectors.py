"""Checked 2-D points and the few vector operations the geometry modules share.

Every public geometry function passes its inputs through `as_point` / `as_points` first, so bad
input (not a pair, NaN, infinity) fails with an InputError naming the argument instead of
producing a wrong answer downstream.

Integers stay integers: `as_point((3, 4))` returns `(3, 4)`, so tests such as box overlap or
squared circle distances are exact on integer (pixel) coordinates.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

import numpy as np

from retro.errors import InputError

Number = int | float
Point = tuple[Number, Number]
PointLike = Sequence[float] | np.ndarray


def as_number(value: object, name: str) -> Number:
    """A finite int or float; numpy scalars are converted to the Python type."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{name}: expected a number, got {value!r}")
    if isinstance(value, numbers.Integral):
        return int(value)
    number = float(value)
    if not math.isfinite(number):
        raise InputError(f"{name}: must be finite, got {number}")
    return number


def as_point(p: object, name: str = "point") -> Point:
    """An (x, y) pair of finite numbers, or InputError naming `name`."""
    if isinstance(p, (str, bytes)):
        raise InputError(f"{name}: expected an (x, y) pair, got {p!r}")
    try:
        x, y = p  # type: ignore[misc]
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected an (x, y) pair, got {p!r}") from None
    return as_number(x, f"{name}.x"), as_number(y, f"{name}.y")


def as_points(points: object, name: str = "points") -> np.ndarray:
    """An (n, 2) float64 array of finite coordinates, or InputError naming `name` and the vertex."""
    try:
        array = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a sequence of (x, y) pairs") from None
    if array.ndim != 2 or array.shape[1] != 2:
        raise InputError(f"{name}: expected a sequence of (x, y) pairs, got shape {array.shape}")
    bad = ~np.isfinite(array).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"{name}: vertex {i} is not finite: ({array[i, 0]}, {array[i, 1]})")
    return array


def as_positive(value: object, name: str) -> Number:
    number = as_number(value, name)
    if number <= 0:
        raise InputError(f"{name}: must be > 0, got {number}")
    return number


def as_nonzero_vector(v: object, name: str) -> Point:
    x, y = as_point(v, name)
    if x == 0 and y == 0:
        raise InputError(f"{name}: zero-length vector (a ray needs a direction)")
    return x, y


def dot(ax: float, ay: float, bx: float, by: float) -> float:
    return ax * bx + ay * by


def cross(ax: float, ay: float, bx: float, by: float) -> float:
    """z of the 3-D cross product: > 0 when b turns counter-clockwise from a (y up)."""
    return ax * by - ay * bx


def normalize(x: float, y: float) -> tuple[float, float]:
    length = math.hypot(x, y)
    if length == 0:
        raise InputError("vector: cannot normalize a zero-length vector")
    return x / length, y / length
