"""Whole checks' CPU, side by side with another checkout: per routine in one warm process, and the set in one.

Per routine: `check_routine(NAME, exhaustive=True, search_budget=0)` (what `retro check NAME --exhaustive
--no-search --jobs 1` runs), once to warm the process (imports, numba, the compiled code's load, the runners),
then best of --rounds, CPU seconds (time.process_time: the machine is shared). Then the issue's whole measure:
`python -m retro check SET... --exhaustive --no-search --jobs 1` in a fresh process, CPU seconds of the child
(getrusage: user + sys), best of --rounds. With `--against DIR` (a checkout of another commit, e.g. made with
`git archive COMMIT | tar -x -C DIR`) each figure is measured for both, in turns (this, that, this, ...), each in
its own process, and the ratio printed; the load average with each turn.

    python benchmarks/check_warm.py [ROUTINE ...] [--rounds N] [--turns N] [--against DIR] [--no-set]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

SET = ("aabb_edges", "aabb_sprite", "circle", "circle_r", "mul8", "pixel", "sprite_edges", "tile", "tile_box")
ROOT = Path(__file__).resolve().parents[1]


def warm(names: list[str], rounds: int) -> dict[str, float]:
    """Per routine, the best CPU seconds of a whole check after one to warm the process."""
    from retro.analysis.check.run import check_routine
    from retro.routines.registry import select

    best = {}
    for name, spec in zip(names, select(names)):
        check_routine(spec, exhaustive=True, search_budget=0)
        spent = []
        for _ in range(rounds):
            began = time.process_time()
            check_routine(spec, exhaustive=True, search_budget=0)
            spent.append(time.process_time() - began)
        best[name] = min(spent)
    return best


def _in(checkout: Path, arguments: list[str]) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(checkout)}
    return subprocess.run([sys.executable, *arguments], cwd=checkout, env=env, capture_output=True, text=True)


def warm_in(checkout: Path, names: list[str], rounds: int) -> dict[str, float]:
    done = _in(checkout, [str(Path(__file__).resolve()), *names, "--rounds", str(rounds), "--warm-only"])
    if done.returncode:
        raise SystemExit(f"{checkout}: {done.stderr.strip()[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def whole_set_in(checkout: Path) -> float:
    """CPU seconds (user + sys) of one `retro check SET... --exhaustive --no-search --jobs 1` process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = _in(checkout, ["-m", "retro", "check", *SET, "--exhaustive", "--no-search", "--jobs", "1", "--quiet"])
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        raise SystemExit(f"{checkout}: retro check exited {done.returncode}: {done.stderr.strip()[-2000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _load() -> str:
    return f"{os.getloadavg()[0]:.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("routines", nargs="*", default=["pixel", "circle", "circle_r", "tile_box"])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--turns", type=int, default=2)
    parser.add_argument("--against", type=Path)
    parser.add_argument("--no-set", action="store_true")
    parser.add_argument("--warm-only", action="store_true", help=argparse.SUPPRESS)  # (one turn, as JSON)
    args = parser.parse_args()
    if args.warm_only:
        print(json.dumps(warm(args.routines, args.rounds)))
        return
    checkouts = {"this": ROOT} | ({"that": args.against.resolve()} if args.against else {})
    best: dict[str, dict[str, float]] = {label: {} for label in checkouts}
    loads = []
    for _ in range(args.turns):
        for label, checkout in checkouts.items():
            loads.append(_load())
            for name, seconds in warm_in(checkout, args.routines, args.rounds).items():
                best[label][name] = min(best[label].get(name, seconds), seconds)
            if not args.no_set:
                seconds = whole_set_in(checkout)
                best[label]["(whole set, one process)"] = min(best[label].get("(whole set, one process)", seconds),
                                                              seconds)
    print(f"whole checks, CPU seconds, best of {args.rounds} rounds x {args.turns} turns; load at each turn: "
          f"{', '.join(loads)}")
    print(f"  {'routine':<26}" + "".join(f"{label:>10}" for label in checkouts) + ("   this/that" if args.against else ""))
    for name in best["this"]:
        row = f"  {name:<26}" + "".join(f"{best[label][name]:>10.3f}" for label in checkouts)
        if args.against:
            row += f"   {best['this'][name] / best['that'][name]:>9.2f}"
        print(row)


if __name__ == "__main__":
    main()
