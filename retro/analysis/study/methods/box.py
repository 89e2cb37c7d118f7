"""Box methods: axis-aligned boxes around a sprite, half-open (boxes that only touch do not collide).

- `BOX`: the whole 24x21 sprite box (what a game gets with no hitbox data), asm/aabb8.s;
- `TIGHT`: the bounding box of the opaque pixels (the usual hand-tuned hitbox at its tightest),
  asm/aabb8.s, every value passed per call;
- `TIGHT_EDGES`: the same hitbox in the convention games use: each object's edges prepared once
  per frame (asm/aabb_edges_prepare), then asm/aabb_edges per pair. Its cycles are the pair test's;
  the preparation is per object, not per test.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import Box, full_box, tight_box
from retro.analysis.study.methods.base import ORIGIN, Method


def box_overlap(a: Box, b: Box, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Half-open boxes a (at the origin) and b (moved by dx, dy) share a pixel."""
    ax0, ay0, ax1, ay1 = a
    bx0, by0, bx1, by1 = b
    return (ax0 < bx1 + dx) & (bx0 + dx < ax1) & (ay0 < by1 + dy) & (by0 + dy < ay1)


@dataclass(frozen=True, kw_only=True)
class BoxMethod(Method):
    fit: Callable[[np.ndarray], Box]  # the shape's mask -> its box (x0, y0, x1, y1), x1/y1 exclusive

    def boxes(self, pair: Pair) -> tuple[Box, Box]:
        return self.fit(pair.a.mask), self.fit(pair.b.mask)

    def verdict(self, pair: Pair) -> np.ndarray:
        a, b = self.boxes(pair)
        return box_overlap(a, b, pair.dx, pair.dy).astype(float)

    def x_extent(self, shape) -> tuple[int, int]:
        x0, _, x1, _ = self.fit(shape.mask)
        return x0, x1

    def case_maker(self, pair: Pair):
        (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = self.boxes(pair)
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()
        return lambda i: dict(ax=ORIGIN + ax0, ay=ORIGIN + ay0, aw=ax1 - ax0, ah=ay1 - ay0,  # asm/aabb8.toml
                              bx=ORIGIN + dxs[i] + bx0, by=ORIGIN + dys[i] + by0, bw=bx1 - bx0, bh=by1 - by0)

    def host_calls(self, pair: Pair, indices: list[int]):
        from retro.geometry.aabb import aabb_overlap

        (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = self.boxes(pair)
        return [lambda dx=int(pair.dx[i]), dy=int(pair.dy[i]):
                aabb_overlap((ax0, ay0), (ax1, ay1), (bx0 + dx, by0 + dy), (bx1 + dx, by1 + dy)) for i in indices]


@dataclass(frozen=True, kw_only=True)
class EdgesBoxMethod(BoxMethod):
    """The box test from edges prepared once per object (asm/aabb_edges)."""

    def case_maker(self, pair: Pair):
        (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = self.boxes(pair)
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()
        left, top = ORIGIN + ax0, ORIGIN + ay0
        return lambda i: dict(a_left=left, a_top=top, a_right1=ORIGIN + ax1 - 1, a_bottom1=ORIGIN + ay1 - 1,
                              b_left=ORIGIN + dxs[i] + bx0, b_right=ORIGIN + dxs[i] + bx1,  # asm/aabb_edges.toml
                              b_top=ORIGIN + dys[i] + by0, b_bottom=ORIGIN + dys[i] + by1)


BOX = BoxMethod(
    key="box", label="sprite box AABB", fit=full_box, colour="#1f77b4", marker="s", routine="aabb8",
    rule="the full 24x21 sprite boxes overlap (half-open: touching boxes do not)",
    counted="asm/aabb8.s on the full 24x21 boxes", origin=__name__)

TIGHT = BoxMethod(
    key="tight", label="tight hitbox AABB", fit=tight_box, colour="#2ca02c", marker="D", routine="aabb8",
    rule="the bounding boxes of the opaque pixels overlap (half-open)",
    counted="asm/aabb8.s on the tight hitboxes", origin=__name__)

TIGHT_EDGES = EdgesBoxMethod(
    key="tight_edges", label="tight hitbox, prepared edges", fit=tight_box, colour="#98df8a", marker="d",
    routine="aabb_edges", prepare="aabb_edges_prepare",
    rule="the bounding boxes of the opaque pixels overlap (half-open), tested from edges prepared once per object",
    counted="asm/aabb_edges.s per pair, on edges made once per object and frame by aabb_edges_prepare "
            "(not counted here)", origin=__name__)
