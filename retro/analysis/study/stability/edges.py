"""Edge conventions: what each method says when shapes touch, overlap by one pixel, or have a gap.

Boxes are sprite hitboxes at pixel positions (x, w): covering pixels x .. x+w-1. "Touching" means
adjacent pixel columns (b.x = a.x + a.w): no pixel is shared, so the VIC-II reports nothing, and a
correct box test must say "no". Circles are given by integer centres and radii; "tangent" means
the centre distance equals r1 + r2 exactly. Each test is run on exactly the same geometry: the
Python references, the study's pixel and latch methods on full sprites, and the 6502 routines.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from retro.analysis.study.corpus import Shape

BOX_W, BOX_H = 8, 8  # a small hitbox, well inside one sprite
BOX_CASES = {"boxes touching (adjacent columns)": BOX_W, "boxes sharing one column": BOX_W - 1,
             "boxes one pixel apart": BOX_W + 1}
CIRCLE_R = 5
CIRCLE_CASES = {"circles tangent (d = r1 + r2)": (2 * CIRCLE_R, 0),
                "circles just inside (largest integer d^2 < (r1 + r2)^2)": None,  # found by _inside_offset
                "circles one pixel apart": (2 * CIRCLE_R + 1, 0)}


@dataclass(frozen=True)
class EdgeRow:
    case: str
    test: str
    hit: bool | None  # None: the test does not apply to this case


def _block_shape(width: int, height: int) -> Shape:
    mask = np.zeros((21, 24), dtype=bool)
    mask[:height, :width] = True
    return Shape(name=f"block{width}x{height}", mask=mask)


def _inside_offset() -> tuple[int, int]:
    """The integer offset with the largest squared distance still below (2r)^2."""
    reach = (2 * CIRCLE_R) ** 2
    return max(((dx, dy) for dx in range(2 * CIRCLE_R + 1) for dy in range(dx + 1) if dx * dx + dy * dy < reach),
               key=lambda p: (p[0] ** 2 + p[1] ** 2, p[0]))


def box_tests() -> dict[str, Callable[[int], bool]]:
    """Tests of two BOX_W x BOX_H boxes, b moved right by dx; and the 6502 routine."""
    from retro.analysis.study.latch import two_sprite_state
    from retro.chips.vic.model import frame_collisions
    from retro.geometry.aabb import aabb_overlap
    from retro.geometry.masks import mask_overlap
    from retro.geometry.sat import sat

    block = _block_shape(BOX_W, BOX_H)
    square = [(0, 0), (BOX_W, 0), (BOX_W, BOX_H), (0, BOX_H)]
    tests = {
        "retro.geometry aabb_overlap": lambda dx: aabb_overlap((0, 0), (BOX_W, BOX_H), (dx, 0), (dx + BOX_W, BOX_H)),
        "retro.geometry sat (boxes as polygons)": lambda dx: sat(square, [(x + dx, y) for x, y in square]) is not None,
        "pixel-perfect (masks)": lambda dx: mask_overlap(block.mask, block.mask, (dx, 0)),
        "VIC-II latch": lambda dx: frame_collisions(two_sprite_state(block, block, 100, 100, 100 + dx, 100)).d01e == 3,
    }
    from retro.analysis.study.stability import routine_edges

    tests.update(routine_edges.box_tests(BOX_W, BOX_H))
    return tests


def circle_tests() -> dict[str, Callable[[int, int], bool]]:
    from retro.geometry.circle import circle_overlap

    tests = {"retro.geometry circle_overlap": lambda dx, dy: circle_overlap((0, 0), CIRCLE_R, (dx, dy), CIRCLE_R)}
    from retro.analysis.study.stability import routine_edges

    tests.update(routine_edges.circle_tests(CIRCLE_R))
    return tests


def edge_table() -> list[EdgeRow]:
    rows = []
    boxes = box_tests()
    for case, dx in BOX_CASES.items():
        rows += [EdgeRow(case, name, bool(test(dx))) for name, test in boxes.items()]
    circles = circle_tests()
    for case, offset in CIRCLE_CASES.items():
        dx, dy = offset if offset is not None else _inside_offset()
        rows += [EdgeRow(f"{case} at ({dx}, {dy})", name, bool(test(dx, dy))) for name, test in circles.items()]
    rows += swept_rows()
    return rows


def swept_rows() -> list[EdgeRow]:
    """The swept tests: a box / circle arriving exactly at touching at the end of the frame."""
    from retro.geometry.swept import swept_aabb, swept_circle

    box = swept_aabb((0, 0), (BOX_W, BOX_H), (4, 0), (BOX_W + 4, 0), (2 * BOX_W + 4, BOX_H))
    circle = swept_circle((0, 0), CIRCLE_R, (4, 0), (2 * CIRCLE_R + 4, 0), CIRCLE_R)
    return [EdgeRow("box moving into touching at t = 1", "retro.geometry swept_aabb", box is not None),
            EdgeRow("circle moving into tangency at t = 1", "retro.geometry swept_circle", circle is not None)]
