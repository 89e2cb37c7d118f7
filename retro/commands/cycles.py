"""`retro cycles`: bytes of code and tables, measured and static cycles and raster lines of routines.

The same run as `retro check` (every case checked), shown as a cost table."""

from __future__ import annotations

from retro.analysis.check import RoutineCheck
from retro.commands.check import check as cycles  # one run, two views: the command is the check itself
from retro.commands.check import cycle_figures, failed
from retro.paths import ASM_DIR
import argparse
from retro.commands import options
from retro.commands.check import checks_of, routine_options

__all__ = ["COST_FIELDS", "cycles", "failed", "as_json", "lines"]


def as_json(checks: list[RoutineCheck]) -> list[dict]:
    """One object per routine with the fields of COST_FIELDS."""
    return [cost_row(c) for c in checks]


def lines(checks: list[RoutineCheck]) -> list[str]:
    notes = dict.fromkeys(note for c in checks for note in c.routine.notes)  # a symbol file shared by specs: once
    return format_cost_table(checks) + [f"note: {note}" for note in notes]


# ---- the cost table: bytes, measured and static cycles, cases and mismatches ------------------------

COST_FIELDS = ("routine", "code_bytes", "table_bytes", "table_blocks", "min", "mean", "max", "static_min", "static_max",
               "cases", "mismatches", "min_inputs", "max_inputs", "budget", "vblank", "raster")

# Issue 5's targets: (statistic, cycles). The statistic is "max" (worst case) or "mean".
TARGETS: dict[str, tuple[str, int]] = {"aabb8": ("max", 30), "aabb_sprite": ("max", 45), "circle": ("max", 65),
                                       "tile": ("max", 45), "mul8": ("mean", 46)}


def cost_row(check: RoutineCheck) -> dict:
    figures = cycle_figures(check)
    row = {"routine": check.routine.name, "code_bytes": check.size.code_bytes, "table_bytes": check.size.table_bytes,
           "table_blocks": dict(check.size.table_blocks),
           **figures, "cases": check.totals.cases, "mismatches": check.mismatches}
    return {key: row[key] for key in COST_FIELDS}


def target_note(row: dict, builtin: bool = True) -> str:
    target = TARGETS.get(row["routine"]) if builtin else None
    if not target:
        return ""
    statistic, cycles = target
    value = row[statistic]
    return f"{statistic} {value} vs target <= {cycles}: {'met' if value <= cycles else 'missed'}"


def budget_note(row: dict) -> str:
    if row["budget"] is None or row["max"] is None:
        return ""
    return f"max {row['max']} vs budget <= {row['budget']}: {'kept' if row['max'] <= row['budget'] else 'broken'}"


def format_cost_table(checks: list[RoutineCheck]) -> list[str]:
    header = ("routine", "code", "tables", "min", "mean", "max", "static", "worst hit", "max lines", "cases", "mismatch",
              "target")
    rows = []
    for check in checks:
        r = cost_row(check)
        static = f"{r['static_min']}-{r['static_max']}" if check.static else (
            "unknown" if check.rows is not None and check.rows.static_note else "off")
        timelines = r["raster"]
        lines_at_most = timelines.get("scene", next(iter(timelines.values()), {})).get("max_lines")
        rows.append((r["routine"], str(r["code_bytes"]), str(r["table_bytes"]), str(r["min"]), f"{r['mean']:.2f}",
                     str(r["max"]), static, "yes" if check.worst_reached else "no",
                     "-" if lines_at_most is None else f"{lines_at_most:.2f}", str(r["cases"]), str(r["mismatches"]),
                     target_note(r, check.routine.spec_path.parent == ASM_DIR) or budget_note(r)))
    widths = [max(len(h), *(len(row[i]) for row in rows)) for i, h in enumerate(header)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(header, widths)).rstrip()]
    lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    lines.append("max lines: raster lines of the slowest case: on the --scene from its start line when given, "
                 "else on a C64 PAL (6510 routines) or an NTSC NES (2A03) with the CPU never stalled")
    lines.append("cycles: from the routine's first instruction through its RTS (the caller's JSR, 6, not included); "
                 "bytes of tables exclude storage the caller fills")
    for check in checks:
        if check.size.table_blocks:
            lines.append(f"tables of {check.routine.name}: the [memory] blocks it read: " + ", ".join(
                f"{name} ({size:,} bytes)" for name, size in check.size.table_blocks))
    return lines


# The command line: this command's options and how it runs from them.

HELP = "bytes of code and tables, measured and static cycles, raster lines of routines (built-in or your own spec)"
PARSER = {"description": f"--json prints a list of objects with the fields {', '.join(COST_FIELDS)}"}


def add_options(p: argparse.ArgumentParser) -> None:
    routine_options(p)


def main(args: argparse.Namespace) -> int:
    checks = checks_of(args)
    options.show(lines, as_json if args.json else None, checks, indent=1)
    return 1 if failed(checks) else 0
