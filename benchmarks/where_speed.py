"""What a `where` costs per block of cases: the domain evaluator of a revision (default: 64be42f, numpy
semantics) beside the working tree's (Python's integer semantics, checked), side by side.

The batched core tests each condition over a column block of up to 65,536 cases; this times that call
for every built-in spec's `where` and a few expressions that use //, %, >>, `x if c else y` and
`and`/`or` values. Columns are drawn uniformly from each input's values.

    PYTHONPATH=. python benchmarks/where_speed.py [--before REV]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
import types
from pathlib import Path

import numpy as np

from retro.routines import where as after
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[1]
LANES = 65_536
EXTRA = [("ax // (bw + 1) <= 9 and ax % 7 != 3", ("ax", "bw")),
         ("(ax >> 2) + (bw << 3) < 900", ("ax", "bw")),
         ("(ax if bw > 10 else bw) >= 5 and (ax or bw) > 3", ("ax", "bw"))]


def revision_module(revision: str) -> types.ModuleType:
    source = subprocess.run(["git", "show", f"{revision}:retro/routines/where.py"], cwd=ROOT, check=True,
                            capture_output=True, text=True).stdout
    module = types.ModuleType("where_before")
    sys.modules["where_before"] = module
    exec(compile(source, f"{revision}:where.py", "exec"), module.__dict__)
    return module


def per_block(conditions, columns) -> float:
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        for condition in conditions:
            condition.over(columns)
        best = min(best, time.perf_counter() - start)
    return best * 1e3


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--before", default="64be42f")
    before = revision_module(parser.parse_args().before)
    rng = np.random.default_rng(1)
    rows = []
    for spec in sorted((ROOT / "asm").glob("*.toml")):
        routine = load_spec(spec)
        text = next((line.split("=", 1)[1].strip().strip('"') for line in spec.read_text().splitlines()
                     if line.startswith("where")), None)
        if text is None:
            continue
        names = routine.input_names
        columns = [rng.integers(p.values.lo, p.values.hi + 1, size=(LANES, len(p.places)) if p.table else LANES)
                   for p in routine.inputs]
        tables = frozenset(p.name for p in routine.inputs if p.table)
        bounds = {p.name: (p.values.lo, p.values.hi) for p in routine.inputs if not p.table}
        rows.append((routine.name, text, names, tables, bounds, columns))
    for text, names in EXTRA:
        rows.append(("(extra)", text, names, frozenset(), {n: (0, 255) for n in names},
                     [rng.integers(0, 256, size=LANES) for _ in names]))
    print(f"ms per block of {LANES:,} cases (best of 5)")
    print(f"{'routine':<18} {'before':>8} {'after':>8} {'after/before':>13}  where")
    for name, text, names, tables, bounds, columns in rows:
        old = before.parse_where(text, names, "bench", tables)
        new = after.parse_where(text, names, "bench", tables, bounds)
        t_old, t_new = per_block(old, columns), per_block(new, columns)
        same = all(np.array_equal(a.over(columns), b.over(columns)) for a, b in zip(old, new))
        print(f"{name:<18} {t_old:8.2f} {t_new:8.2f} {t_new / t_old:12.2f}x  {text[:60]}"
              + ("" if same else "   (answers differ: numpy wrapped or divided by zero)"))


if __name__ == "__main__":
    main()
