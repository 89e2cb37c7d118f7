"""Case generators of the built-in routines (asm/*.toml name them as `boundary`, `sweep` and
`random_generator`), and the adapters their specs need.

Cases are tuples in each spec's input order (the reference's argument order) where there are few (the
boundaries), column blocks (dicts of numpy arrays by the specs' input names) where there are many (the
random generators: no Python object per value); the sweeps are grids (retro.routines.grid: counted,
entered at any case by the worker whose range it is):
- boundary: touching, one apart, overlapping by one, 0, 255/256, maximum sizes, screen edges;
- sweep (with --exhaustive): mul8 and mul16 every product; tile every 9-bit X by every Y; pixel every (dx, dy)
  for three mask pairs; circle and circle_r every (dx, dy) of both signs at every radius sum;
  exhaustive slices across each domain boundary for the others;
- random: distributions that put half the cases near the answer's edge.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from functools import lru_cache
from itertools import product

import numpy as np

from retro.chips.vic.constants import SPRITE_HEIGHT, SPRITE_WIDTH
from retro.chips.vic.constants import SPRITE_X_POSITIONS as X_POSITIONS  # 9-bit X
from retro.routines import reference
from retro.routines.grid import Grid, one_row, repeated_row
from retro.chips.vic.screen import SPRITE_ROW_BYTES

BYTE = 256
MASK_BYTES = SPRITE_HEIGHT * SPRITE_ROW_BYTES


# ---- shared generators ----------------------------------------------------------------------

def _interval_configs() -> list[tuple[int, int, int, int]]:
    """(a, aw, b, bw) on one axis: touching, one apart, overlapping by one, nested, 0/255 ends."""
    configs = []
    for a, aw in ((0, 1), (10, 8), (100, 24), (200, 55), (250, 5), (230, 26), (255, 1), (128, 127), (0, 255)):
        for b in {a - 2, a - 1, a, a + 1, a + aw - 2, a + aw - 1, a + aw, a + aw + 1}:
            for bw in (1, 2, 8, 255, a + aw - b if a + aw > b else 1, max(a - b, 1), max(a - b + 1, 1)):
                if 0 <= b <= 255 and 0 <= bw <= 255:
                    configs.append((a, aw, b, bw))
    return sorted(set(configs))


def _axis_pairs(limit: int) -> list[tuple[tuple, tuple]]:
    configs = _interval_configs()
    rng = np.random.default_rng(5)
    picked = [configs[i] for i in rng.choice(len(configs), size=min(limit, len(configs)), replace=False)]
    return [(x, y) for x in picked for y in picked[: max(1, limit // 4)]]


def _bytes(rng: np.random.Generator, n: int, columns: int) -> np.ndarray:
    return rng.integers(0, BYTE, size=(n, columns))


def _block(names: tuple[str, ...], columns) -> dict[str, np.ndarray]:
    """A column block by input name (each column its own contiguous int64 array): what a generator returns
    instead of tuples, the same cases without a Python object per value."""
    return {name: np.ascontiguousarray(column, dtype=np.int64) for name, column in zip(names, columns, strict=True)}


# ---- aabb8 -----------------------------------------------------------------------------------

def aabb8_boundary() -> list[tuple]:
    out = []
    for (ax, aw, bx, bw), (ay, ah, by, bh) in _axis_pairs(60):
        out.append((ax, ay, aw, ah, bx, by, bw, bh))
        out.append((bx, by, bw, bh, ax, ay, aw, ah))
    for size in (0, 1):
        out.append((10, 10, size, 5, 10, 10, 5, 5))
        out.append((10, 10, 5, 5, 12, 10, size, 5))
        out.append((10, 10, 5, size, 10, 12, 5, 5))
        out.append((10, 12, 5, 5, 10, 10, 5, size))
    return out


AABB8_INPUTS = ("ax", "ay", "aw", "ah", "bx", "by", "bw", "bh")  # asm/aabb8.toml's inputs, in order


def aabb8_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    cases = _bytes(rng, n, 8)
    near = rng.random(n) < 0.5  # half the cases: b placed near a, so overlaps are common
    cases[near, 4] = (cases[near, 0] + rng.integers(-40, 40, size=near.sum())) % BYTE
    cases[near, 5] = (cases[near, 1] + rng.integers(-40, 40, size=near.sum())) % BYTE
    small = rng.random(n) < 0.5
    cases[small, 2:4] = rng.integers(0, 48, size=(small.sum(), 2))
    cases[small, 6:8] = rng.integers(0, 48, size=(small.sum(), 2))
    return _block(AABB8_INPUTS, cases.T)


AABB8_OVERLAPPING = {"x": (10, 5, 8, 5), "y_a_first": (10, 5, 12, 5), "y_b_first": (12, 5, 10, 5)}
# (position, size, other position, other size) the axis not swept is held at: the boxes overlap there,
# so the answer is the swept axis's. y is swept twice: the routine's y test has one copy for each way
# its x test goes (box A starting first on x, or box B), each entered with its own carry.
AABB8_AXIS_CALLS = BYTE ** 4  # every (position, size, other position, other size) of one axis


def aabb8_sweep(starts: Iterable[int] = range(BYTE)) -> list[Grid]:
    """Every input of each axis: all 2^32 (ax, aw, bx, bw) with y overlapping, then all 2^32 (ay, ah,
    by, bh) after each way the x test goes: 3 x 2^32 calls (every size against every other size for one
    pair of positions per 65,536; grids: a worker makes only its range). `starts`: the positions of box A
    swept (a bounded form for tests: a few of them)."""
    ay, ah, by, bh = AABB8_OVERLAPPING["x"]
    grids = [Grid({"ax": list(starts), "bx": BYTE, "aw": BYTE, "bw": BYTE},
                  lambda ax, bx, aw, bw: dict(ax=ax, ay=ay, aw=aw, ah=ah, bx=bx, by=by, bw=bw, bh=bh))]
    for held in ("y_a_first", "y_b_first"):
        ax, aw, bx, bw = AABB8_OVERLAPPING[held]
        grids.append(Grid({"ay": list(starts), "by": BYTE, "ah": BYTE, "bh": BYTE},
                          lambda ay, by, ah, bh, ax=ax, aw=aw, bx=bx, bw=bw: dict(ax=ax, ay=ay, aw=aw, ah=ah, bx=bx,
                                                                                 by=by, bw=bw, bh=bh)))
    return grids


# ---- aabb_sprite -------------------------------------------------------------------------------

def _sprite_case(x1: int, y1: int, box1: tuple, x2: int, y2: int, box2: tuple) -> tuple:
    return (x1 & 0xFF, x1 >> 8, y1, *box1, x2 & 0xFF, x2 >> 8, y2, *box2)


def aabb_sprite_boundary() -> list[tuple]:
    out = []
    boxes = ((0, 0, 24, 21), (4, 3, 16, 15), (23, 20, 1, 1), (0, 0, 48, 42), (10, 0, 1, 21))
    for box1, box2 in product(boxes, repeat=2):
        for x1 in (0, 24, 240, 250, 255, 256, 257, 300, 343, 488, 511):
            right1 = x1 + box1[0] + box1[2]
            for x2 in {right1 - box2[0] - 1, right1 - box2[0], right1 - box2[0] + 1,
                       x1 + box1[0] - box2[0] - box2[2], x1 + box1[0] - box2[0] - box2[2] + 1, x1}:
                if 0 <= x2 < X_POSITIONS:
                    out.append(_sprite_case(x1, 100, box1, x2, 100, box2))
        for y1 in (0, 50, 200, 240, 255):
            bottom1 = y1 + box1[1] + box1[3]
            for y2 in {bottom1 - box2[1] - 1, bottom1 - box2[1], y1 + box1[1] - box2[1] - box2[3], y1}:
                if 0 <= y2 < BYTE:
                    out.append(_sprite_case(300, y1, box1, 300, y2, box2))
    return out


AABB_SPRITE_INPUTS = ("x1", "x1h", "y1", "ox1", "oy1", "w1", "h1", "x2", "x2h", "y2", "ox2", "oy2", "w2", "h2")


def aabb_sprite_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    x1 = rng.integers(0, X_POSITIONS, size=n)
    x2 = np.where(rng.random(n) < 0.6, (x1 + rng.integers(-48, 48, size=n)) % X_POSITIONS, rng.integers(0, X_POSITIONS, size=n))
    y1 = rng.integers(0, BYTE, size=n)
    y2 = np.where(rng.random(n) < 0.6, (y1 + rng.integers(-42, 42, size=n)) % BYTE, rng.integers(0, BYTE, size=n))
    small = rng.random(n) < 0.7
    boxes = np.where(small[:, None], rng.integers(0, 48, size=(n, 8)), rng.integers(0, BYTE, size=(n, 8))).T
    return _block(AABB_SPRITE_INPUTS, (x1 & 0xFF, x1 >> 8, y1, *boxes[:4], x2 & 0xFF, x2 >> 8, y2, *boxes[4:]))


def _nine_bit(low: str, high: str) -> dict[str, np.ndarray]:
    """A grid axis of every 9-bit X position as its two inputs (low byte, high bit)."""
    x = np.arange(X_POSITIONS)
    return {low: x & 0xFF, high: x >> 8}


def _held(**inputs: int) -> dict[str, list[int]]:
    """A grid axis of one value: inputs held constant (by name)."""
    return {name: [value] for name, value in inputs.items()}


def aabb_sprite_sweep() -> Grid:
    """Every pair of 9-bit X positions with two fixed hitboxes (the 255/256 boundary included)."""
    return Grid({"x1": _nine_bit("x1", "x1h"), "x2": _nine_bit("x2", "x2h"),
                 "held": _held(y1=100, ox1=4, oy1=3, w1=16, h1=15, y2=104, ox2=0, oy2=0, w2=SPRITE_WIDTH,
                               h2=SPRITE_HEIGHT)})


# ---- circle ------------------------------------------------------------------------------------

def _circle_case(dx: int, dy: int, radius_sum: int, cx: int = 0, cy: int = 0) -> tuple:
    x1, x2 = (dx, 0) if dx >= 0 else (0, -dx)
    y1, y2 = (dy, 0) if dy >= 0 else (0, -dy)
    r1 = radius_sum // 2
    r2 = radius_sum - r1
    return (x1, y1, min(r1, 255), x2, y2, min(r2, 255))


def circle_boundary() -> list[tuple]:
    out = []
    for dx, dy in ((0, 0), (3, 4), (-3, 4), (3, -4), (-3, -4), (255, 0), (0, 255), (-255, 0), (0, -255),
                   (255, 255), (-255, -255), (180, 180), (-181, 180), (1, 0), (0, -1), (127, 128)):
        distance = math.isqrt(dx * dx + dy * dy)
        for radius_sum in {0, 1, distance, distance + 1, 254, 255, 256, 300, 510}:
            out.append(_circle_case(dx, dy, radius_sum))
    return out


CIRCLE_INPUTS = ("x1", "y1", "r1", "x2", "y2", "r2")


def circle_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    cases = _bytes(rng, n, 6)
    tight = np.flatnonzero(rng.random(n) < 0.5)  # half: radius sum at the distance, where the answer flips
    x1, y1, _, x2, y2, _ = cases[tight].T
    # (one draw of 0 or 1 per tight case, in case order: numpy's integers gives the same values drawn one
    # at a time or all at once)
    radius_sum = _isqrt((x1 - x2) ** 2 + (y1 - y2) ** 2) + rng.integers(0, 2, size=len(tight))
    fits = radius_sum <= 255
    cases[tight[fits], 2] = radius_sum[fits] // 2
    cases[tight[fits], 5] = radius_sum[fits] - radius_sum[fits] // 2
    return _block(CIRCLE_INPUTS, cases.T)


def _isqrt(values: np.ndarray) -> np.ndarray:
    """math.isqrt of each (whole numbers below 2^52): the float root's floor, corrected by one either way."""
    root = np.floor(np.sqrt(values.astype(np.float64))).astype(np.int64)
    root -= root * root > values
    root += (root + 1) * (root + 1) <= values
    return root


