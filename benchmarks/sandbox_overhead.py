"""What the guards of retro.routines.sandbox cost per call of a user's function.

A scalar reference is called once per case; an array reference once per block of up to 65,536
cases (the batched core's lanes). The guard's cost is fixed per call (a timer armed and disarmed,
the address-space limit set and restored, the watchdog armed), so it matters for scalar references.
Printed: microseconds per call bare and guarded, the ratio, and the share of a block of 65,536 cases
for an array reference of realistic size.

    PYTHONPATH=. python benchmarks/sandbox_overhead.py

Measured on the development machine (2 shared cores): aabb8 case by case 18 us bare, 27 us guarded
(+9 us: two interval timers armed and disarmed, RLIMIT_AS set and restored, /proc/self/statm read at
most once a second); an array reference on 65,536 cases +1% (within noise). A whole check,
`retro check tests/data/specs/boxhit_acme.toml --random 200000 --engine batch --jobs 1` (265,536 cases,
its reference called case by case): 20.0 and 22.3 s at 64be42f, 22.0 and 22.6 s guarded.
"""

from __future__ import annotations

import time

import numpy as np

from retro.routines.reference import aabb8
from retro.routines.sandbox import guarded

CALLS = 20_000
LANES = 65_536


def per_call(function, arguments: dict, calls: int) -> float:
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(calls):
            function(**arguments)
        best = min(best, (time.perf_counter() - start) / calls)
    return best * 1e6


def main() -> None:
    scalar = dict(ax=10, ay=20, aw=8, ah=8, bx=14, by=22, bw=8, bh=8)
    bare = per_call(aabb8, scalar, CALLS)
    safe = per_call(guarded(aabb8, "bench:boxhit"), scalar, CALLS)
    print(f"scalar reference (aabb8, one case):  bare {bare:7.2f} us  guarded {safe:7.2f} us  "
          f"overhead {safe - bare:6.2f} us per call ({safe / bare:.1f}x)")
    rng = np.random.default_rng(1)
    arrays = {k: rng.integers(0, 256, LANES) for k in scalar}
    bare = per_call(aabb8, arrays, 50)
    safe = per_call(guarded(aabb8, "bench:boxhit"), arrays, 50)
    print(f"array reference (aabb8, {LANES:,} cases): bare {bare:9.1f} us  guarded {safe:9.1f} us  "
          f"overhead {(safe - bare) / bare:+.2%} of the call")


if __name__ == "__main__":
    main()
