"""`retro demo` step of the collision routines: a bounded cross-check and the cycles table."""

from __future__ import annotations

import json
from pathlib import Path

from retro.analysis.check import run_checks
from retro.analysis.cost import cost_row, format_cost_table
from retro.fileio import write_atomic

DEMO_RANDOM_CASES = 150
DEMO_EXHAUSTIVE_SAMPLE = 1_000  # cases of each exhaustive set (sampled): the demo stays a few seconds


def cycles_table(out_dir: Path) -> list[str]:
    checks = run_checks(None, random_count=DEMO_RANDOM_CASES, jobs=1, bounded_product=DEMO_EXHAUSTIVE_SAMPLE)
    write_atomic(out_dir / "routine_cycles.json", json.dumps([cost_row(c) for c in checks], indent=1) + "\n")
    lines = format_cost_table(checks)
    total = sum(c.totals.cases for c in checks)
    bad = sum(c.mismatches for c in checks)
    lines.append(f"{total} calls checked against the references and the timing model: {bad} mismatches "
                 f"(full run: retro check --exhaustive)")
    lines.append("wrote routine_cycles.json")
    return lines
