"""The compiled engine against the batched core and Machine, side by side in one run (issue 24's figures).

For each routine: calls per CPU-second (time.process_time: the machine is shared, wall time would
measure the neighbours) of Machine (`RoutineRunner.run`), the batched core (`run_batch`, 65,536 lanes)
and the compiled engine (`run_compiled`, the same 65,536 cases, calls it leaves to the batched core
included), on the routine's own random cases (its spec's generator: half of them near the answer's
edge: the branches go either way at random, the compiled engine's worst case); then the batched core
and the compiled engine on the first SWEEP_BLOCKS blocks of the routine's `--exhaustive` cases (its
exhaustive product, else its sweep: what a proof runs, the issue's measure); the ratios; and apart, the compiled engine's compile time (CPU seconds, into an empty cache)
and its load time from the cache, and from how many calls the compile pays for itself against the
batched core (what `--engine auto`'s AUTO_COMPILED_CASES is set from).

    python benchmarks/compiled_speed.py [ROUTINE ...]
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from itertools import islice

import numpy as np

from retro.cpu import compiled as compiled_module
from retro.cpu.compiled import Untranslatable, numba_problem
from retro.routines import cases as case_sets
from retro.routines.registry import get
from retro.routines.runner import RoutineRunner

LANES = 65_536
SCALAR_CASES = 2_000
MIN_SECONDS = 0.5
ROUTINES = ["aabb8", "mul8", "circle", "tile", "tile_box", "pixel", "aabb_sprite", "aabb_edges", "circle_r",
            "sprite_edges"]
GOAL = 8  # the issue: at least 8x the batched core on aabb8, mul8, circle and tile
SWEEP_BLOCKS = 4


def random_block(routine, n: int) -> list:
    parts = [p for p in case_sets.plan(routine, exhaustive=True, seed=routine.seed, random=n) if p.name == "random"]
    return next(case_sets.batches(parts, n))


def sweep_blocks(routine, n: int) -> list:
    """The first SWEEP_BLOCKS blocks of `n` cases of the exhaustive product, else of the sweep ([] if neither)."""
    parts = case_sets.plan(routine, exhaustive=True, seed=routine.seed, random=0)
    chosen = [p for p in parts if p.name == "exhaustive"] or [p for p in parts if p.name == "sweep"]
    return list(islice(case_sets.batches(chosen, n), SWEEP_BLOCKS)) if chosen else []


def _each(run, blocks: list):
    def every() -> None:
        for block in blocks:
            run(block)
    return every


def per_cpu_second(run, count: int) -> float:
    done, start = 0, time.process_time()
    while True:
        run()
        done += count
        spent = time.process_time() - start
        if spent >= MIN_SECONDS:
            return done / spent


def row(name: str) -> None:
    routine = get(name)
    runner = RoutineRunner(routine, routine.seed)
    block = random_block(routine, LANES)
    cases = case_sets.columns_to_cases([c[:SCALAR_CASES] for c in block])

    def scalar() -> None:
        for case in cases:
            runner.run(case)
    machine = per_cpu_second(scalar, len(cases))
    batch = per_cpu_second(lambda: runner.run_batch(block), LANES)
    compiled_module._LOADED.clear()
    began = time.process_time()
    try:
        compiled = runner.compiled()
    except Untranslatable as exc:
        print(f"{name:<13} {machine:>10,.0f} {batch:>12,.0f}  not compiled: {exc}")
        return
    cold = time.process_time() - began
    compiled_module._LOADED.clear()
    runner._compiled = None
    began = time.process_time()
    warm = runner.compiled()
    load = time.process_time() - began
    assert warm.from_cache and not compiled.from_cache
    fast = per_cpu_second(lambda: runner.run_compiled(block), LANES)
    saved = 1 / batch - 1 / fast
    pays = f"{cold / saved:>13,.0f}" if saved > 0 else f"{'never':>13}"
    goal = f"  goal >= {GOAL}x" if name in ("aabb8", "mul8", "circle", "tile") else ""
    blocks = sweep_blocks(routine, LANES)
    if blocks:
        calls = sum(len(b[0]) for b in blocks)
        sweep_batch = per_cpu_second(_each(runner.run_batch, blocks), calls)
        sweep_fast = per_cpu_second(_each(runner.run_compiled, blocks), calls)
        sweep = f"{sweep_batch:>12,.0f} {sweep_fast:>13,.0f} {sweep_fast / sweep_batch:>7.1f}x"
    else:
        sweep = f"{'(none)':>12} {'':>13} {'':>8}"
    print(f"{name:<13} {machine:>10,.0f} {batch:>12,.0f} {fast:>13,.0f} {fast / batch:>7.1f}x {fast / machine:>8.0f}x "
          f"{sweep} {cold:>9.2f} {load:>7.2f} {len(compiled.translation.blocks):>6} {pays}{goal}")


def main(argv: list[str]) -> None:
    problem = numba_problem()
    if problem:
        sys.exit(f"compiled_speed: {problem}")
    import numba

    names = [a for a in argv if not a.startswith("--")] or ROUTINES
    with tempfile.TemporaryDirectory() as cache:
        os.environ["RETRO_CACHE"] = cache  # an empty cache: the compile times are cold
        print(f"numpy {np.__version__}, numba {numba.__version__}; calls per CPU-second on {LANES:,} random cases "
              f"(Machine: {SCALAR_CASES:,}); compile and load in CPU seconds")
        print(f"{'':<13} {'random cases':-^55} {'--exhaustive cases':-^35}")
        print(f"{'routine':<13} {'Machine':>10} {'batch':>12} {'compiled':>13} {'/batch':>8} {'/Machine':>9} "
              f"{'batch':>12} {'compiled':>13} {'/batch':>8} "
              f"{'compile':>9} {'load':>7} {'blocks':>6} {'pays from':>13}")
        for name in names:
            row(name)


if __name__ == "__main__":
    main(sys.argv[1:])
