"""The compiled engine against the batched core and Machine, side by side in one run (issue 24's figures).

For each routine: calls per CPU-second (time.process_time: the machine is shared, wall time would
measure the neighbours) of Machine (`RoutineRunner.run`), the batched core (`run_batch`, 65,536 lanes)
and the compiled engine (`run_compiled`, the same 65,536 cases, calls it leaves to the batched core
included), on the routine's own random cases (its spec's generator: half of them near the answer's
edge: the branches go either way at random, the compiled engine's worst case); then the batched core
and the compiled engine on the first SWEEP_BLOCKS blocks of the routine's `--exhaustive` cases (its
exhaustive product, else its sweep: what a proof runs, the issue's measure); the ratios; and apart,
the compiled engine's compile time (CPU seconds of a fresh process's first compile into an empty
cache, numba's import and start included: a cold compile, whatever routines the run measured before)
and its load time from the cache, and from how many calls the compile pays for itself against the
batched core.

With `--checks`: whole checks instead, `retro check NAME --exhaustive --no-search --jobs 1 --json` in a
fresh process per routine and engine (start-up, compile or cache load, the engine agreement on Machine,
the entry-state reruns, the tally and the reference included: what a user waits for), CPU seconds of
the process (getrusage of the child) on the batched core (`--engine batch`: today's engine) and on the
compiled engine (its cache filled first: the compile is counted apart above), with the ratio per
routine and for the whole set. aabb8's full sweep (3 x 2^32 calls) is too long to run twice here: its
row is the same check with box A's position from the first AABB8_STARTS values only
(benchmarks/aabb8_sweep.py's slice; 3 x 2^24 calls per value). Then the issue's own measure: the whole
set (every routine named but aabb8, whose work changed since the issue was filed) checked in ONE process,
`retro check NAME... --exhaustive --no-search --jobs 1`, on `--engine batch` and on `--engine auto`, CPU
seconds of the process and its children, best of SET_ROUNDS runs each, and the ratio (`--set`: that
figure alone).

With `--auto`: the figures `--engine auto`'s rule between the batched core and the compiled engine is
set from (retro.analysis.check.engines): CPU ns per 6502 cycle of each routine's calls on both engines,
the compiled engine's start in a fresh process, the crossover they give against the rule's, and where
each routine's --exhaustive check falls.

    python benchmarks/compiled_speed.py [ROUTINE ...] [--checks | --set | --auto]
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from itertools import islice

import numpy as np

from retro.cpu import compiled as compiled_module
from retro.cpu.compiled import numba_problem
from retro.routines import cases as case_sets
from retro.routines.registry import get
from retro.routines.runner import RoutineRunner

LANES = 65_536
SCALAR_CASES = 2_000
MIN_SECONDS = 0.5
ROUTINES = ["aabb8", "mul8", "circle", "tile", "tile_box", "pixel", "aabb_sprite", "aabb_edges", "circle_r",
            "sprite_edges", "mul16"]
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
    try:
        cold = _fresh_start(name)  # the cache is empty: a cold compile, in a fresh process as a user's first check
    except subprocess.CalledProcessError as exc:
        print(f"{name:<13} {machine:>10,.0f} {batch:>12,.0f}  not compiled: {exc.stderr.strip().splitlines()[-1]}")
        return
    for _ in range(2):  # (the first load in this process also starts numba's CPU target: timed the second)
        compiled_module._LOADED.clear()
        runner._compiled = None
        began = time.process_time()
        compiled = runner.compiled()
        load = time.process_time() - began
    assert compiled.from_cache
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


ROOT = Path(__file__).resolve().parent.parent
CHECK_ROUTINES = ["aabb8", "aabb_edges", "aabb_sprite", "circle", "circle_r", "mul8", "pixel", "sprite_edges",
                  "tile", "tile_box"]  # every built-in with an --exhaustive run of its own (the prepare steps aside)
AABB8_STARTS = 1
OWN_KEYS = {"code_coverage"}  # the compiled engine counts no code coverage (docs/compiled.md)


def _child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def whole_check(target: str, engine: str) -> tuple[float, dict]:
    """CPU seconds of `retro check TARGET --exhaustive` on `engine` in a fresh process, and its record."""
    before = _child_cpu()
    done = subprocess.run([sys.executable, "-m", "retro", "check", target, "--exhaustive", "--no-search", "--jobs", "1",
                           "--engine", engine, "--json"], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    spent = _child_cpu() - before
    if done.returncode not in (0, 1) or not done.stdout.strip():
        sys.exit(f"compiled_speed: retro check {target} --engine {engine} failed: {done.stderr.strip()[-300:]}")
    return spent, json.loads(done.stdout)[0]


def whole_checks(names: list[str]) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from aabb8_sweep import sliced_spec

    print("whole checks (--exhaustive --no-search --jobs 1), CPU seconds of the process; the compiled engine's "
          "cache filled first")
    print(f"{'routine':<24} {'calls':>15} {'batch (s)':>10} {'compiled (s)':>13} {'ratio':>7}  engine, fallbacks")
    totals = [0.0, 0.0]
    with tempfile.TemporaryDirectory() as folder:
        for name in names:
            target, label = name, name
            if name == "aabb8":
                target = str(sliced_spec(Path(folder), AABB8_STARTS))
                label = f"aabb8 (slice, {AABB8_STARTS}/256)"
            whole_check(target, "compiled")  # fills the cache: the compile is not the check's
            batch, slow = whole_check(target, "batch")
            fast, record = whole_check(target, "compiled")
            differ = sorted(k for k in set(slow) | set(record) if not k.startswith(("engine", "compile"))
                            and k not in OWN_KEYS and slow.get(k) != record.get(k))
            totals[0] += batch
            totals[1] += fast
            print(f"{label:<24} {record['cases']:>15,} {batch:>10.1f} {fast:>13.1f} {batch / fast:>6.1f}x  "
                  f"{record.get('engine')}, {record.get('compiled_fallbacks') or 0}"
                  f"{'' if not differ else '  records differ: ' + ', '.join(differ)}")
    print(f"{'all':<24} {'':>15} {totals[0]:>10.1f} {totals[1]:>13.1f} {totals[0] / totals[1]:>6.1f}x  "
          "(one process per routine)")
    one_process([n for n in names if n != "aabb8"])


SET_ROUNDS = 2
ISSUE_SET = [n for n in CHECK_ROUTINES if n != "aabb8"]  # issue 24's set: every built-in with an --exhaustive run
ISSUE_FIGURES = {"64be42f (batched only)": 35.9}  # ... its CPU s where the issue was filed (quiet machine)


def one_process(names: list[str]) -> None:
    """The set in one process (issue 24's measure), `--engine batch` and `--engine auto`, best of SET_ROUNDS."""
    if not names:
        return
    spent = {}
    for engine in ("batch", "auto"):
        rounds = []
        for _ in range(SET_ROUNDS):
            before = _child_cpu()
            done = subprocess.run([sys.executable, "-m", "retro", "check", *names, "--exhaustive", "--no-search",
                                   "--jobs", "1", "--engine", engine, "--json"], capture_output=True, text=True,
                                  env={**os.environ, "PYTHONPATH": str(ROOT)})
            rounds.append(_child_cpu() - before)
            if done.returncode not in (0, 1) or not done.stdout.strip():
                sys.exit(f"compiled_speed: retro check --engine {engine} failed: {done.stderr.strip()[-300:]}")
        spent[engine] = min(rounds)
    load = os.getloadavg()[0]
    print(f"one process, {' '.join(names)} (--exhaustive --no-search --jobs 1), CPU s, best of {SET_ROUNDS}, "
          f"load {load:.1f}: batch {spent['batch']:.1f}, auto {spent['auto']:.1f} "
          f"({spent['batch'] / spent['auto']:.1f}x)"
          + "".join(f"; {where}: {seconds:.1f} ({seconds / spent['auto']:.1f}x, issue 24: at least 4x)"
                    for where, seconds in ISSUE_FIGURES.items() if names == ISSUE_SET))


AUTO_ROUTINES = ["aabb8", "aabb_edges", "aabb_sprite", "circle", "circle_r", "mul8", "sprite_edges", "tile",
                 "tile_box", "mul16"]
START_SCRIPT = """
import resource, sys, time
import retro.cli
from retro.routines.registry import get
from retro.routines.runner import RoutineRunner
routine = get(sys.argv[1])
runner = RoutineRunner(routine, routine.seed)
began = time.process_time()
runner.compiled()
print(time.process_time() - began)
"""


def _fresh_start(name: str) -> float:
    """CPU seconds of a fresh process's first load of `name`'s compiled code from the cache (numba's import
    and start included: what a check on the compiled engine pays before its first call), or of its
    compile when the cache does not hold it."""
    done = subprocess.run([sys.executable, "-c", START_SCRIPT, name], capture_output=True, text=True, check=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    return float(done.stdout.split()[-1])


def auto_rule(names: list[str]) -> None:
    """The figures `--engine auto`'s rule is set from (retro.analysis.check.engines): per routine, CPU ns per
    6502 cycle of its calls on the batched core and on the compiled engine (its --exhaustive cases' first
    blocks and its random cases), the compiled engine's start in a fresh process, the crossover they give,
    and the planned cycles of each routine's --exhaustive check against it."""
    from retro.analysis.check import engines
    from retro.analysis.check.run import _planned, _static
    from retro.routines.registry import spec_path

    print("CPU ns per 6502 cycle of the calls (mean cycles per call from the run); start: a fresh process's first "
          "load from the cache, numba's import and start included (CPU s)")
    print(f"{'routine':<13} {'cycles':>8} {'batch':>8} {'compiled':>9} {'saved':>7} {'start':>7} "
          f"{'planned (M cycles)':>19}  auto")
    batches, fasts, starts = [], [], []
    for name in names:
        routine = get(name)
        runner = RoutineRunner(routine, routine.seed)
        runner.compiled()  # (into the cache: the start below loads it)
        blocks = sweep_blocks(routine, LANES) + [random_block(routine, LANES)]
        cycles = sum(int(runner.run_batch(b).cycles.sum()) for b in blocks)
        batch = 1e9 / per_cpu_second(_each(runner.run_batch, blocks), cycles)
        fast = 1e9 / per_cpu_second(_each(runner.run_compiled, blocks), cycles)
        start = _fresh_start(name)
        batches.append(batch)
        fasts.append(fast)
        starts.append(start)
        plan = _planned(str(spec_path(name)), True, None, None, case_sets.BOUNDED_PRODUCT)
        planned = engines.planned_cycles(runner, plan.parts, _static(plan, runner))
        calls = sum(len(b[0]) for b in blocks)
        print(f"{name:<13} {cycles / calls:>8.1f} {batch:>8.2f} {fast:>9.2f} {batch - fast:>7.2f} {start:>7.2f} "
              f"{'(a sweep)' if planned is None else f'{planned / 1e6:,.0f}':>19}  "
              f"{engines.array_engine('auto', plan.calls, planned)[0]}")
    batch, fast, start = (float(np.median(figures)) for figures in (batches, fasts, starts))
    print(f"median: batch {batch:.2f} ns, compiled {fast:.2f} ns a cycle, {start:.2f} s to start: the compiled "
          f"engine pays from {start / (batch - fast) * 1e3:,.0f} M cycles; the rule's constants "
          f"(retro.analysis.check.engines): {engines.BATCH_NS_PER_CYCLE} and {engines.COMPILED_NS_PER_CYCLE} ns, "
          f"{engines.COMPILED_START_SECONDS} s: AUTO_COMPILED_CYCLES {engines.AUTO_COMPILED_CYCLES / 1e6:,.0f} M")


def main(argv: list[str]) -> None:
    problem = numba_problem()
    if problem:
        sys.exit(f"compiled_speed: {problem}")
    import numba

    names = [a for a in argv if not a.startswith("--")]
    if "--checks" in argv:
        whole_checks(names or CHECK_ROUTINES)
        return
    if "--set" in argv:  # the one-process figure alone
        one_process([n for n in names or CHECK_ROUTINES if n != "aabb8"])
        return
    if "--auto" in argv:
        auto_rule(names or AUTO_ROUTINES)
        return
    names = names or ROUTINES
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
