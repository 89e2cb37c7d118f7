"""`retro cycles`: bytes of code and tables, measured and static cycles and raster lines of routines.

The same run as `retro check` (every case checked), shown as a cost table."""

from __future__ import annotations

from retro.analysis.check import RoutineCheck
from retro.analysis.cost import cost_row, format_cost_table
from retro.commands.check import check as cycles  # one run, two views: the command is the check itself
from retro.commands.check import failed

__all__ = ["cycles", "failed", "as_json", "lines"]


def as_json(checks: list[RoutineCheck]) -> list[dict]:
    """One object per routine with the fields of retro.analysis.cost.COST_FIELDS."""
    return [cost_row(c) for c in checks]


def lines(checks: list[RoutineCheck]) -> list[str]:
    notes = dict.fromkeys(note for c in checks for note in c.routine.notes)  # a symbol file shared by specs: once
    return format_cost_table(checks) + [f"note: {note}" for note in notes]
