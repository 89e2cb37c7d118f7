"""aabb8's exhaustive sweep (retro.routines.builtin_cases.aabb8_sweep) in a bounded slice, for any
routine with aabb8's conventions: the full 3 x 2^32 calls run with RETRO_EXHAUSTIVE=1 through
`retro check --exhaustive`; CI runs one block in `step` of two positions of box A."""

from __future__ import annotations

from itertools import islice

import numpy as np

from retro.cpu.compiled import numba_problem
from retro.routines import reference
from retro.routines.builtin_cases import aabb8_sweep
from retro.routines.runner import RoutineRunner

NAMES = "ax ay aw ah bx by bw bh".split()
SECTIONS = (("aw bw", "ax", "bx"), ("ah bh", "ay", "by"), ("ah bh", "ay", "by"))  # x, then y after each x way


def sweep_slice_mismatches(routine, starts, step: int) -> tuple[list, int]:
    """(the first mismatching case of each section that has one, calls run): the routine's blocks on
    the compiled engine (the batched core without numba) against the reference inside the domain
    (sizes >= 1), also checking each block is what the sweep promises."""
    runner = RoutineRunner(routine, routine.seed)
    run = runner.run_batch if numba_problem() else runner.run_compiled
    blocks = aabb8_sweep(starts)
    wrong_cases, seen = [], 0
    for section, (swept, position, other) in enumerate(SECTIONS):
        for k, block in enumerate(islice(blocks, len(starts) * 256)):
            if k % step:
                continue
            size, other_size = (block[name] for name in swept.split())
            assert len(size) == 1 << 16 and len(set((size * 256 + other_size).tolist())) == 1 << 16
            assert block[position][0] == starts[k // 256] and block[other][0] == k % 256
            columns = [block[name] for name in NAMES]
            outcome = run(columns)
            assert not outcome.error.any()
            expected = reference.aabb8(*columns).astype(np.int64)
            inside = np.logical_and.reduce([block[name] >= 1 for name in ("aw", "ah", "bw", "bh")])  # `where`
            wrong = np.flatnonzero((outcome.outputs[0] != expected) & inside)
            if len(wrong):
                wrong_cases.append((section, [int(c[wrong[0]]) for c in columns]))
            seen += len(size)
    assert next(blocks, None) is None
    return wrong_cases, seen
