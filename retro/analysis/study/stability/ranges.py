"""Arithmetic range: the exact input domain where each 6502 routine answers correctly, found by
running the assembly (filled in from issue 5's routines and domain search when they exist)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RangeRow:
    routine: str
    searched: str
    cases: int
    wrong: int
    domain: str


@dataclass(frozen=True)
class WrapRoutineRow:
    routine: str
    inputs: str
    cases: int
    mismatches: int
    example: str | None


def range_rows(reduced: bool = False) -> list[RangeRow]:
    """A minimal domain search run on the assembly (issue 5's `retro check` domain search was not in
    the tree; this is the study's own, marked as such): every input in the searched space, compared
    with the plain-integer definition. `reduced` takes every 5th value of the swept coordinates."""
    from retro.analysis.study.stability.routine_edges import _machine

    step = 5 if reduced else 1
    rows = []
    machine = _machine("circle.s", "circle")
    if machine is not None:
        for r1, r2 in ((1, 1), (50, 60), (127, 128), (128, 128)):
            wrong, cases, first = 0, 0, None
            for x2 in range(0, 256, step):
                for y2 in range(0, 256, step):
                    said = machine.call("circle", memory={0x10: [128, 128, r1, x2, y2, r2]}).flags["C"]
                    truth = (128 - x2) ** 2 + (128 - y2) ** 2 < (r1 + r2) ** 2
                    cases += 1
                    if said != truth:
                        wrong += 1
                        first = first or f"centre 2 ({x2}, {y2}): routine {bool(said)}, truth {truth}"
            rows.append(RangeRow("circle", f"r1 = {r1}, r2 = {r2} (sum {r1 + r2}); centre 1 (128, 128), centre 2 "
                                 f"over the 8-bit grid", cases, wrong,
                                 "correct on every input searched" if wrong == 0 else f"wrong, first at {first}"))
    machine = _machine("aabb8.s", "aabb8")
    if machine is not None:
        wrong, cases, first = 0, 0, None
        for aw, bw in ((1, 1), (24, 24), (255, 1), (200, 200)):
            for ax in range(0, 256, step * 4):
                for bx in range(0, 256, step):
                    said = machine.call("aabb8", memory={0x10: [ax, 0, aw, 1, bx, 0, bw, 1]}).flags["C"]
                    truth = ax < bx + bw and bx < ax + aw
                    cases += 1
                    if said != truth:
                        wrong += 1
                        first = first or f"ax={ax} aw={aw} bx={bx} bw={bw}"
        rows.append(RangeRow("aabb8", "x of both boxes over 0..255, widths {1,1}, {24,24}, {255,1}, {200,200}",
                             cases, wrong, "every input searched (x + w past 255 included)" if wrong == 0
                             else f"wrong answers, first at {first}"))
    return rows


WRAP_W = 24  # full sprite width


def wrap_routine_rows(reduced: bool = False) -> list[WrapRoutineRow]:
    """aabb8 with boxes reaching past 255 (x + w > 255), and aabb_sprite with X across 255/256,
    against the plain-integer overlap of the same boxes. Every pair of positions in the window."""
    from retro.analysis.study.stability.routine_edges import _machine
    from retro.cpu.machine import DEFAULT_FLAGS

    rows = []
    step = 3 if reduced else 1
    machine = _machine("aabb8.s", "aabb8")
    if machine is not None:
        xs = range(200, 256, step)
        wrong, example, cases = 0, None, 0
        for ax in xs:
            for bx in xs:
                said = machine.call("aabb8", memory={0x10: [ax, 0, WRAP_W, 8, bx, 0, WRAP_W, 8]}).flags["C"]
                truth = ax < bx + WRAP_W and bx < ax + WRAP_W
                cases += 1
                if said != truth:
                    wrong += 1
                    example = example or f"ax={ax}, bx={bx}: routine {said}, truth {truth}"
        rows.append(WrapRoutineRow("aabb8", f"x = 200..255 (x + 24 up to 279), w = 24", cases, wrong, example))
    machine = _machine("aabb_sprite.s", "aabb_sprite")
    if machine is not None:
        xs = range(220, 300, step)
        wrong, example, cases = 0, None, 0
        for x1 in xs:
            for x2 in xs:
                # asm/aabb_sprite.s: sprite 2's X in A and the carry, y2 in Y, x1h in X, the rest zero page
                memory = {0x10: [x1 & 0xFF, 100, 0, 0, WRAP_W, 21, 0, 0, WRAP_W, 21]}
                said = machine.call("aabb_sprite", a=x2 & 0xFF, x=x1 >> 8, y=100, p=DEFAULT_FLAGS | (x2 >> 8),
                                    memory=memory).flags["C"]
                truth = x1 < x2 + WRAP_W and x2 < x1 + WRAP_W
                cases += 1
                if said != truth:
                    wrong += 1
                    example = example or f"x1={x1}, x2={x2}: routine {said}, truth {truth}"
        rows.append(WrapRoutineRow("aabb_sprite", "9-bit X = 220..299 across 255/256, full 24x21 hitboxes",
                                   cases, wrong, example))
    return rows
