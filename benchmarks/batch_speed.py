"""The batched core against Machine, side by side in one run (issue 11's figures).

For each routine: calls per second of `RoutineRunner.run_batch` (the batched core) at N = 256, 4,096
and 65,536 lanes, and of `RoutineRunner.run` (Machine) on the same cases, and their ratio. The cases
are the routine's own random cases (its spec's generator: half of them near the answer's edge, so
lanes diverge as they would in a check). Then a 2^24-case sweep of circle on the batched core, and
with --check the wall time of `retro check --exhaustive` with each engine (minutes: the scalar run
takes long).

    python benchmarks/batch_speed.py [ROUTINE ...] [--check]
"""

from __future__ import annotations

import json
import subprocess
import sys
import time

import numpy as np

from retro.routines import cases as case_sets
from retro.routines.registry import get
from retro.routines.runner import RoutineRunner

GOALS = {"aabb8": 100, "circle": 100, "mul8": 100, "tile": 100, "aabb_sprite": 30}
LANES = (256, 4_096, 65_536)
SCALAR_CASES = 3_000
MIN_SECONDS = 0.3
SWEEP_CASES = 1 << 24


def random_block(routine, n: int) -> list:
    parts = [p for p in case_sets.plan(routine, exhaustive=True, seed=routine.seed, random=n) if p.name == "random"]
    return next(case_sets.batches(parts, n))


def per_second(run, count: int) -> float:
    """Calls per second of run() (count calls each), repeated for at least MIN_SECONDS."""
    done, start = 0, time.perf_counter()
    while True:
        run()
        done += count
        elapsed = time.perf_counter() - start
        if elapsed >= MIN_SECONDS:
            return done / elapsed


def routine_row(name: str) -> None:
    routine = get(name)
    runner = RoutineRunner(routine, routine.seed)
    block = random_block(routine, max(LANES))
    cases = case_sets.columns_to_cases([c[:SCALAR_CASES] for c in block])

    def scalar() -> None:
        for case in cases:
            runner.run(case)
    machine = per_second(scalar, len(cases))
    cells = []
    for n in LANES:
        lanes = [c[:n] for c in block]
        rate = per_second(lambda: runner.run_batch(lanes), n)
        cells.append(f"{rate:>12,.0f} ({rate / machine:6.1f}x)")
    goal = GOALS.get(name)
    print(f"{name:<13} {machine:>9,.0f}  " + "  ".join(cells) + (f"  goal >= {goal}x at 65,536" if goal else ""))


def circle_sweep() -> None:
    routine = get("circle")
    runner = RoutineRunner(routine, routine.seed)
    sweep = [p for p in case_sets.plan(routine, exhaustive=True, seed=routine.seed) if p.name == "sweep"]
    done, engine = 0, 0.0
    start = time.perf_counter()
    for block in case_sets.batches(sweep, 65_536):
        t = time.perf_counter()
        runner.run_batch(block)
        engine += time.perf_counter() - t
        done += len(block[0])
        if done >= SWEEP_CASES:
            break
    total = time.perf_counter() - start
    print(f"circle sweep, {done:,} cases (every dy and radius sum for {done // (511 * 256)} values of dx): "
          f"{total:.1f} s with case generation, {engine:.1f} s in the batched core (goal: under 5 s)")


BIG_SWEEPS = ("circle", "circle_r")  # 67 million calls each: hours on Machine
PROOF_SWEEPS = ("aabb8", "mul16")  # 3 x 2^32 and 2^32 calls: hours on the batched core, days on Machine; measured on
# the compiled engine by benchmarks/aabb8_sweep.py and benchmarks/mul16_sweep.py


def _wall(args: list[str]) -> tuple[float, str]:
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "retro", "check", *args, "--json"], capture_output=True, text=True)
    cases = sum(r["cases"] for r in json.loads(result.stdout)) if result.stdout.strip() else 0
    return time.perf_counter() - start, f"{cases:,} calls, exit {result.returncode}"


def check_walls() -> None:
    """retro check --exhaustive on both engines, side by side, for every routine but the two 67-million
    call sweeps and the full proofs (PROOF_SWEEPS); the first on the batched core, and on Machine
    extrapolated from its measured rate."""
    from retro.routines.registry import builtin_names

    rest = [n for n in builtin_names() if n not in BIG_SWEEPS + PROOF_SWEEPS]
    batch_s, batch_what = _wall(["--exhaustive", "--engine", "batch", *rest])
    scalar_s, scalar_what = _wall(["--exhaustive", "--engine", "scalar", *rest])
    print(f"retro check --exhaustive ({len(rest)} routines): batch {batch_s:.1f} s ({batch_what}), "
          f"scalar {scalar_s:.1f} s ({scalar_what}): {scalar_s / batch_s:.1f}x")
    for name in BIG_SWEEPS:
        big_s, big_what = _wall(["--exhaustive", "--engine", "batch", name])
        calls = _calls(big_what)
        # Machine's rate from two runs of different length (their difference cancels start-up)
        short_s, short_what = _wall(["--engine", "scalar", "--jobs", "2", name, "--random", "20000"])
        long_s, long_what = _wall(["--engine", "scalar", "--jobs", "2", name, "--random", "200000"])
        per_call = (long_s - short_s) / (_calls(long_what) - _calls(short_what))
        print(f"retro check --exhaustive {name}: batch {big_s:.1f} s ({big_what}); Machine on two cores at "
              f"{1 / per_call:,.0f} calls/s (measured between {_calls(short_what):,} and {_calls(long_what):,} calls): "
              f"about {calls * per_call / 60:.0f} min")


def _calls(what: str) -> int:
    return int(what.split(" calls")[0].replace(",", ""))


def main(argv: list[str]) -> None:
    names = [a for a in argv if not a.startswith("--")] or ["aabb8", "circle", "mul8", "tile", "aabb_sprite",
                                                            "tile_box", "pixel", "aabb_edges", "circle_r",
                                                            "sprite_edges"]
    print(f"numpy {np.__version__}; calls per second (ratio to Machine), the routine's random cases")
    print(f"{'routine':<13} {'Machine':>9}  " + "  ".join(f"{f'batch N={n:,}':>22}" for n in LANES))
    for name in names:
        routine_row(name)
    circle_sweep()
    if "--check" in argv:
        check_walls()


if __name__ == "__main__":
    main(sys.argv[1:])
