"""The data every broad phase takes and returns: a set of boxes with collision layers, and pairs.

Layers follow the category/mask scheme: each object has `layer` bits (what it is) and `mask` bits
(what it wants to hit). A pair (i, j) is a candidate only when each accepts the other:
`layer[i] & mask[j] != 0 and layer[j] & mask[i] != 0`. Example, "only enemies vs player bullets":
enemies have layer ENEMY, mask BULLET; bullets have layer BULLET, mask ENEMY; two enemies then never
pair up because ENEMY & BULLET == 0. Defaults: layer 1, mask all ones (everything hits everything).

Boxes use the strict edge convention of `retro.geometry.aabb`: touching boxes are not a pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.errors import InputError

ALL_LAYERS = 0xFFFFFFFF  # masks are 32-bit


def layers_match(layer_a: int, mask_a: int, layer_b: int, mask_b: int) -> bool:
    """True when each object's layer is in the other's mask."""
    return bool(layer_a & mask_b) and bool(layer_b & mask_a)


@dataclass(frozen=True)
class BoxSet:
    """N boxes as numpy arrays: mins and maxs of shape (N, 2), layers and masks of shape (N,)."""

    mins: np.ndarray
    maxs: np.ndarray
    layers: np.ndarray
    masks: np.ndarray

    @classmethod
    def from_arrays(cls, mins: object, maxs: object, layers: object = None, masks: object = None) -> "BoxSet":
        """Checked BoxSet: finite coordinates, min <= max, layers/masks 32-bit unsigned."""
        lo = np.asarray(mins, dtype=np.float64)
        hi = np.asarray(maxs, dtype=np.float64)
        if lo.ndim != 2 or lo.shape[1:] != (2,) or hi.shape != lo.shape:
            raise InputError(f"boxes: mins and maxs must both have shape (N, 2), got {lo.shape} and {hi.shape}")
        n = len(lo)
        for name, arr in (("mins", lo), ("maxs", hi)):
            bad = ~np.isfinite(arr).all(axis=1)
            if bad.any():
                raise InputError(f"boxes: {name}[{int(np.argmax(bad))}] is not finite")
        inverted = (lo > hi).any(axis=1)
        if inverted.any():
            raise InputError(f"boxes: box {int(np.argmax(inverted))} has min greater than max")

        def bits(values: object, name: str, default: int) -> np.ndarray:
            if values is None:
                return np.full(n, default, dtype=np.int64)
            arr = np.asarray(values)
            if arr.shape != (n,) or not np.issubdtype(arr.dtype, np.integer):
                raise InputError(f"boxes: {name} must be {n} integers")
            if n and (arr.min() < 0 or arr.max() > ALL_LAYERS):
                raise InputError(f"boxes: {name} must be 32-bit unsigned integers")
            return arr.astype(np.int64)

        return cls(lo, hi, bits(layers, "layers", 1), bits(masks, "masks", ALL_LAYERS))

    def __len__(self) -> int:
        return len(self.mins)

    def columns(self) -> tuple[list[float], list[float], list[float], list[float], list[int], list[int]]:
        """x0, y0, x1, y1, layers, masks as Python lists (fast to index in a Python loop)."""
        return (self.mins[:, 0].tolist(), self.mins[:, 1].tolist(), self.maxs[:, 0].tolist(),
                self.maxs[:, 1].tolist(), self.layers.tolist(), self.masks.tolist())


@dataclass(frozen=True)
class PairResult:
    """Candidate pairs (i < j, sorted) whose boxes overlap and whose layers match, and how many
    box-vs-box tests the method performed to find them (the machine-independent cost)."""

    pairs: list[tuple[int, int]]
    tests: int
