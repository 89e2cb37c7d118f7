"""The study's corpus: pairs of sprite shapes at every relative offset where their sprite boxes meet,
and the ground truth for each case.

A shape is the opacity mask of a sprite as the VIC-II displays it, indexed [y, x] in screen pixels
(hires: a `1` bit is opaque; multicolor: the pairs 01, 10 and 11 are opaque and every pair is two
pixels wide, so a multicolor sprite is still 24 screen pixels wide). See retro.sprites for the
decoding.

Offsets: (dx, dy) is the position of shape b's top-left pixel relative to shape a's (the convention
of retro.geometry.masks). A pair's cases are all integer offsets where the two *full sprite boxes*
share at least one pixel: dx in [-(wb-1), wa-1] and dy in [-(hb-1), ha-1], i.e. 47 x 41 = 1927 cases
for two unexpanded sprites. Outside that range no method except a deliberately padded one could
report a hit, so including more offsets would only inflate every method's true negatives.

Ground truth: the number of screen pixels opaque in both sprites at that offset; a case collides
when that number is at least one, which is exactly when the VIC-II sets both sprites' bits in $D01E.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from retro.errors import InputError
from retro.paths import SPRITES_DIR

# The shapes the issue names (round, ring, ship, bullet, thin bar, pentagon, L-shape), by file stem,
# and a multicolor one whose rim is the 01 pair (opaque on the VIC-II although it is "colour 1").
DEFAULT_SHAPES = ("ball", "ring", "ship", "bullet", "bar", "pentagon", "lshape", "mc_gem")
# A reduced corpus for CI and `retro demo`: a round, a thin and a multicolor shape.
REDUCED_SHAPES = ("ball", "bar", "mc_gem")


@dataclass(frozen=True)
class Shape:
    """A sprite's opacity mask in screen pixels and where it came from."""

    name: str
    mask: np.ndarray  # bool [y, x]
    multicolor: bool = False
    source: str = ""
    data: bytes | None = None  # the 63 sprite bytes, when the shape came from a sprite file
    expand_x: bool = False  # the mask is already doubled; these say how the VIC-II must show it
    expand_y: bool = False

    def __post_init__(self) -> None:
        if self.mask.ndim != 2 or self.mask.dtype != bool:
            raise InputError(f"{self.source or self.name}: shape mask must be a 2-D bool array")
        if not self.mask.any():
            raise InputError(f"{self.source or self.name}: sprite has no opaque pixel, nothing can collide")

    @property
    def height(self) -> int:
        return int(self.mask.shape[0])

    @property
    def width(self) -> int:
        return int(self.mask.shape[1])


@dataclass(frozen=True)
class Pair:
    """Every case of one shape pair: offsets flattened in row-major (dy, dx) order, with ground truth."""

    a: Shape
    b: Shape
    dx: np.ndarray  # int, one per case
    dy: np.ndarray
    overlap: np.ndarray = field(repr=False)  # int: pixels opaque in both sprites

    @property
    def name(self) -> str:
        return f"{self.a.name}+{self.b.name}"

    @property
    def truth(self) -> np.ndarray:
        return self.overlap > 0

    @property
    def cases(self) -> int:
        return int(self.dx.size)


def offset_grid(a: Shape, b: Shape) -> tuple[np.ndarray, np.ndarray]:
    """Flattened (dx, dy) of every offset where the full sprite boxes of a and b share a pixel."""
    dys, dxs = np.meshgrid(np.arange(-(b.height - 1), a.height), np.arange(-(b.width - 1), a.width), indexing="ij")
    return dxs.ravel(), dys.ravel()


def overlap_counts(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pixels set in both masks for every offset of b relative to a at once.

    Result [dy + hb - 1, dx + wb - 1]: a is padded by b's size minus one on every side, and each
    b-sized window of the padded a is the part of a under b at one offset.
    """
    hb, wb = b.shape
    padded = np.pad(a.astype(np.int32), ((hb - 1, hb - 1), (wb - 1, wb - 1)))
    windows = sliding_window_view(padded, (hb, wb))
    return np.einsum("ijkl,kl->ij", windows, b.astype(np.int32))


def make_pair(a: Shape, b: Shape) -> Pair:
    dx, dy = offset_grid(a, b)
    return Pair(a=a, b=b, dx=dx, dy=dy, overlap=overlap_counts(a.mask, b.mask).ravel())


def pair_at(a: Shape, b: Shape, offsets: list[tuple[int, int]]) -> Pair:
    """A pair with the given offsets only (they may lie where the sprite boxes do not meet: their
    overlap is 0 there), for the scenarios of the stability study."""
    counts = overlap_counts(a.mask, b.mask)
    dx = np.array([o[0] for o in offsets], dtype=np.int64)
    dy = np.array([o[1] for o in offsets], dtype=np.int64)
    row, col = dy + b.height - 1, dx + b.width - 1
    inside = (row >= 0) & (row < counts.shape[0]) & (col >= 0) & (col < counts.shape[1])
    overlap = np.zeros(dx.shape, dtype=counts.dtype)
    overlap[inside] = counts[row[inside], col[inside]]
    return Pair(a=a, b=b, dx=dx, dy=dy, overlap=overlap)


def load_shape(path: Path) -> Shape:
    """A sprite file as a shape (frame 0), decoded by retro.sprites with the VIC-II's opacity rules."""
    from retro.analysis.study.sprites_io import sprite_opacity

    mask, multicolor, data = sprite_opacity(path)
    return Shape(name=path.stem, mask=mask, multicolor=multicolor, source=str(path), data=data)


def load_shapes(names: tuple[str, ...] | list[str] = DEFAULT_SHAPES, directory: Path = SPRITES_DIR) -> list[Shape]:
    """Shapes by file stem from the sprites directory; a missing one is an InputError naming it."""
    shapes = []
    for name in names:
        path = directory / f"{name}.spr"
        if not path.exists():
            available = ", ".join(sorted(p.stem for p in directory.glob("*.spr"))) or "none"
            raise InputError(f"{path}: sprite not found (available in {directory}: {available})")
        shapes.append(load_shape(path))
    return shapes
