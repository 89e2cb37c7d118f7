"""Stochastic rewriting (after STOKE, Schkufza, Sharma and Aiken, ASPLOS 2013): random moves on the
whole routine (replace an instruction, insert, delete, swap two neighbours, change an operand or a
branch's target), each move's result run on the samples, cost = mismatched sample cases x a weight
+ the objective's cycles (or bytes), moves accepted by the Metropolis rule; a rewrite with no
mismatch that beats the best is proven like any other candidate (retro.optimize.optimizer)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from retro.optimize.code import Instruction, Listing, assemble
from retro.optimize.effects import windowable

MISMATCH_WEIGHT = 100.0  # a wrong sample case costs as much as this many cycles
TEMPERATURE = 2.0
WALK_MOVES = 400  # moves of one walk (a work unit), from the best routine found so far


def _pick(rng: np.random.Generator, items: list):
    return items[int(rng.integers(len(items)))]


def _editable(listing: Listing) -> list[int]:
    """Indices of the instructions a move may change (those a window may hold)."""
    return [k for k, i in enumerate(listing.instructions) if windowable(i)]


def _replace_one(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    editable = _editable(listing)
    if not editable:
        return None
    k = _pick(rng, editable)
    return listing.with_window(k, k + 1, (_pick(rng, pool),))


def _insert(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    """Before any instruction but past the last (the routine's last instruction ends it)."""
    k = int(rng.integers(len(listing.instructions)))
    return listing.with_window(k, k, (_pick(rng, pool),))


def _delete(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    editable = _editable(listing)
    if not editable:
        return None
    k = _pick(rng, editable)
    return listing.with_window(k, k + 1, ())


def _swap_neighbours(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    instructions, editable = listing.instructions, _editable(listing)
    if len(editable) < 2:
        return None
    k = _pick(rng, editable)
    if k + 1 < len(instructions) and windowable(instructions[k + 1]):
        return listing.with_window(k, k + 2, (instructions[k + 1], instructions[k]))
    return None


def _other_operand(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    """The same operation on another operand of the pool."""
    editable = _editable(listing)
    if not editable:
        return None
    k = _pick(rng, editable)
    old = listing.instructions[k]
    same = [i for i in pool if i.mnemonic == old.mnemonic and i != old]
    return listing.with_window(k, k + 1, (_pick(rng, same),)) if same else None


def _other_target(listing: Listing, pool: list[Instruction], rng: np.random.Generator) -> Listing | None:
    """A branch's target moved to another label of the routine."""
    instructions = listing.instructions
    branches = [k for k, i in enumerate(instructions) if i.is_branch and isinstance(i.target, str)]
    names = [name for name, _ in listing.labels]
    if not branches or len(names) < 2:
        return None
    k = _pick(rng, branches)
    return listing.with_window(k, k + 1, (replace(instructions[k], target=_pick(rng, names)),))


MOVES = (_replace_one, _insert, _delete, _swap_neighbours, _other_operand, _other_target)


def walk(start: Listing, cost: Callable[[bytes], tuple | None], pool: list[Instruction], cpu: str,
         size_limit: int, moves: int, seed: int) -> tuple[list[Listing], int]:
    """`moves` Metropolis moves from `start` (one restart of the search; retro.optimize.units runs
    many). `cost(code)`: (mismatched sample cases, the objective's value) or None when the code
    cannot run. Returns the rewrites with no mismatch, each cheaper than every one before it (and
    than `start`), in the order found, and the moves tried: the caller proves them."""
    rng = np.random.default_rng(seed)

    def scalar(value: tuple) -> float:
        return MISMATCH_WEIGHT * value[0] + value[1]

    first = cost(assemble(start, cpu))
    if first is None:
        return [], 0
    current, current_cost = start, scalar(first)
    best_value = first[1] if first[0] == 0 else math.inf
    found: list[Listing] = []
    for _ in range(moves):
        proposal = _pick(rng, MOVES)(current, pool, rng)
        if proposal is None:
            continue
        code = assemble(proposal, cpu)
        if code is None or len(code) > size_limit:
            continue
        value = cost(code)
        if value is None:
            continue
        if value[0] == 0 and value[1] < best_value:
            best_value = value[1]
            found.append(proposal)
        total = scalar(value)
        if total <= current_cost or rng.random() < math.exp((current_cost - total) / TEMPERATURE):
            current, current_cost = proposal, total
    return found, moves
