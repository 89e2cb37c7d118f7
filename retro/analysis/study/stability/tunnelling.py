"""Tunnelling: how often a static test misses a fast object crossing a thin obstacle.

Set-up: a mover shape travels horizontally at v pixels per frame, vertically centred on a wall
obstacle T pixels thick and a full sprite tall. Its positions over the frames are
x_k = x_0 + k*v; every start phase x_0 mod v (0 .. v-1) is taken once, so a miss rate is exact,
not sampled. The mover crosses the wall completely, so the correct answer is always "collided":
a static method misses when none of the frame positions is one where it reports a hit.

Every method whose verdict is a 0/1 answer takes part (an averaged method, the tile cells, has no
single answer per position). Methods that give the same answer at every position of every crossing
(the tight box through aabb8, aabb_edges or sprite_edges; pixel-perfect and the latch) are one line,
named by all of them. The swept test beside them is retro.geometry.swept_aabb on the tight hitboxes,
frame by frame (the box moving by v over each frame).

Reference: a mover of length L through a wall of thickness T overlaps it at T + L - 1 integer
positions, so a pixel-exact static test misses a share max(0, 1 - (T + L - 1) / v) of the phases.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Shape, make_pair
from retro.analysis.study.fits import tight_box
from retro.analysis.study.methods import METHODS, Method, sub_pair

SWEPT = "swept"
GROUP = "/"  # joins the keys of methods that answer alike on every crossing
SPEEDS = tuple(range(1, 41))
THICKNESSES = (1, 2, 4, 8)
WALL_HEIGHT = 21


def wall(thickness: int, height: int = WALL_HEIGHT, width: int = 24) -> Shape:
    """A sprite-sized shape whose opaque part is a vertical wall `thickness` pixels wide, centred."""
    mask = np.zeros((height, width), dtype=bool)
    left = (width - thickness) // 2
    mask[:, left:left + thickness] = True
    return Shape(name=f"wall{thickness}", mask=mask)


def _row_offset(mover: Shape, obstacle: Shape) -> int:
    """dy that centres the mover's opaque rows on the obstacle's opaque rows."""
    _, my0, _, my1 = tight_box(mover.mask)
    _, oy0, _, oy1 = tight_box(obstacle.mask)
    return (oy0 + oy1) // 2 - (my0 + my1) // 2


def static_hits_by_dx(method: Method, mover: Shape, obstacle: Shape) -> tuple[np.ndarray, np.ndarray]:
    """(dx values, verdict) of a static method along the mover's line through the obstacle; the
    obstacle is shape a at the origin, the mover shape b at (dx, dy). Only the line's cases are
    evaluated."""
    pair = make_pair(obstacle, mover)
    line = sub_pair(pair, np.flatnonzero(pair.dy == _row_offset(mover, obstacle)))
    return line.dx, method.verdict(line) > 0


def miss_rate_from_hits(dxs: np.ndarray, hits: np.ndarray, speed: int) -> float:
    """Share of start phases in which no frame position is a hit position. Positions outside dxs
    are never hits (the full sprite boxes do not even meet there)."""
    hit_positions = dxs[hits]
    if hit_positions.size == 0:
        return 1.0
    phases = (hit_positions - hit_positions.min()) % speed
    return 1.0 - np.unique(phases).size / speed


def swept_miss_rate(mover: Shape, obstacle: Shape, speed: int) -> float:
    """The same crossings tested with retro.geometry.swept_aabb on the tight hitboxes."""
    from retro.geometry.swept import swept_aabb

    ox0, oy0, ox1, oy1 = tight_box(obstacle.mask)
    mx0, my0, mx1, my1 = tight_box(mover.mask)
    dy = _row_offset(mover, obstacle)
    start = -mover.width - speed  # fully left of the obstacle's sprite box
    misses = 0
    for phase in range(speed):
        x = start + phase
        hit = False
        while x <= obstacle.width:
            if swept_aabb((x + mx0, dy + my0), (x + mx1, dy + my1), (speed, 0), (ox0, oy0), (ox1, oy1)) is not None:
                hit = True
                break
            x += speed
        misses += not hit
    return misses / speed


@dataclass(frozen=True)
class TunnelRow:
    method: str
    thickness: int
    speed: int
    miss_rate: float


def tunnelling_methods(methods: tuple[Method, ...]) -> tuple[Method, ...]:
    return tuple(m for m in methods if not m.averaged)


def tunnelling_table(mover: Shape, speeds: tuple[int, ...] = SPEEDS, thicknesses: tuple[int, ...] = THICKNESSES,
                     methods: tuple[Method, ...] = METHODS) -> list[TunnelRow]:
    """Rows per (method group, thickness, speed); a group's key is its methods' keys joined by GROUP."""
    walls = [wall(t) for t in thicknesses]
    hits: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    for m in tunnelling_methods(methods):
        hits[m.key] = [static_hits_by_dx(m, mover, obstacle) for obstacle in walls]
    groups: dict[tuple, list[str]] = {}
    for key, lines in hits.items():
        signature = tuple((dxs[h].tobytes(), dxs.tobytes()) for dxs, h in lines)
        groups.setdefault(signature, []).append(key)
    rows = []
    for i, (t, obstacle) in enumerate(zip(thicknesses, walls)):
        for keys in groups.values():
            dxs, h = hits[keys[0]][i]
            rows += [TunnelRow(GROUP.join(keys), t, v, miss_rate_from_hits(dxs, h, v)) for v in speeds]
        rows += [TunnelRow(SWEPT, t, v, swept_miss_rate(mover, obstacle, v)) for v in speeds]
    return rows


def safe_speed(rows: list[TunnelRow], method_key: str, thickness: int) -> int:
    """The highest speed up to which the method never misses (0 if it misses already at 1 px/frame)."""
    safe = 0
    for r in sorted((r for r in rows if r.method == method_key and r.thickness == thickness), key=lambda r: r.speed):
        if r.miss_rate > 0:
            break
        safe = r.speed
    return safe
