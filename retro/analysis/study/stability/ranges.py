"""Arithmetic range: the exact input domain where each 6502 routine answers correctly, found by
running the assembly (the cross-check's domain search, retro.analysis.check), and the coordinate-wrap
rows of the box routines."""

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


RANGE_RANDOM_CASES = {True: 300, False: 20_000}  # random cases per routine on top of the structured ones


def range_rows(reduced: bool = False, progress=None) -> list[RangeRow]:
    """Per routine: the cases inside its stated domain (all must be right), and for each condition of
    the domain the cases that break it and how many of those the assembly answers wrong (a condition
    with wrong answers is needed). The full run uses the exhaustive sweeps of `retro check --exhaustive`."""
    from retro.analysis.check import run_checks

    rows = []
    for check in run_checks(None, exhaustive=not reduced, random_count=RANGE_RANDOM_CASES[reduced],
                            progress=progress):
        t = check.totals
        stated = " and ".join(name for name, _ in check.routine.domain) or "every input"
        rows.append(RangeRow(check.routine.name, f"inside the stated domain ({stated})", t.cases - t.outside,
                             t.result_mismatches, "exact" if t.result_mismatches == 0 else "WRONG inside the domain"))
        for name, _ in check.routine.domain:
            broken, wrong = t.constraint_cases.get(name, 0), t.constraint_wrong.get(name, 0)
            verdict = ("needed: the routine is wrong there" if wrong else
                       "no wrong answer among these cases" if broken else "no case breaks it")
            rows.append(RangeRow(check.routine.name, f"cases breaking {name}", broken, wrong, verdict))
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
    xs = range(200, 256, step)
    wrong, example, cases = 0, None, 0
    for ax in xs:
        for bx in xs:
            said = machine.call("aabb8", a=ax, x=0, memory={0x10: [WRAP_W, 8, bx, 0, WRAP_W, 8]}).flags["C"]
            truth = ax < bx + WRAP_W and bx < ax + WRAP_W
            cases += 1
            if said != truth:
                wrong += 1
                example = example or f"ax={ax}, bx={bx}: routine {said}, truth {truth}"
    rows.append(WrapRoutineRow("aabb8", "x = 200..255 (x + 24 up to 279), w = 24", cases, wrong, example))
    machine = _machine("aabb_sprite.s", "aabb_sprite")
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
