"""Stochastic rewriting (after STOKE, Schkufza, Sharma and Aiken, ASPLOS 2013): random moves on the
whole routine (replace an instruction, insert, delete, swap two neighbours, change an operand or a
branch's target), each move's result run on the samples, cost = mismatched sample cases x a weight
+ the objective's cycles (or bytes), moves accepted by the Metropolis rule; a rewrite with no
mismatch that beats the best is proven like any other candidate (retro.optimize.optimizer)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from retro.optimize.code import Instruction, Listing, assemble
from retro.optimize.effects import windowable

MISMATCH_WEIGHT = 100.0  # a wrong sample case costs as much as this many cycles
TEMPERATURE = 2.0
RESTART_EVERY = 400  # moves from the best routine found so far


def moves(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    """One random move; None when it does not apply (the caller draws again)."""
    instructions = listing.instructions
    editable = [k for k, i in enumerate(instructions) if windowable(i)]
    kind = int(rng.integers(6))
    if kind == 0 and editable:  # replace
        k = editable[int(rng.integers(len(editable)))]
        return listing.with_window(k, k + 1, (pool[int(rng.integers(len(pool)))],))
    if kind == 1:  # insert before any instruction but past the last
        k = int(rng.integers(len(instructions)))
        return listing.with_window(k, k, (pool[int(rng.integers(len(pool)))],))
    if kind == 2 and editable:  # delete
        k = editable[int(rng.integers(len(editable)))]
        return listing.with_window(k, k + 1, ())
    if kind == 3 and len(editable) > 1:  # swap two neighbours
        k = editable[int(rng.integers(len(editable)))]
        if k + 1 < len(instructions) and windowable(instructions[k + 1]):
            return listing.with_window(k, k + 2, (instructions[k + 1], instructions[k]))
        return None
    if kind == 4 and editable:  # operand: the same operation on another operand of the pool
        k = editable[int(rng.integers(len(editable)))]
        same = [i for i in pool if i.mnemonic == instructions[k].mnemonic and i != instructions[k]]
        return listing.with_window(k, k + 1, (same[int(rng.integers(len(same)))],)) if same else None
    if kind == 5:  # a branch's target: another label of the routine
        branches = [k for k, i in enumerate(instructions) if i.is_branch and isinstance(i.target, str)]
        names = [name for name, _ in listing.labels]
        if branches and len(names) > 1:
            k = branches[int(rng.integers(len(branches)))]
            target = names[int(rng.integers(len(names)))]
            return listing.with_window(k, k + 1, (replace(instructions[k], target=target),))
    return None


def rewrite(start: Listing, cost: Callable[[bytes], tuple | None], pool: list[Instruction], cpu: str,
            size_limit: int, deadline: float, seed: int, found: Callable[[Listing, bytes], bool]) -> int:
    """Metropolis search from `start` until `deadline`. `cost(code)`: (mismatched sample cases, the
    objective's value) or None when the code cannot run; `found(listing, code)` is told of every
    rewrite with no mismatch cheaper than the best so far (it proves it and says whether it was
    kept). Returns the moves tried."""
    rng = np.random.default_rng(seed)

    def scalar(value: tuple) -> float:
        return MISMATCH_WEIGHT * value[0] + value[1]

    first = cost(assemble(start, cpu))
    if first is None:
        return 0
    current, current_cost = start, scalar(first)
    best, best_value = start, first[1]
    tried = 0
    while time.monotonic() < deadline:
        tried += 1
        if tried % RESTART_EVERY == 0:
            current, current_cost = best, scalar((0, best_value))
        proposal = moves(current, pool, rng)
        if proposal is None:
            continue
        code = assemble(proposal, cpu)
        if code is None or len(code) > size_limit:
            continue
        value = cost(code)
        if value is None:
            continue
        if value[0] == 0 and value[1] < best_value and found(proposal, code):
            best, best_value = proposal, value[1]
        total = scalar(value)
        if total <= current_cost or rng.random() < math.exp((current_cost - total) / TEMPERATURE):
            current, current_cost = proposal, total
    return tried
