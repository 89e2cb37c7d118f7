"""What collecting code coverage costs a check on the batched core: the same `retro check --engine
batch` (its default cases, one job) with coverage collected and with it left out, timed side by side
in one run (alternating, best of --repeats each). "Left out" replaces the batched blocks' collection
and the check's last step (every reachable instruction listed, the worst case's path run again) by
nothing; the rest of the check (the rows, the Machine agreement runs, the reference, the tally, the
static bounds) is the same in both; the coverage-guided search is off in both (it is not collection:
its cost is its budget, docs/specs.md). Goal: coverage costs at most 15% of a check's time.

    PYTHONPATH=. python benchmarks/coverage_cost.py [ROUTINE ...] [--repeats N]
"""

from __future__ import annotations

import argparse
import time
from contextlib import contextmanager

from retro.analysis.check import run as check_run
from retro.routines.registry import builtin_names, spec_path

GOAL = 1.15


def _without_coverage(run_on_batched_core):
    def run(runner, columns, confirm_stop=True, coverage=True, engine="batch"):
        return run_on_batched_core(runner, columns, confirm_stop, False, engine)
    return run


@contextmanager
def coverage_left_out():
    """The check's blocks (run.array_block through `run_on_batched_core`) run without collecting
    coverage, and its last step (completed, worst_path) does nothing."""
    saved = check_run.run_on_batched_core, check_run.completed, check_run.worst_path
    check_run.run_on_batched_core = _without_coverage(saved[0])
    check_run.completed = lambda coverage, runner: coverage
    check_run.worst_path = lambda runner, case: ()
    try:
        yield
    finally:
        check_run.run_on_batched_core, check_run.completed, check_run.worst_path = saved


def seconds(name: str, random: int | None) -> tuple[float, int]:
    start = time.perf_counter()
    check = check_run.check_routine(str(spec_path(name)), engine="batch", jobs=1, random_count=random,
                                    search_budget=0)
    return time.perf_counter() - start, check.totals.cases


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("routines", nargs="*", default=[n for n in builtin_names() if not n.endswith("_prepare")])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--random", type=int, default=None, help="random cases per check (default: the spec's)")
    options = parser.parse_args()
    print(f"{'routine':<16} {'cases':>8} {'without (s)':>12} {'with (s)':>10} {'ratio':>7}")
    worst = 0.0
    for name in options.routines:
        seconds(name, options.random)  # warm: the spec loaded, the runner built, the tables made
        without, with_ = float("inf"), float("inf")
        for _ in range(options.repeats):
            with coverage_left_out():
                without = min(without, seconds(name, options.random)[0])
            took, cases = seconds(name, options.random)
            with_ = min(with_, took)
        ratio = with_ / without
        worst = max(worst, ratio)
        print(f"{name:<16} {cases:>8,} {without:>12.3f} {with_:>10.3f} {ratio:>6.3f}x")
    print(f"highest ratio {worst:.3f}x (goal: at most {GOAL:.2f}x)")


if __name__ == "__main__":
    main()
