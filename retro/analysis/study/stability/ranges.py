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


def range_rows(reduced: bool = False, progress=None, engine: str = "auto") -> list[RangeRow]:
    """Per routine: the cases inside its stated domain (all must be right), and for each condition of
    the domain the cases that break it and how many of those the assembly answers wrong (a condition
    with wrong answers is needed). The full run uses the exhaustive sweeps of `retro check --exhaustive`."""
    from retro.analysis.check import run_checks
    from retro.workers import configured

    rows = []
    for check in run_checks(None, exhaustive=not reduced, random_count=RANGE_RANDOM_CASES[reduced],
                            progress=progress, engine=engine,
                            jobs=configured(None, None)):  # its sweeps on Dask: local, or $RETRO_SCHEDULER's
        t = check.totals
        stated = " and ".join(c.text for c in check.routine.domain) or "every input"
        rows.append(RangeRow(check.routine.name, f"inside the stated domain ({stated})", t.cases - t.outside,
                             t.result_mismatches, "exact" if t.result_mismatches == 0 else "WRONG inside the domain"))
        for name in (c.text for c in check.routine.domain):
            broken, wrong = t.constraint_cases.get(name, 0), t.constraint_wrong.get(name, 0)
            verdict = ("needed: the routine is wrong there" if wrong else
                       "no wrong answer among these cases" if broken else "no case breaks it")
            rows.append(RangeRow(check.routine.name, f"cases breaking {name}", broken, wrong, verdict))
    return rows


WRAP_W = 24  # full sprite width


def wrap_routine_rows(reduced: bool = False) -> list[WrapRoutineRow]:
    """aabb8 with boxes reaching past 255 (x + w > 255), and aabb_sprite with X across 255/256,
    against the plain-integer overlap of the same boxes. Every pair of positions in the window."""
    from retro.analysis.study.methods.base import routine_runner

    step = 3 if reduced else 1
    aabb8 = routine_runner("aabb8")
    aabb_sprite = routine_runner("aabb_sprite")
    # logical cases: aabb8 (ax, ay, aw, ah, bx, by, bw, bh); aabb_sprite (x1 low, x1 bit 8, y1, ox1,
    # oy1, w1, h1, x2 low, x2 bit 8, y2, ox2, oy2, w2, h2)
    windows = [
        ("aabb8", "x = 200..255 (x + 24 up to 279), w = 24", range(200, 256, step),
         lambda a, b: aabb8.answer((a, 0, WRAP_W, 8, b, 0, WRAP_W, 8))),
        ("aabb_sprite", "9-bit X = 220..299 across 255/256, full 24x21 hitboxes", range(220, 300, step),
         lambda a, b: aabb_sprite.answer((a & 0xFF, a >> 8, 100, 0, 0, WRAP_W, 21,
                                          b & 0xFF, b >> 8, 100, 0, 0, WRAP_W, 21))),
    ]
    rows = []
    for routine, inputs, xs, call in windows:
        wrong, example, cases = 0, None, 0
        for a in xs:
            for b in xs:
                said = bool(call(a, b))
                truth = a < b + WRAP_W and b < a + WRAP_W
                cases += 1
                if said != truth:
                    wrong += 1
                    example = example or f"x1={a}, x2={b}: routine {said}, truth {truth}"
        rows.append(WrapRoutineRow(routine, inputs, cases, wrong, example))
    return rows
