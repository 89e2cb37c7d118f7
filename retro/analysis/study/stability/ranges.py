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
    return []


def wrap_routine_rows() -> list[WrapRoutineRow]:
    return []
