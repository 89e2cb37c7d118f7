"""The 6502 routines' answers on the edge-convention cases (issue 5's asm/aabb8.s, asm/circle.s).

Calls go through the routines' specs (logical cases in the reference's argument order), so the
calling conventions live in one place.
"""

from __future__ import annotations

from collections.abc import Callable

BASE = 100  # box a / circle a sits here; every coordinate stays within 8 bits


def box_tests(width: int, height: int) -> dict[str, Callable[[int], bool]]:
    from retro.analysis.study.routine_inputs import routine_runner

    runner = routine_runner("aabb8")

    def test(dx: int) -> bool:
        return bool(runner.answer((BASE, BASE, width, height, BASE + dx, BASE, width, height)))
    return {"6502 aabb8": test}


def circle_tests(radius: int) -> dict[str, Callable[[int, int], bool]]:
    from retro.analysis.study.routine_inputs import routine_runner

    runner = routine_runner("circle")

    def test(dx: int, dy: int) -> bool:
        return bool(runner.answer((BASE, BASE, radius, BASE + dx, BASE + dy, radius)))
    return {"6502 circle": test}
