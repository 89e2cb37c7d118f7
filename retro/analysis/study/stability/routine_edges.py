"""The 6502 routines' answers on the edge-convention cases (joined to edges.py when they exist)."""

from __future__ import annotations

from collections.abc import Callable


def box_tests(width: int, height: int) -> dict[str, Callable[[int], bool]]:
    return {}


def circle_tests(radius: int) -> dict[str, Callable[[int, int], bool]]:
    return {}
