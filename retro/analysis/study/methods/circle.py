"""Circle methods: the smallest integer circle around the opaque pixels (fits.fitted_circle).

The rule: squared centre distance against (r1 + r2)^2, strictly (`touching=False`: tangent circles
do not collide, the convention of asm/circle.s and asm/circle_r.s). The radius is fitted for that
comparison, so a fitted circle never misses a real collision.

- `CIRCLE`: asm/circle.s, both radii passed per call;
- `CIRCLE_R`: asm/circle_r.s, the radius sum prepared once per pair of object kinds
  (asm/circle_r_prepare); its cycles are the pair test's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import Circle, fitted_circle
from retro.analysis.study.methods.base import KIND_PAIR, ORIGIN, Method


@dataclass(frozen=True, kw_only=True)
class CircleMethod(Method):
    touching: bool = False  # True: d^2 <= (r1 + r2)^2, tangent circles collide

    def circles(self, pair: Pair) -> tuple[Circle, Circle]:
        return fitted_circle(pair.a.mask, self.touching), fitted_circle(pair.b.mask, self.touching)

    def verdict(self, pair: Pair) -> np.ndarray:
        ca, cb = self.circles(pair)
        ddx = cb.cx + pair.dx - ca.cx
        ddy = cb.cy + pair.dy - ca.cy
        d2 = ddx * ddx + ddy * ddy
        reach = (ca.r + cb.r) ** 2
        return (d2 <= reach if self.touching else d2 < reach).astype(float)

    def x_extent(self, shape) -> tuple[int, int]:
        """|dx| < r1 + r2 is needed for a hit (|dx| <= r1 + r2 when touching), and [cx - r, cx + r)
        intervals meet exactly when |dx| < r1 + r2."""
        c = fitted_circle(shape.mask, self.touching)
        return c.cx - c.r, c.cx + c.r + (1 if self.touching else 0)

    def case_maker(self, pair: Pair):
        ca, cb = self.circles(pair)
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()
        return lambda i: dict(x1=ORIGIN + ca.cx, y1=ORIGIN + ca.cy, r1=ca.r,  # asm/circle.toml
                              x2=ORIGIN + dxs[i] + cb.cx, y2=ORIGIN + dys[i] + cb.cy, r2=cb.r)

    def host_calls(self, pair: Pair, indices: list[int]):
        from retro.geometry.circle import circle_overlap

        ca, cb = self.circles(pair)
        return [lambda dx=int(pair.dx[i]), dy=int(pair.dy[i]):
                circle_overlap((ca.cx, ca.cy), ca.r, (cb.cx + dx, cb.cy + dy), cb.r) for i in indices]


@dataclass(frozen=True, kw_only=True)
class RadiusSumCircleMethod(CircleMethod):
    def case_maker(self, pair: Pair):
        ca, cb = self.circles(pair)
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()
        return lambda i: dict(x1=ORIGIN + ca.cx, y1=ORIGIN + ca.cy, radius_sum=ca.r + cb.r,  # asm/circle_r.toml
                              x2=ORIGIN + dxs[i] + cb.cx, y2=ORIGIN + dys[i] + cb.cy)


CIRCLE = CircleMethod(
    key="circle", label="fitted circle", colour="#ff7f0e", marker="o", routine="circle",
    rule="integer circles enclosing the opaque pixels: squared centre distance against (r1+r2)^2, strictly "
         "(tangent circles do not collide)",
    counted="asm/circle.s on the fitted circles (its tables counted)", origin=__name__)

CIRCLE_R = RadiusSumCircleMethod(
    key="circle_r", label="fitted circle, radius sum prepared", colour="#ffbb78", marker="h", routine="circle_r",
    prepare="circle_r_prepare", prepare_per=KIND_PAIR,
    rule="the fitted circles' rule, tested with r1 + r2 prepared once per pair of object kinds",
    counted="asm/circle_r.s per pair, R = r1 + r2 made beforehand by circle_r_prepare (not counted here); "
            "its tables counted", origin=__name__)
