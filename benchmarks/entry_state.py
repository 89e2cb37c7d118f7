"""What the entry-state runs (issue 23 part 2: a sample of the cases again with the unnamed
registers, flags and untouched memory all ones and random) cost a check: the same check with and
without them, side by side in one run, on both engines, one process (jobs = 1), best of `--repeat`
(the two alternate, so that a machine's changing load weighs on both alike).

    PYTHONPATH=. python benchmarks/entry_state.py [--repeat 5]

The default check reruns every case up to 2,000 planned cases, then about 2,000 of them (every k-th);
with --exhaustive every case up to 65,536. Each rerun case costs two more calls on the check's
engine (no reference calls: the check's own outputs are the baseline).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from retro.analysis.check import check_routine
from retro.routines.registry import spec_path

ROOT = Path(__file__).resolve().parents[1]
CHECKS = [  # (spec, engine, exhaustive, random)
    ("mul8", "scalar", False, None),
    ("tile", "scalar", False, None),
    ("circle_r", "batch", False, None),
    ("aabb_edges_prepare", "batch", False, None),
    ("examples/boxhit/boxhit.toml", "batch", False, None),
    ("tests/data/entry/overlap8_stated.toml", "batch", True, None),
    ("tests/data/entry/overlap8_stated.toml", "scalar", False, 20_000),
]


def timed(spec: str, engine: str, exhaustive: bool, random: int | None, entry: bool) -> tuple[float, object]:
    began = time.perf_counter()
    check = check_routine(spec, engine=engine, exhaustive=exhaustive, random_count=random, jobs=1, entry_state=entry)
    return time.perf_counter() - began, check


def best_of(spec: str, engine: str, exhaustive: bool, random: int | None, repeat: int) -> tuple[float, float, object]:
    """Best times without and with the entry-state runs, the two alternating (load drifts alike)."""
    without = with_runs = float("inf")
    check = None
    for _ in range(repeat):
        without = min(without, timed(spec, engine, exhaustive, random, False)[0])
        seconds, check = timed(spec, engine, exhaustive, random, True)
        with_runs = min(with_runs, seconds)
    return without, with_runs, check


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=5)
    repeat = parser.parse_args().repeat
    print(f"{'check':<48} {'engine':<7} {'cases':>8} {'rerun':>7} {'without s':>10} {'with s':>8} {'ratio':>6}")
    for spec, engine, exhaustive, random in CHECKS:
        name = Path(spec).name
        resolved = str(ROOT / spec) if spec.endswith(".toml") else str(spec_path(spec))
        without, with_runs, check = best_of(resolved, engine, exhaustive, random, repeat)
        label = name + (" --exhaustive" if exhaustive else "") + (f" --random {random}" if random else "")
        print(f"{label:<48} {engine:<7} {check.totals.cases:>8,} {check.totals.entry_cases:>7,} "
              f"{without:>10.2f} {with_runs:>8.2f} {with_runs / without:>6.2f}")


if __name__ == "__main__":
    main()
