"""The 6502 routines' answers on the edge-convention cases (issue 5's asm/aabb8.s, asm/circle.s)."""

from __future__ import annotations

from collections.abc import Callable

BASE = 100  # box a / circle a sits here; every coordinate stays within 8 bits


def _machine(source: str, entry: str):
    from retro.analysis.study.routine_inputs import _program
    from retro.cpu import Machine

    try:
        program = _program(source)
    except Exception:  # the routine is not in the tree: the table simply lacks its column
        return None
    if entry not in program.symbols:
        return None
    machine = Machine()
    machine.load(program)
    return machine


def box_tests(width: int, height: int) -> dict[str, Callable[[int], bool]]:
    machine = _machine("aabb8.s", "aabb8")
    if machine is None:
        return {}

    def test(dx: int) -> bool:
        values = [BASE, BASE, width, height, BASE + dx, BASE, width, height]
        return bool(machine.call("aabb8", memory={0x10: values}).flags["C"])
    return {"6502 aabb8": test}


def circle_tests(radius: int) -> dict[str, Callable[[int, int], bool]]:
    machine = _machine("circle.s", "circle")
    if machine is None:
        return {}

    def test(dx: int, dy: int) -> bool:
        values = [BASE, BASE, radius, BASE + dx, BASE + dy, radius]
        return bool(machine.call("circle", memory={0x10: values}).flags["C"])
    return {"6502 circle": test}
