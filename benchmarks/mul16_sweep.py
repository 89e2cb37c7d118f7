"""mul16 over all 2^32 inputs (`retro check mul16 --exhaustive`): a slice of the sweep measured, the
whole extrapolated; or, with --full, the whole check run and measured (issue 24 part 3: a 16x16-bit
multiply's 2^32 inputs "well under an hour"; at most 1 GiB of RSS per worker).

The slice is the same sweep with a taken from its first K values instead of all 65,536 (K x 2^16
calls: K = 1024 is 2^26), run by `retro check --exhaustive --engine ENGINE --jobs J --no-search` on a
copy of the spec. Printed: wall and CPU seconds of the whole process tree (the workers included,
sampled from /proc), calls per CPU-second, the largest RSS of any one process of the tree, and the
full sweep's time on J cores extrapolated from the slice's rate (the boundary and random cases and
the start-up are in the slice's time: the extrapolation is on the safe side).

    python benchmarks/mul16_sweep.py [K] [--jobs J] [--engine compiled|batch]
    python benchmarks/mul16_sweep.py --full [--jobs J]    # `retro check mul16 --exhaustive --jobs J`, its report
                                                          # printed (minutes: see the slice first)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

from peak_memory import sampled_run, spec_with_sweep  # benchmarks/: the script's own folder

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "asm" / "mul16.toml"
WORD = 1 << 16
FULL_CALLS = WORD * WORD
GOAL_RSS = 1 << 30  # per worker


def sliced_spec(folder: Path, first_a: int) -> Path:
    """A copy of mul16's spec whose sweep takes a from 0..first_a-1 (every b for each)."""
    return spec_with_sweep(SPEC, folder, "from retro.routines.grid import Grid\n\n\n"
                                         f"def sweep():\n    return Grid({{'a': {first_a}, 'b': {WORD}}})\n")


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("first_a", nargs="?", type=int, default=1024, help="values of a swept (of 65,536)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--engine", default="auto")
    parser.add_argument("--full", action="store_true", help="the whole 2^32 sweep of asm/mul16.toml")
    args = parser.parse_args(argv)
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as folder:
        spec = SPEC if args.full else sliced_spec(Path(folder), args.first_a)
        run = sampled_run([sys.executable, "-m", "retro", "check", "mul16" if args.full else str(spec), "--exhaustive",
                           "--engine", args.engine, "--jobs", str(args.jobs)]
                          + (["--json", "--no-search"] if not args.full else []))
    if args.full:  # the command as a user runs it: its report printed as it is
        print(run.stdout.rstrip())
        record = {"cases": int(run.stdout.split(" cases,")[0].rsplit(" ", 1)[-1]) if " cases," in run.stdout else 0}
    else:
        record = json.loads(run.stdout)[0] if run.stdout.strip() else {}
    calls = record.get("cases", 0)
    swept = FULL_CALLS if args.full else args.first_a * WORD
    rate = calls / run.cpu if run.cpu else 0.0
    said = "" if args.full else (f", mismatches {record.get('mismatches', '?')}, engine {record.get('engine', '?')} "
                                 f"({record.get('engine_reason', '')})")  # (the full run's report says them above)
    print(f"mul16 {'full sweep' if args.full else f'slice: a from {args.first_a} of 65,536 values'}: {swept:,} sweep "
          f"calls, {calls:,} calls in all, exit {run.returncode}{said}")
    print(f"  --engine {args.engine} --jobs {args.jobs}: {run.wall:.1f} s wall, {run.cpu:.1f} CPU s, "
          f"{rate / 1e6:.2f} M calls per CPU-second; largest process RSS {run.peak / 2**20:.0f} MiB "
          f"(goal: under {GOAL_RSS >> 20} MiB per worker), whole tree {run.peak_tree / 2**20:.0f} MiB; "
          f"load before {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}, after {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    if not args.full and rate:
        full_cpu = FULL_CALLS / rate
        print(f"  the full sweep (2^32 calls) at that rate: {full_cpu:,.0f} CPU s, about "
              f"{full_cpu / args.jobs / 60:.1f} min on {args.jobs} cores")


if __name__ == "__main__":
    main(sys.argv[1:])
