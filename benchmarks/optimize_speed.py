"""How fast the superoptimiser searches and proves (docs/optimize.md): sequences tested per
CPU-second (each one instruction run on the sample cases' machine states with the batched core's
handlers), whole routines run on the samples per CPU-second, and proofs per second (a proof: every
case of the space, or the spec's cases, on two runners), per spec, one process.

    PYTHONPATH=. python benchmarks/optimize_speed.py [--budget 10]

Beside each rate: the previous version's (commit d17bcd4, before the enumeration's reuse of one
machine per size, its vectorised bounds and its state keys without the bytes no instruction
writes), measured on the same machine in the same session with the same budget, and the ratio; the
last column sets the rate beside the prototype's the issue cites (450,000 candidates per
CPU-second): ratios, not targets the code is tested against.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from retro.optimize.optimizer import Options, optimize
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[1]
SPECS = ["examples/optimize/wasteful.toml", "examples/optimize/absdiff.toml", "examples/optimize/overlap8.toml",
         "asm/mul8.toml", "asm/aabb8.toml"]
PROTOTYPE_RATE = 450_000  # candidates per CPU-second, issue 27's prototype
# spec -> (sequences per CPU-second, proofs per second) of commit d17bcd4 (`--budget 10`, one process, the
# 2-core machine shared with seven other jobs; measured right after this version's run)
BEFORE = {"examples/optimize/wasteful.toml": (142_949, 64.4), "examples/optimize/absdiff.toml": (202_598, 68.1),
          "examples/optimize/overlap8.toml": (210_646, 78.3), "asm/mul8.toml": (96_365, 44.4),
          "asm/aabb8.toml": (258_864, 381.1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budget", type=float, default=10.0)
    args = parser.parse_args()
    print(f"{'spec':<34}{'cpu s':>7}{'sequences':>11}{'seq/cpu-s':>11}{'before':>10}{'ratio':>7}"
          f"{'routines/cpu-s':>16}{'proofs':>8}{'proofs/s':>10}{'before':>8}{'ratio':>7}{'vs prototype':>14}")
    for spec in SPECS:
        routine = load_spec(ROOT / spec)
        began = time.process_time()
        outcome = optimize(routine, Options(budget=args.budget))
        cpu = time.process_time() - began
        search_cpu = max(outcome.search_seconds, 1e-9)
        rate = outcome.tested / search_cpu
        proofs = outcome.proofs / max(outcome.prove_seconds, 1e-9)
        rate_before, proofs_before = BEFORE[spec]
        print(f"{spec:<34}{cpu:>7.1f}{outcome.tested:>11,}{rate:>11,.0f}{rate_before:>10,}{rate / rate_before:>6.2f}x"
              f"{outcome.routine_tests / cpu:>16,.1f}{outcome.proofs:>8}{proofs:>10,.1f}{proofs_before:>8,.1f}"
              f"{proofs / proofs_before:>6.2f}x{rate / PROTOTYPE_RATE:>13.3f}x")

if __name__ == "__main__":
    main()
