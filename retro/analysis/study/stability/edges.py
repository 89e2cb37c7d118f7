"""Edge conventions: what each method says when shapes touch, overlap by one pixel, or have a gap.

Boxes: two full sprites (every pixel of the 24x21 box opaque), b moved right by dx: "touching" is
b's first column right after a's last (dx = 24): no pixel is shared, so the VIC-II reports nothing,
and a correct test must say "no"; "sharing one column" is dx = 23, "one pixel apart" dx = 25.
Circles: two identical discs whose fitted circle (fits.fitted_circle) has radius r, b moved so the
circles are tangent (d = 2r), just inside (the largest integer d^2 below (2r)^2) or one pixel apart.

Each case is given to the geometry references (retro.geometry, the pixel masks, the VIC-II model),
to every method's rule (its verdict on that case) and to every method's 6502 routine through the
method's own inputs (a method averaged over grid alignments has no single routine answer).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Shape, pair_at
from retro.analysis.study.fits import fitted_circle
from retro.analysis.study.methods import METHODS, Method

SPRITE_W, SPRITE_H = 24, 21
BOX_CASES = {"boxes touching (adjacent columns)": SPRITE_W, "boxes sharing one column": SPRITE_W - 1,
             "boxes one pixel apart": SPRITE_W + 1}
DISC_RADIUS2 = 49  # the disc's pixels: squared distance from (12, 10) at most this; its fitted circle has r = 8
TANGENT, INSIDE, APART = "circles tangent (d = r1 + r2)", "circles just inside (largest integer d^2 < (r1 + r2)^2)", \
    "circles one pixel apart"


@dataclass(frozen=True)
class EdgeRow:
    case: str
    test: str
    hit: float | None  # 1.0 hit, 0.0 no; an averaged method's share of alignments; None: does not apply


def full_block() -> Shape:
    return Shape(name="block", mask=np.ones((SPRITE_H, SPRITE_W), dtype=bool))


def disc() -> Shape:
    ys, xs = np.mgrid[0:SPRITE_H, 0:SPRITE_W]
    return Shape(name="disc", mask=(xs - 12) ** 2 + (ys - 10) ** 2 <= DISC_RADIUS2)


def inside_offset(r: int) -> tuple[int, int]:
    """The integer offset with the largest squared distance still below (2r)^2 (then the largest dx)."""
    reach = (2 * r) ** 2
    return max(((dx, dy) for dx in range(2 * r + 1) for dy in range(dx + 1) if dx * dx + dy * dy < reach),
               key=lambda p: (p[0] ** 2 + p[1] ** 2, p[0]))


def circle_cases(r: int) -> dict[str, tuple[int, int]]:
    return {TANGENT: (2 * r, 0), INSIDE: inside_offset(r), APART: (2 * r + 1, 0)}


def reference_box_tests() -> dict[str, Callable[[int], bool]]:
    """The references on two full-sprite boxes, b moved right by dx."""
    from retro.analysis.study.latch import two_sprite_state
    from retro.chips.vic.model import frame_collisions
    from retro.geometry.aabb import aabb_overlap
    from retro.geometry.masks import mask_overlap
    from retro.geometry.sat import sat

    block = full_block()
    square = [(0, 0), (SPRITE_W, 0), (SPRITE_W, SPRITE_H), (0, SPRITE_H)]
    return {
        "retro.geometry aabb_overlap": lambda dx: aabb_overlap((0, 0), (SPRITE_W, SPRITE_H), (dx, 0),
                                                               (dx + SPRITE_W, SPRITE_H)),
        "retro.geometry sat (boxes as polygons)": lambda dx: sat(square, [(x + dx, y) for x, y in square]) is not None,
        "pixel masks (retro.geometry.masks)": lambda dx: mask_overlap(block.mask, block.mask, (dx, 0)),
        "VIC-II model ($D01E)": lambda dx: frame_collisions(two_sprite_state(block, block, 100, 100, 100 + dx, 100)
                                                            ).d01e == 3,
    }


def method_rows(methods: tuple[Method, ...], a: Shape, b: Shape, cases: dict[str, tuple[int, int]]) -> list[EdgeRow]:
    """Every method's rule and 6502 routine on the cases (offsets of b) of one shape pair."""
    rows = []
    pair = pair_at(a, b, list(cases.values()))
    for m in methods:
        verdict = m.verdict(pair)
        rows += [EdgeRow(case, f"rule: {m.label}", float(v)) for case, v in zip(cases, verdict)]
        if m.host_only or m.averaged:
            continue
        session = m.session(pair)
        rows += [EdgeRow(case, f"6502 {m.routine} ({m.key})", float(session.run(i)[0])) for i, case in enumerate(cases)]
    return rows


def edge_table(methods: tuple[Method, ...] = METHODS) -> list[EdgeRow]:
    from retro.geometry.circle import circle_overlap

    rows = []
    for name, test in reference_box_tests().items():
        rows += [EdgeRow(case, name, float(bool(test(dx)))) for case, dx in BOX_CASES.items()]
    block = full_block()
    rows += method_rows(methods, block, block, {case: (dx, 0) for case, dx in BOX_CASES.items()})
    round_shape = disc()
    r = fitted_circle(round_shape.mask).r
    cases = circle_cases(r)
    named = {f"{case} at {offset}, r = {r}": offset for case, offset in cases.items()}
    rows += [EdgeRow(case, "retro.geometry circle_overlap", float(circle_overlap((0, 0), r, offset, r)))
             for case, offset in named.items()]
    rows += method_rows(methods, round_shape, round_shape, named)
    rows += swept_rows()
    return rows


def swept_rows() -> list[EdgeRow]:
    """The swept tests: a box / circle arriving exactly at touching at the end of the frame."""
    from retro.geometry.swept import swept_aabb, swept_circle

    box = swept_aabb((0, 0), (SPRITE_W, SPRITE_H), (4, 0), (SPRITE_W + 4, 0), (2 * SPRITE_W + 4, SPRITE_H))
    circle = swept_circle((0, 0), 5, (4, 0), (14, 0), 5)
    return [EdgeRow("box moving into touching at t = 1", "retro.geometry swept_aabb", float(box is not None)),
            EdgeRow("circle moving into tangency at t = 1", "retro.geometry swept_circle", float(circle is not None))]
