"""The search's work units: one window's enumeration (retro.optimize.search) and one stochastic walk
(retro.optimize.stochastic), plain functions of a picklable context. The optimiser runs them through
retro.workers.run_in_order, the engine the check's sweeps use: in its own process by default, as
Dask tasks on local worker processes (`--jobs N`) or on a cluster (`--scheduler ADDRESS`). A unit's
result depends only on its arguments (the samples, the listing, the seed), never on which worker ran
it or how many there are; the proofs, and the choice of what is kept, happen in the calling
process in task order. So a run is the same for a seed on one worker or many, up to where a time
limit cuts an enumeration or the budget ends the run.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from retro.cpu.batch import LaneError
from retro.optimize.code import Instruction, Listing, assemble
from retro.optimize.effects import live_after
from retro.optimize.evaluate import LaneRunner, Samples, outputs_equal
from retro.optimize.search import (BRANCHES, BRK, END, FLAG_BITS, Executor, cycles_of, enumerate_window,
                                   instruction_pool, rank, state_of, state_ports)
from retro.optimize.stochastic import walk
from retro.routines.places import Port
from retro.routines.spec import Routine, load_spec

SYNTHESIS_LANES = 64  # sample cases the synthesis enumerates on (it searches deeper, on more states)
_ROUTINES: dict[str, Routine] = {}  # spec path -> the routine, loaded once per worker process


@dataclass
class SearchContext:
    """What every unit of one search shares: the routine (by its spec's path: a worker loads it
    once), the seed, the samples and what the search tracks. The routine object itself never
    crosses a pipe."""

    spec: str
    seed: int
    objective: str
    scratch: tuple[int, ...]
    addresses: tuple[int, ...]
    at_return: frozenset
    preserve: tuple[Port, ...]
    samples: Samples
    kept: list | None = None  # the original's preserved outputs on the samples
    routine: Routine | None = field(default=None, compare=False, repr=False)
    table_pool: tuple[Instruction, ...] = ()  # reads of the [memory] tables the user allows (retro.optimize.tables)

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["routine"] = None
        return state

    def the_routine(self) -> Routine:
        if self.routine is None:
            if self.spec not in _ROUTINES:
                _ROUTINES.clear()
                _ROUTINES[self.spec] = load_spec(self.spec)
            self.routine = _ROUTINES[self.spec]
        return self.routine


@dataclass
class WindowResult:
    """One window's enumeration: the window as it ran (branches to its join as branches to END),
    what is live after it, the sequences that reach its end state (best first), the count."""

    start: int
    stop: int
    kind: str
    window: tuple[Instruction, ...] = ()
    live: frozenset = frozenset()
    found: list = field(default_factory=list)
    tested: int = 0
    complete: bool = True
    cpu_seconds: float = 0.0


def window_states(context: SearchContext, code: bytes, start_address: int):
    """The machine state where the routine reaches `start_address`, per sample case that does:
    (state, lanes, probe runner) from a run with BRK there (the tracked addresses read as outputs)."""
    routine = context.the_routine()
    probe = replace(routine, outputs=state_ports(context.addresses))
    runner = LaneRunner(probe, context.seed, context.scratch)
    patched = bytearray(code)
    patched[start_address - routine.entry_address] = BRK
    s = context.samples
    outcome = runner.run(bytes(patched), routine.entry_address, s.columns, s.indices, s.pinned)
    lanes = np.flatnonzero(outcome.error == LaneError.BRK)
    return state_of(outcome.outputs, context.addresses, lanes), lanes, runner


def synthesis_target(context: SearchContext, state, lanes):
    """The state the whole routine must end in: the reference's answers in the output places (and
    the preserved registers and flags as the original leaves them)."""
    routine = context.the_routine()
    target = type(state)(state.a.copy(), state.x.copy(), state.y.copy(), state.p.copy(), dict(state.memory))
    live = set()
    for port, expected in zip(routine.outputs, context.samples.expected):
        values = expected[lanes]
        for k, place in enumerate(port.places):
            byte = (values[:, k] if port.table else (values >> (8 * k)) & 0xFF).astype(np.int32)
            if place.kind == "register":
                setattr(target, place.register, byte)
                live.add(place.register.upper())
            elif place.kind == "flag":
                target.p = np.where(values != 0, target.p | place.bit, target.p & ~place.bit).astype(np.int32)
                live.add(next(n for n, b in FLAG_BITS.items() if b == place.bit))
            elif place.kind == "memory":
                target.memory[place.address] = byte
                live.add(place.address)
    for port, kept in zip(context.preserve, context.kept or ()):
        place = port.places[0]
        if place.kind == "register":
            setattr(target, place.register, np.asarray(kept[lanes], dtype=np.int32))
            live.add(place.register.upper())
        else:
            target.p = np.where(kept[lanes] != 0, target.p | place.bit, target.p & ~place.bit).astype(np.int32)
            live.add(next(n for n, b in FLAG_BITS.items() if b == place.bit))
    return target, frozenset(live)


def _first_lanes(state, lanes: np.ndarray, count: int):
    """The state on its first `count` sample cases only (synthesis enumerates on fewer cases; the
    whole-routine run and the proof see them all)."""
    if len(lanes) <= count:
        return state, lanes
    return (type(state)(state.a[:count], state.x[:count], state.y[:count], state.p[:count],
                        {a: v[:count] for a, v in state.memory.items()}), lanes[:count])


def run_window(context: SearchContext, listing: Listing, start: int, stop: int, kind: str, seconds: float,
               best_cycles: tuple[float, float], length: int) -> WindowResult:
    """Enumerate one window (or, kind "synthesis", the whole body of a short routine) for at most
    `seconds`: the sequences of up to `length` instructions that reach the window's end state on
    what is live (synthesis: the reference's answers) within its cost (`best_cycles`: the best
    routine's worst and mean, which bound a synthesised body)."""
    began = time.process_time()
    routine = context.the_routine()
    cpu, objective = routine.cpu, context.objective
    result = WindowResult(start, stop, kind)
    addresses = [listing.origin]
    for i in listing.instructions:
        addresses.append(addresses[-1] + i.length)
    state, lanes, probe = window_states(context, assemble(listing, cpu), addresses[start])
    if not len(lanes):
        return result
    window = listing.instructions[start:stop]
    executor = Executor(cpu, bytes(probe.runner.call_image), len(lanes), addresses[start])
    pool = instruction_pool(cpu, listing, window, context.addresses) + list(context.table_pool)
    if kind == "synthesis":
        state, lanes = _first_lanes(state, lanes, SYNTHESIS_LANES)
        target, live = synthesis_target(context, state, lanes)
        rts = cycles_of(cpu, listing.instructions[-1])
        worst_cycles, mean_cycles = best_cycles[0] - rts, best_cycles[1] - rts
        size = addresses[stop] - addresses[start]
        bound = {"worst": (worst_cycles, size + 1), "mean": (mean_cycles, size + 1),
                 "bytes": (size, worst_cycles + 1)}[objective]
        pool = [i for i in pool if i.mode != "rel"] + [Instruction(b, "rel", target=END) for b in BRANCHES]
    else:
        window = tuple(replace(i, target=END) if i.is_branch else i for i in window)  # branches to the join
        if any(i.is_branch for i in window):
            pool = [i for i in pool if not i.is_branch] + [Instruction(b, "rel", target=END) for b in BRANCHES]
        target = state
        for instruction in window:
            target = executor.step(target, instruction)
        live = live_after(listing, context.at_return)[stop - 1]
        bound = rank(objective, target.filled().cycles[None, :], addresses[stop] - addresses[start])[0]
    found = enumerate_window(executor, cpu, state, target, live, pool, length, bound,
                             time.monotonic() + seconds, objective)
    result.window, result.live = tuple(window), live
    result.found = [sequence for _, sequence in found.found]
    result.tested, result.complete = found.tested, found.complete
    result.cpu_seconds = time.process_time() - began
    return result


@dataclass
class WalkResult:
    """One stochastic walk: the rewrites with no mismatch on the samples, each cheaper than the
    walk's best before it, in the order found; moves tried, routines run."""

    candidates: list = field(default_factory=list)  # listings
    tried: int = 0
    runs: int = 0


_LIMITED: dict = {}  # (spec, seed, limit) -> the runner of a worker's walks


def run_walk(context: SearchContext, start: Listing, limit: int, size_limit: int, seed: int,
             moves: int) -> WalkResult:
    """`moves` Metropolis moves from `start` (retro.optimize.stochastic), each move's routine run on
    the samples with a cycle limit of `limit` (a move can make a loop that never ends)."""
    routine = context.the_routine()
    key = (context.spec, id(routine), context.seed, limit, context.scratch)
    if key not in _LIMITED:
        _LIMITED.clear()
        _LIMITED[key] = LaneRunner(replace(routine, limit=limit, outputs=routine.outputs + context.preserve),
                                   context.seed, context.scratch)
    lanes = _LIMITED[key]
    result = WalkResult()
    objective = context.objective

    def cost(code: bytes):
        s = context.samples
        run = lanes.run(code, routine.entry_address, s.columns, s.indices, s.pinned)
        ok = outputs_equal(run, s.expected)
        if context.preserve:
            ok &= outputs_equal(run, [None] * len(routine.outputs) + list(context.kept), skip=True)
        result.runs += 1
        cycles = run.cycles[run.error == 0]
        if not len(cycles):
            return None
        value = {"worst": float(cycles.max()), "mean": float(cycles.mean()), "bytes": float(len(code))}[objective]
        return int((~ok).sum()), value

    pool = instruction_pool(routine.cpu, start, (), context.addresses) + list(context.table_pool)
    result.candidates, result.tried = walk(start, cost, pool, routine.cpu, size_limit, moves, seed)
    return result
