"""The engine agreement's CPU: Machine with the timing model on the first 2,000 cases of each part.

Every check on the batched or compiled engine also runs the first AGREEMENT_PER_PART cases of each
part on Machine, each call timed again by the independent timing model, and compares both engines call
for call (`retro.analysis.check.run._agreement`). This prints, per routine of the set, the CPU seconds
(time.process_time, best of --rounds) of that agreement as `retro check NAME --exhaustive` runs it
(engine as `--engine auto` picks it), the total, and Machine's timed calls per CPU-second on those cases
(`RoutineRunner.run(case, timed=True)`), with a digest of every agreement tally: equal digests, the same
results.

`--against DIR`: the same measure of another checkout (a `git worktree` of an older commit), run in
turns with this one, each in its own process, and the ratio of the best totals (side by side in one
run on a shared machine).

    python benchmarks/agreement_speed.py [ROUTINE ...] [--rounds N] [--against DIR] [--turns N]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import time
from itertools import islice
from pathlib import Path

SET = ("aabb_edges", "aabb_sprite", "circle", "circle_r", "mul8", "pixel", "sprite_edges", "tile", "tile_box")


def measure(names: list[str], rounds: int) -> dict:
    """Per routine, the agreement's best CPU seconds; the total; Machine's timed calls per CPU-second; a
    digest of the tallies."""
    from retro.analysis.check import run as check_run
    from retro.cpu.timing import model_cycles
    from retro.analysis.check.engines import AGREEMENT_PER_PART, runner_for
    from retro.routines import cases as case_sets
    from retro.routines.registry import select

    plans = []
    for spec in select(names):
        plan = check_run._planned(spec, True, None, None, case_sets.BOUNDED_PRODUCT)
        runner = runner_for(plan.spec, plan.seed, None)
        plans.append((plan, runner, check_run._engine_choice(plan, runner, "auto", None)))
    best: dict[str, float] = {}
    tallies: dict[str, str] = {}
    for _ in range(rounds):
        for plan, _, choice in plans:
            began = time.process_time()
            tally = check_run._agreement(plan.spec, plan.seed, plan.parts, choice.used, None)
            spent = time.process_time() - began
            best[plan.routine.name] = min(best.get(plan.routine.name, spent), spent)
            tallies[plan.routine.name] = repr(sorted(vars(tally).items()))
    calls, seconds = 0, 0.0
    for plan, runner, _ in plans:
        cases = [case for part in plan.parts for case in islice(part.cases, AGREEMENT_PER_PART)]
        timed = _takes_timed(runner)
        read, cpu = runner.machine.memory.__getitem__, plan.routine.cpu
        began = time.process_time()
        for case in cases:
            if timed:
                runner.run(case, None, timed=True)
            else:  # an older checkout: the path recorded, then walked by the model
                steps: list = []
                runner.run(case, steps)
                model_cycles(read, steps, cpu)
        seconds += time.process_time() - began
        calls += len(cases)
    return {"seconds": best, "total": sum(best.values()), "calls_per_second": calls / seconds,
            "digest": hashlib.sha1(repr(sorted(tallies.items())).encode()).hexdigest()[:12]}


def _takes_timed(runner) -> bool:
    import inspect

    return "timed" in inspect.signature(runner.run).parameters  # (an older checkout records the path)


def _in_process(directory: Path, names: list[str], rounds: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(directory)}
    done = subprocess.run([sys.executable, str(Path(__file__).resolve()), *names, "--rounds", str(rounds),
                           "--json"], cwd=directory, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", default=list(SET))
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--against", type=Path, help="another checkout, measured in turns with this one")
    parser.add_argument("--turns", type=int, default=2)
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.json:
        print(json.dumps(measure(args.names, args.rounds)))
        return
    here = Path(__file__).resolve().parents[1]
    checkouts = {"this": here} if args.against is None else {"against": args.against.resolve(), "this": here}
    results: dict[str, list[dict]] = {name: [] for name in checkouts}
    for _ in range(args.turns if args.against is not None else 1):
        for name, directory in checkouts.items():
            results[name].append(_in_process(directory, args.names, args.rounds))
    print(f"engine agreement, CPU seconds (best of {args.rounds} rounds, {args.turns if args.against else 1} "
          f"turn(s)), load {os.getloadavg()[0]:.1f}")
    best = {name: min(runs, key=lambda r: r["total"]) for name, runs in results.items()}
    print(f"  {'routine':<14}" + "".join(f"{name:>10}" for name in best))
    for routine in best["this"]["seconds"]:
        print(f"  {routine:<14}" + "".join(f"{best[name]['seconds'][routine]:10.3f}" for name in best))
    print(f"  {'total':<14}" + "".join(f"{best[name]['total']:10.3f}" for name in best))
    print(f"  {'calls/CPU-s':<14}" + "".join(f"{max(r['calls_per_second'] for r in results[name]):10,.0f}"
                                             for name in best) + "  (Machine, timed by the model)")
    print(f"  {'digest':<14}" + "".join(f"{best[name]['digest']:>13}" for name in best))
    if args.against is not None:
        print(f"ratio this / against: {best['this']['total'] / best['against']['total']:.2f}x the CPU "
              f"({1 - best['this']['total'] / best['against']['total']:.0%} less); calls per CPU-s "
              f"{max(r['calls_per_second'] for r in results['this']) / max(r['calls_per_second'] for r in results['against']):.2f}x")


if __name__ == "__main__":
    main()