def _apart(delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two bytes whose difference (first - second) is delta (-255..255): one of them 0."""
    return np.maximum(delta, 0), np.maximum(-delta, 0)


SIGNED_BYTE_DELTAS = range(-(BYTE - 1), BYTE)  # a difference of two bytes
CIRCLE_RADIUS_DELTAS = np.array([(0, 0), (200, 100), (-255, -255), (3, 4)])  # (dx, dy) of circle's (r1, r2) sweep


def _deltas(first: str, second: str, deltas=SIGNED_BYTE_DELTAS) -> dict[str, np.ndarray]:
    """A grid axis of differences (first - second) as the two bytes (`_apart`)."""
    return dict(zip((first, second), _apart(np.asarray(deltas))))


def circle_sweep() -> list[Grid]:
    """Every (dx, dy) of both signs (-255..255 each) at every radius sum 0..255, split r1 = sum // 2;
    then every (r1, r2) pair (each 0..255) at a few deltas (the radius domain and its edge). (Axes of
    inputs that go together: no make, the columns kept from block to block.)"""
    radius_sum = np.arange(BYTE)
    by_radii = {**_deltas("x1", "x2", CIRCLE_RADIUS_DELTAS[:, 0]), **_deltas("y1", "y2", CIRCLE_RADIUS_DELTAS[:, 1])}
    return [Grid({"dx": _deltas("x1", "x2"), "dy": _deltas("y1", "y2"),
                  "radius_sum": {"r1": radius_sum // 2, "r2": radius_sum - radius_sum // 2}}),
            Grid({"delta": by_radii, "r1": BYTE, "r2": BYTE})]


# ---- mul8 ----------------------------------------------------------------------------------------

def mul8_boundary() -> list[tuple]:
    values = (0, 1, 2, 127, 128, 129, 254, 255)
    return list(product(values, repeat=2))


def mul8_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    return _block(("a", "b"), _bytes(rng, n, 2).T)


def mul8_sweep() -> Grid:
    return Grid({"a": BYTE, "b": BYTE})


# ---- tile and tile_box ---------------------------------------------------------------------------

_EDGE_X = (0, 23, 24, 25, 31, 32, 255, 256, 343, 344, 345, 511)
_EDGE_Y = (0, 49, 50, 51, 57, 58, 249, 250, 251, 255)

def tile_boundary() -> list[tuple]:
    return [(x & 0xFF, x >> 8, y) for x in _EDGE_X for y in _EDGE_Y]


def tile_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    x = rng.integers(0, X_POSITIONS, size=n)
    y = rng.integers(0, BYTE, size=n)
    return _block(("x", "xh", "y"), (x & 0xFF, x >> 8, y))


def tile_sweep() -> Grid:
    """Every 9-bit X by every Y."""
    return Grid({"x": _nine_bit("x", "xh"), "y": BYTE})


def tile_box_boundary() -> list[tuple]:
    out = []
    for x in _EDGE_X:
        for y in _EDGE_Y:
            for w, h in ((0, 5), (5, 0), (1, 1), (8, 8), (9, 9), (SPRITE_WIDTH, SPRITE_HEIGHT), (255, 255)):
                out.append((x & 0xFF, x >> 8, y, w, h))
    return out


def tile_box_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    x = rng.integers(0, X_POSITIONS, size=n)
    y = rng.integers(0, BYTE, size=n)
    small = rng.random(n) < 0.8
    w = np.where(small, rng.integers(0, 33, size=n), rng.integers(0, BYTE, size=n))
    h = np.where(small, rng.integers(0, 33, size=n), rng.integers(0, BYTE, size=n))
    return _block(("x", "xh", "y", "w", "h"), (x & 0xFF, x >> 8, y, w, h))


def tile_box_sweep() -> list[Grid]:
    """Every 9-bit X and every Y for a sprite-sized box; every width at a few heights and back."""
    return [Grid({"x": _nine_bit("x", "xh"), "y": BYTE, "box": _held(w=SPRITE_WIDTH, h=SPRITE_HEIGHT)}),
            Grid({"other": (0, 1, 8, 21, 255), "height_varies": 2, "size": BYTE},
                 lambda other, height_varies, size: dict(x=20, xh=0, y=45, w=np.where(height_varies, other, size),
                                                         h=np.where(height_varies, size, other)))]


# ---- pixel ---------------------------------------------------------------------------------------

FIXED_MASK_PAIRS = 5  # full, one dot, corners, ring/dot, ring/ring; the rest are random


@lru_cache(maxsize=8)
def pixel_masks(seed: int = 0) -> tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]:
    """Mask pairs the pixel cases use: five shapes, then twelve random pairs of three densities
    drawn from seed + 1."""
    rng = np.random.default_rng(seed + 1)
    full = bytes([0xFF] * MASK_BYTES)
    dot = bytearray(MASK_BYTES)
    dot[10 * SPRITE_ROW_BYTES + 1] = 0x10  # one pixel near the middle
    corner = bytearray(MASK_BYTES)
    corner[0] = 0x80
    corner[-1] = 0x01
    ring = bytearray(MASK_BYTES)
    for row in range(SPRITE_HEIGHT):
        for col in range(SPRITE_WIDTH):
            if 7 <= math.hypot(col - 11.5, row - 10) < 10:
                ring[row * SPRITE_ROW_BYTES + col // 8] |= 0x80 >> (col % 8)
    masks = [(full, full), (bytes(dot), full), (bytes(corner), bytes(corner)), (bytes(ring), bytes(dot)),
             (bytes(ring), bytes(ring))]
    for density in (0.02, 0.1, 0.5):
        for _ in range(4):
            a = np.packbits(rng.random((SPRITE_HEIGHT, SPRITE_WIDTH)) < density, axis=1).tobytes()
            b = np.packbits(rng.random((SPRITE_HEIGHT, SPRITE_WIDTH)) < density, axis=1).tobytes()
            masks.append((a, b))
    return tuple((tuple(a), tuple(b)) for a, b in masks)


def _signed(value: int) -> int:
    return value - BYTE if value & 0x80 else value


OFFSET_SPAN = 24  # |dx| and |dy| below this can overlap two 24 x 21 masks; beyond, no pixel is shared


@lru_cache(maxsize=64)
def _overlap_table(mask_a: bytes, mask_b: bytes) -> np.ndarray:
    """reference.pixel at every offset where masks can meet, indexed [dy + SPAN, dx + SPAN]."""
    a, b = reference.mask_bits(mask_a), reference.mask_bits(mask_b)
    span = range(-OFFSET_SPAN, OFFSET_SPAN + 1)
    return np.array([[reference.pixel(dx, dy, a, b) for dx in span] for dy in span], dtype=bool)


PAIR_WORDS = -(-2 * MASK_BYTES // 8)  # a mask pair's 126 bytes as 64-bit words (the last one padded with 0)
ROW_HASH = np.random.default_rng(0x6502).integers(1, 2 ** 63, size=PAIR_WORDS, dtype=np.uint64) | np.uint64(1)


def _distinct_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(distinct rows, each row's index among them) of (n, PAIR_WORDS) uint64 rows: by a 64-bit hash of
    each row, checked row by row (a collision falls back to sorting the rows themselves)."""
    keys = rows @ ROW_HASH  # wraps modulo 2^64
    _, first, which = np.unique(keys, return_index=True, return_inverse=True)
    distinct = rows[first]
    if (distinct[which.ravel()] == rows).all():
        return distinct, which.ravel()
    distinct, which = np.unique(rows, axis=0, return_inverse=True)
    return distinct, which.ravel()


def _mask_pairs(mask_a: np.ndarray, mask_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(distinct mask pairs as rows of 126 bytes, each case's index among them): a block whose two
    columns are each one row repeated (grid.one_row: pixel's sweep) is one pair without a look at its
    cases; any other is hashed row by row as 64-bit words (`_distinct_rows`)."""
    row_a, row_b = one_row(mask_a), one_row(mask_b)
    if row_a is not None and row_b is not None:
        return np.concatenate([row_a, row_b])[None].astype(np.uint8), np.zeros(len(mask_a), dtype=np.intp)
    masks = np.zeros((len(mask_a), 8 * PAIR_WORDS), dtype=np.uint8)
    masks[:, :MASK_BYTES] = mask_a  # (wrapped to bytes, as astype(np.uint8) would)
    masks[:, MASK_BYTES:2 * MASK_BYTES] = mask_b
    distinct, which = _distinct_rows(masks.view(np.uint64))
    return np.ascontiguousarray(distinct).view(np.uint8)[:, :2 * MASK_BYTES], which


def pixel_reference(dx, dy, mask_a, mask_b):
    """reference.pixel on the routine's inputs: offsets as two's-complement bytes, masks as 63 bytes.

    Over arrays (one case per element, masks as rows of 63 bytes): each distinct mask pair's answers at
    every offset come from reference.pixel once, then every case is a lookup."""
    scalar = np.ndim(dx) == 0
    dx, dy = np.atleast_1d(dx).astype(np.int64), np.atleast_1d(dy).astype(np.int64)
    pairs, which = _mask_pairs(np.atleast_2d(mask_a), np.atleast_2d(mask_b))
    signed_dx, signed_dy = dx - ((dx & 0x80) << 1), dy - ((dy & 0x80) << 1)
    near = (np.abs(signed_dx) <= OFFSET_SPAN) & (np.abs(signed_dy) <= OFFSET_SPAN)
    hit = np.zeros(len(dx), dtype=bool)
    for k, pair in enumerate(pairs):
        cases = np.flatnonzero((which.ravel() == k) & near)
        table = _overlap_table(pair[:MASK_BYTES].tobytes(), pair[MASK_BYTES:].tobytes())
        hit[cases] = table[signed_dy[cases] + OFFSET_SPAN, signed_dx[cases] + OFFSET_SPAN]
    return bool(hit[0]) if scalar else hit


def pixel_boundary(seed: int = 0) -> list[tuple]:
    masks = pixel_masks(seed)
    offsets = (-128, -25, -24, -23, -22, -8, -1, 0, 1, 7, 8, 9, 16, 22, 23, 24, 127)
    return [(dx & 0xFF, dy & 0xFF, *masks[pair]) for pair in range(FIXED_MASK_PAIRS) for dx in offsets
            for dy in offsets if abs(dy) <= 25 or dx == 0]


@lru_cache(maxsize=8)
def _mask_tables(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """pixel_masks(seed) as two (pairs, 63) byte tables: the first masks, the second masks."""
    table = np.asarray(pixel_masks(seed), dtype=np.uint8)  # (pairs, 2, 63)
    return np.ascontiguousarray(table[:, 0]), np.ascontiguousarray(table[:, 1])


def _mask_columns(seed: int, pair: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each case's two masks (`pair`: its index among pixel_masks(seed)) as (n, 63) int64 columns. A block
    of one pair gets that pair's rows repeated (grid.repeated_row: no copy, and its readers see one pair);
    any other, the rows picked as bytes, then widened (several times faster than picking int64 rows)."""
    tables = _mask_tables(seed)
    if len(pair) and pair.min() == pair.max():
        return tuple(repeated_row(table[int(pair[0])], len(pair)) for table in tables)
    return tuple(np.take(table, pair, axis=0).astype(np.int64) for table in tables)


def pixel_random(rng: np.random.Generator, n: int, seed: int = 0) -> dict:
    masks = pixel_masks(seed)
    dx = rng.integers(-26, 27, size=n)
    dy = rng.integers(-23, 24, size=n)
    pair = rng.integers(0, len(masks), size=n)
    mask_a, mask_b = _mask_columns(seed, pair)
    return {"dx": dx & 0xFF, "dy": dy & 0xFF, "mask_a": mask_a, "mask_b": mask_b}


def pixel_sweep(seed: int = 0) -> Grid:
    """Every pair of offset bytes for every mask pair of the corpus (a block of cases holds one pair: its
    mask columns are that pair's rows repeated, `_mask_columns`)."""
    masks = pixel_masks(seed)

    def with_masks(pair, dx, dy):
        mask_a, mask_b = _mask_columns(seed, pair)
        return {"dx": dx, "dy": dy, "mask_a": mask_a, "mask_b": mask_b}
    return Grid({"pair": len(masks), "dx": BYTE, "dy": BYTE}, with_masks)


# ---- circle_r ------------------------------------------------------------------------------------

def circle_r_sweep() -> Grid:
    """Every (dx, dy) of both signs (-255..255 each) at every radius sum 0..255."""
    return Grid({"dx": _deltas("x1", "x2"), "dy": _deltas("y1", "y2"), "radius_sum": BYTE})


def circle_r_boundary() -> list[tuple]:
    """Coincident centres (R = 0 is outside the domain: two points never overlap), byte ends, tangency."""
    out = []
    for dx, dy in ((0, 0), (3, 4), (-3, -4), (255, 0), (-255, 0), (0, 255), (0, -255), (180, -180), (1, 1)):
        distance = math.isqrt(dx * dx + dy * dy)
        for radius in {0, 1, distance, distance + 1, 254, 255}:
            if 0 <= radius <= 255:
                x1, x2 = (dx, 0) if dx >= 0 else (0, -dx)
                y1, y2 = (dy, 0) if dy >= 0 else (0, -dy)
                out.append((x1, y1, radius, x2, y2))
    return out


# ---- aabb_edges and sprite_edges: edges as their prepare routines make them -----------------------

def _boxes(rng: np.random.Generator, n: int, limit: int) -> tuple[np.ndarray, np.ndarray]:
    """Starts and sizes (size >= 1, start + size <= limit); half the sizes small, as sprites are."""
    size = np.where(rng.random(n) < 0.5, rng.integers(1, 48, size=n), rng.integers(1, limit, size=n))
    start = (rng.random(n) * (limit - size + 1)).astype(np.int64)
    return start, size


def _near(rng: np.random.Generator, start: np.ndarray, size: np.ndarray, limit: int) -> np.ndarray:
    """B's start near A's (half the cases), so hits, misses and touching are all common."""
    near = np.clip(start + rng.integers(-48, 48, size=len(start)), 0, limit - 1)
    return np.where(rng.random(len(start)) < 0.5, near, rng.integers(0, limit, size=len(start)))


def aabb_edges_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    ax, aw = _boxes(rng, n, 256)
    ay, ah = _boxes(rng, n, 256)
    bw = np.where(rng.random(n) < 0.5, rng.integers(1, 48, size=n), rng.integers(1, 256, size=n))
    bh = np.where(rng.random(n) < 0.5, rng.integers(1, 48, size=n), rng.integers(1, 256, size=n))
    bx = np.minimum(_near(rng, ax, aw, 256), 255 - bw)
    by = np.minimum(_near(rng, ay, ah, 256), 255 - bh)
    columns = (ax, ay, ax + aw - 1, ay + ah - 1, bx, bx + bw, by, by + bh)
    return _block(("a_left", "a_top", "a_right1", "a_bottom1", "b_left", "b_right", "b_top", "b_bottom"), columns)


def sprite_edges_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    a_left, a_width = _boxes(rng, n, X_POSITIONS + 48)
    b_left = _near(rng, a_left, a_width, X_POSITIONS + 48)
    b_width = np.where(rng.random(n) < 0.5, rng.integers(1, 48, size=n), rng.integers(1, 256, size=n))
    a_top, a_height = _boxes(rng, n, 256)
    b_height = np.where(rng.random(n) < 0.5, rng.integers(1, 48, size=n), rng.integers(1, 256, size=n))
    b_top = np.minimum(_near(rng, a_top, a_height, 256), 255 - b_height)
    a_right, b_right = a_left + a_width, b_left + b_width
    columns = (a_left & 0xFF, a_top, a_top + a_height - 1, a_left >> 8, a_right & 0xFF, a_right >> 8,
               b_left & 0xFF, b_left >> 8, b_right & 0xFF, b_right >> 8, b_top, b_top + b_height)
    return _block(("a_left", "a_top", "a_bottom1", "a_left_hi", "a_right", "a_right_hi", "b_left", "b_left_hi", "b_right",
                   "b_right_hi", "b_top", "b_bottom"), columns)


# ---- mul16 ---------------------------------------------------------------------------------------

WORD = 1 << 16
_WORD_EDGES = (0, 1, 2, 0x7F, 0x80, 0xFF, 0x100, 0x5555, 0x7FFF, 0x8000, 0xAAAA, 0xFFFE, 0xFFFF)
# the byte and sign edges, alternating bits, and b = 0 / $FFFF (no add, 16 adds: the cycle extremes;
# with a = $FFFF every add carries out of the high byte)


def mul16_boundary() -> list[tuple]:
    return list(product(_WORD_EDGES, repeat=2))


def mul16_random(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    return _block(("a", "b"), rng.integers(0, WORD, size=(n, 2)).T)


def mul16_sweep() -> Grid:
    """Every (a, b): 2^32 calls, b varying fastest (a grid: a worker makes only its range)."""
    return Grid({"a": WORD, "b": WORD})
