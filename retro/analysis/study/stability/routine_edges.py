"""The 6502 routines' answers on the edge-convention cases (issue 5's asm/aabb8.s, asm/circle.s)."""

from __future__ import annotations

from collections.abc import Callable

BASE = 100  # box a / circle a sits here; every coordinate stays within 8 bits


def _machine(source: str, entry: str):
    from retro.analysis.study.routine_inputs import _program
    from retro.cpu import Machine

    machine = Machine()
    machine.load(_program(source))
    machine.resolve(entry, "entry")  # a renamed entry fails here, not as a silently missing column
    return machine


def box_tests(width: int, height: int) -> dict[str, Callable[[int], bool]]:
    machine = _machine("aabb8.s", "aabb8")

    def test(dx: int) -> bool:
        values = [width, height, BASE + dx, BASE, width, height]  # asm/aabb8.s: box a's x in A, y in X
        return bool(machine.call("aabb8", a=BASE, x=BASE, memory={0x10: values}).flags["C"])
    return {"6502 aabb8": test}


def circle_tests(radius: int) -> dict[str, Callable[[int, int], bool]]:
    machine = _machine("circle.s", "circle")

    def test(dx: int, dy: int) -> bool:
        values = [BASE + dx, BASE + dy, radius]  # asm/circle.s: circle a's x in A, radius in X
        return bool(machine.call("circle", a=BASE, x=radius, memory={"y1": BASE, "x2": values}).flags["C"])
    return {"6502 circle": test}
