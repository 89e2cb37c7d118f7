"""The search's work units (retro.optimize.units) through retro.workers.run_in_order: the same result
for a seed on one worker (this process) and on two Dask workers."""

from __future__ import annotations

from pathlib import Path

import pytest

from retro.optimize.optimizer import Options, Search, optimize
from retro.optimize.units import run_walk
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[2]


def _summary(outcome):
    return ([(c.kind, c.start, c.removed, c.added) for c in outcome.changes], outcome.best.instructions,
            outcome.best_proof.cycles, outcome.tested, outcome.complete)


@pytest.mark.parametrize("spec", ["tests/optimize/wasteful/join.toml", "examples/optimize/wasteful.toml"])
def test_one_worker_and_two_give_the_same_search(spec):
    """Every window's enumeration finishes well inside the budget, so nothing depends on timing: the
    windows, their candidates, the proofs and the result are the same on 1 and on 2 workers."""
    routine = load_spec(ROOT / spec)
    options = Options(budget=120, synthesis=False, stochastic=False, window=2, seed=11)
    alone = optimize(routine, options)
    shared = optimize(routine, Options(**{**options.__dict__, "jobs": 2}))
    assert alone.complete and alone.changes
    assert _summary(alone) == _summary(shared)


def test_a_walk_depends_only_on_its_arguments():
    search = Search(load_spec(ROOT / "examples/optimize/wasteful.toml"), Options(seed=3))
    context = search.context()
    first = run_walk(context, search.listing, 200, search.size, 17, 300)
    again = run_walk(context, search.listing, 200, search.size, 17, 300)
    other = run_walk(context, search.listing, 200, search.size, 18, 300)
    assert first.tried == 300 and first.runs > 0
    assert [c.instructions for c in first.candidates] == [c.instructions for c in again.candidates]
    assert first.runs == again.runs and (first.runs, first.candidates) != (other.runs, other.candidates)


def test_a_context_crosses_a_pipe_without_its_routine():
    import pickle
    search = Search(load_spec(ROOT / "examples/optimize/wasteful.toml"), Options(seed=3))
    context = pickle.loads(pickle.dumps(search.context()))
    assert context.routine is None and context.the_routine().name == "wasteful"
