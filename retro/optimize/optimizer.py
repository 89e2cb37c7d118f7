"""The superoptimiser's loop: the routine's windows searched within a time budget, each change run
on the samples and proven on the whole routine before it is kept (retro.optimize.search,
retro.optimize.evaluate). The search may miss a routine; it never admits one that fails a proof."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from retro.cpu.batch import LaneError
from retro.errors import InputError, RunError
from retro.optimize.code import Instruction, Listing, assemble, code_bytes, program_with, read_listing
from retro.optimize.effects import ALL_MEMORY, live_after, windowable
from retro.optimize.evaluate import LaneRunner, Proof, Prover, answered, outputs_equal, sample_cases, scratch_of
from retro.optimize.stochastic import rewrite
from retro.optimize.tables import allowed_tables, table_bytes, table_pool
from retro.optimize.search import (BRANCHES, BRK, END, FLAG_BITS, Executor, cycles_of, enumerate_window,
                                   instruction_pool, rank, state_of, state_ports)
from retro.routines.places import FLAGS, Place, Port
from retro.routines.spec import Routine

OBJECTIVES = ("worst", "mean", "bytes")
PRESERVABLE = ("A", "X", "Y", "C", "Z", "N", "V", "D")
DEFAULT_WINDOW = 3
WINDOW_SHARE = 8  # a window's enumeration takes at most 1/this of the budget (synthesis: half) ...
MIN_WINDOW_SECONDS = 0.5  # ... but at least this long
SYNTHESIS_LENGTH = 6
STOCHASTIC_MIN_LIMIT = 200  # cycles a rewrite's call may take at least (else 4 x the best's worst case)
PINNED_INDEX = 1 << 40  # the case numbers of SMT counterexamples (their entry state is their own)
SYNTHESIS_LANES = 64  # sample cases the synthesis enumerates on (it searches deeper, on more states)  # a routine of at most this many instructions (before its RTS) is also searched whole


@dataclass(frozen=True)
class Options:
    objective: str = "worst"
    no_slower: bool = False
    budget: float = 30.0
    window: int = DEFAULT_WINDOW
    seed: int | None = None
    preserve: tuple[str, ...] = ()
    synthesis: bool = True
    windows: bool = True  # the enumerative window search (off: only synthesis and stochastic rewriting)
    stochastic: bool = True  # rewrite at random for the budget the windows leave
    smt: bool = True  # past the sweep's reach, prove each change with z3 (retro.optimize.formal)
    tables: tuple[str, ...] = ()  # [memory] blocks a candidate may read, their bytes counted (retro.optimize.tables)


def check_options(options: Options) -> None:
    if options.objective not in OBJECTIVES:
        raise InputError(f"--objective: {options.objective!r} is not one of {', '.join(OBJECTIVES)}")
    if not options.budget > 0:
        raise InputError(f"--budget: {options.budget:g} seconds: give a time above 0")
    if not 1 <= options.window <= 8:
        raise InputError(f"--window: {options.window}: give 1 to 8 instructions")
    for name in options.preserve:
        if name not in PRESERVABLE:
            raise InputError(f"--preserve: {name!r} is not one of {', '.join(PRESERVABLE)}")


@dataclass
class Change:
    start: int
    removed: tuple[Instruction, ...]
    added: tuple[Instruction, ...]
    kind: str  # "window" or "synthesis"
    proof: Proof


@dataclass
class Outcome:
    routine: Routine
    original: Listing
    best: Listing
    original_proof: Proof
    best_proof: Proof
    changes: list = field(default_factory=list)
    tested: int = 0  # sequences run on the samples' states
    routine_tests: int = 0  # whole-routine runs on the samples
    proofs: int = 0
    failed_proofs: int = 0
    counterexamples: int = 0
    seconds: float = 0.0
    search_seconds: float = 0.0
    prove_seconds: float = 0.0
    complete: bool = True  # every window was searched to its length within the budget
    windows: int = 0
    rewrites: int = 0  # stochastic moves tried
    program: object = None  # the new Program
    smt_seconds: float = 0.0  # CPU seconds in z3
    table_bytes: tuple = (0, 0)  # bytes of the allowed tables the original and the best routine read


def preserved_ports(names: tuple[str, ...]) -> tuple[Port, ...]:
    ports = []
    for name in names:
        place = Place("register", register=name.lower()) if name in "AXY" else Place("flag", bit=FLAGS[name])
        ports.append(Port(f"preserved_{name}", (place,)))
    return tuple(ports)


def direct_addresses(routine: Routine, listing: Listing) -> tuple[int, ...]:
    """Addresses the search may read and write: the routine's direct operands and its ports in memory."""
    found = {i.operand for i in listing.instructions if i.mode in ("zpg", "abs") and i.target is None}
    for port in routine.inputs + routine.outputs:
        if port.via is None:
            found.update(p.address for p in port.places if p.kind == "memory")
    return tuple(sorted(found))


def live_at_return(routine: Routine, preserve: tuple[str, ...]) -> frozenset:
    live = set(preserve)
    for port in routine.outputs:
        for place in port.places:
            if place.kind == "register":
                live.add(place.register.upper())
            elif place.kind == "flag":
                live.add(next(n for n, b in FLAG_BITS.items() if b == place.bit))
            elif place.kind == "memory":
                live.add(place.address)
            else:
                live.add(ALL_MEMORY)
    if any(port.via is not None for port in routine.outputs):
        live.add(ALL_MEMORY)
    return frozenset(live)


def score(objective: str, proof: Proof, size: int) -> tuple:
    """What the objective orders by, the others as tie-breakers (smaller is better)."""
    worst, mean = proof.cycles["max"], proof.cycles["mean"]
    if objective == "bytes":
        return (size, worst, mean)
    if objective == "mean":
        return (mean, worst, size)
    return (worst, mean, size)


class Search:
    def __init__(self, routine: Routine, options: Options, progress: Callable[[str], None] | None = None) -> None:
        check_options(options)
        if routine.reference is None:
            raise InputError(f"{routine.shown_path or routine.spec_path}: reference: the spec has no reference "
                             "function: the optimiser needs one to know what the routine must compute")
        if routine.world is not None and not routine.world.empty:
            raise InputError(f"{routine.spec_path}: the routine has a world ([mocks], [hardware], an interrupt "
                             "entry or an exit): the optimiser runs plain routines only")
        self.routine, self.options = routine, options
        self.progress = progress or (lambda line: None)
        self.seed = routine.seed if options.seed is None else options.seed
        try:
            self.listing = read_listing(routine.program, routine.entry_address, routine.cpu)
        except InputError as exc:
            raise InputError(f"{routine.shown_path or routine.spec_path}: program: {exc}") from None
        self.size = code_bytes(self.listing)
        original = assemble(self.listing, routine.cpu)
        start = routine.entry_address - routine.program.origin
        if original != routine.program.code[start:start + len(original)]:
            raise InputError(f"{routine.spec_path}: the routine's code does not assemble back to its bytes")
        self.addresses = direct_addresses(routine, self.listing)
        self.scratch = scratch_of(routine, self.addresses)
        preserve = preserved_ports(options.preserve)
        self.preserve = preserve
        self.lanes = LaneRunner(replace(routine, outputs=routine.outputs + preserve), self.seed, self.scratch)
        self.samples = sample_cases(routine, self.seed, self.lanes.runner.memory_values)
        self.prover = Prover(routine, self.seed, self.scratch, preserve)
        self.at_return = live_at_return(routine, options.preserve)
        self.kept_samples = None
        self.synthesised = False
        self.formal = None  # made when a change needs it (retro.optimize.formal)
        self.tables = allowed_tables(routine, options.tables, self.lanes.runner.memory_values)
        self.table_pool = table_pool(routine.cpu, self.tables)

    def weight(self, listing: Listing) -> int:
        """A routine's size: its code's bytes and those of every allowed table it reads."""
        return code_bytes(listing) + table_bytes(listing, self.tables)

    # ---- whole-routine runs --------------------------------------------------------------------

    def sample_ok(self, code: bytes) -> bool:
        s = self.samples
        outcome = self.lanes.run(code, self.routine.entry_address, s.columns, s.indices, s.pinned)
        ok = outputs_equal(outcome, s.expected)
        if self.preserve:
            kept = self.kept_samples
            ok &= outputs_equal(outcome, [None] * len(self.routine.outputs) + list(kept), skip=True)
        return bool(ok.all())

    def refresh_kept(self, code: bytes) -> None:
        if self.preserve:
            s = self.samples
            outcome = self.lanes.run(code, self.routine.entry_address, s.columns, s.indices, s.pinned)
            self.kept_samples = outcome.outputs[-len(self.preserve):]

    def window_states(self, code: bytes, start_address: int):
        """The machine state where the routine reaches `start_address`, per sample case that does:
        (state, lanes) from a run with BRK there (and the direct addresses read as outputs)."""
        probe = replace(self.routine, outputs=state_ports(self.addresses))
        runner = LaneRunner(probe, self.seed, self.scratch)
        patched = bytearray(code)
        patched[start_address - self.routine.entry_address] = BRK
        s = self.samples
        outcome = runner.run(bytes(patched), self.routine.entry_address, s.columns, s.indices, s.pinned)
        lanes = np.flatnonzero(outcome.error == LaneError.BRK)
        return state_of(outcome.outputs, self.addresses, lanes), lanes, runner

    # ---- the loop ------------------------------------------------------------------------------

    def run(self) -> Outcome:
        began = time.monotonic()
        deadline = began + self.options.budget
        routine = self.routine
        code = assemble(self.listing, routine.cpu)
        began_cpu = time.process_time()
        first = self.prover.prove(code, routine.entry_address)
        if not first.passed:
            columns, expected, index = first.counterexample
            raise RunError(f"{routine.spec_path}: the routine itself fails its spec (e.g. inputs "
                           f"{', '.join(f'{n}={int(c[0]) if c.ndim == 1 else c[0].tolist()}' for n, c in zip(routine.input_names, columns))}"
                           f" with the entry state the spec leaves free random): run `retro check` and fix it first")
        self.prover.reference_cycles = first.per_case
        self.refresh_kept(code)
        outcome = Outcome(routine, self.listing, self.listing, first, first, proofs=1,
                          prove_seconds=time.process_time() - began_cpu)
        best_score = score(self.options.objective, first, self.weight(self.listing))
        current = self.listing
        improved = True
        while improved and self.options.windows and time.monotonic() < deadline:
            improved = False
            for start, stop, kind in self.windows(current):
                if time.monotonic() > deadline:
                    outcome.complete = False
                    break
                found = self.search_window(current, start, stop, kind, deadline, outcome, best_score)
                if found is not None:
                    current, best_score, change = found
                    outcome.changes.append(change)
                    outcome.best, outcome.best_proof = current, change.proof
                    self.progress(f"{kind} at instruction {start}: {len(change.removed)} -> {len(change.added)} "
                                  f"instructions; worst {change.proof.cycles['max']}, mean "
                                  f"{change.proof.cycles['mean']:.2f}, {self.weight(current)} bytes")
                    improved = True
                    break
        if self.options.stochastic and time.monotonic() < deadline:
            self.rewrite(outcome, deadline)
        outcome.seconds = time.monotonic() - began
        outcome.best_proof = chained(outcome)
        outcome.table_bytes = (table_bytes(self.listing, self.tables), table_bytes(outcome.best, self.tables))
        outcome.program = program_with(routine.program, outcome.best, routine.cpu, self.size)
        return outcome

    def rewrite(self, outcome: Outcome, deadline: float) -> None:
        """Stochastic rewriting of the best routine for the rest of the budget (retro.optimize.stochastic):
        moves run on the samples with a tight cycle limit (a move can make a loop that never ends)."""
        routine, objective = self.routine, self.options.objective
        limit = max(4 * outcome.best_proof.cycles["max"], STOCHASTIC_MIN_LIMIT)
        lanes = LaneRunner(replace(routine, limit=limit, outputs=routine.outputs + self.preserve), self.seed,
                           self.scratch)
        best_score = [score(objective, outcome.best_proof, self.weight(outcome.best))]

        def cost(code: bytes):
            s = self.samples
            run = lanes.run(code, routine.entry_address, s.columns, s.indices, s.pinned)
            ok = outputs_equal(run, s.expected)
            if self.preserve:
                ok &= outputs_equal(run, [None] * len(routine.outputs) + list(self.kept_samples), skip=True)
            outcome.routine_tests += 1
            cycles = run.cycles[run.error == 0]
            if not len(cycles):
                return None
            value = {"worst": float(cycles.max()), "mean": float(cycles.mean()), "bytes": float(len(code))}[objective]
            return int((~ok).sum()), value

        def found(listing: Listing, code: bytes) -> bool:
            if not self.sample_ok(code):
                return False
            proof = self.proven(code, outcome, outcome.best, listing)
            if not proof.passed or (self.options.no_slower and proof.slower):
                return False
            new_score = score(objective, proof, self.weight(listing))
            if new_score >= best_score[0]:
                return False
            best_score[0] = new_score
            outcome.changes.append(Change(0, outcome.best.instructions, listing.instructions, "stochastic", proof))
            outcome.best, outcome.best_proof = listing, proof
            self.progress(f"stochastic rewrite: worst {proof.cycles['max']}, mean {proof.cycles['mean']:.2f}, "
                          f"{len(code)} bytes")
            return True

        pool = instruction_pool(routine.cpu, outcome.best, (), self.addresses) + self.table_pool
        outcome.rewrites += rewrite(outcome.best, cost, pool, routine.cpu, self.size, deadline, self.seed, found)

    def windows(self, listing: Listing):
        """(start, stop, kind): the whole routine first when it is short, then every window of up to
        `window` straight-line instructions with no branch target inside, shortest first."""
        instructions = listing.instructions
        n = len(instructions)
        if (self.options.synthesis and not self.synthesised and instructions and instructions[-1].mnemonic == "RTS"
                and 1 < n <= SYNTHESIS_LENGTH + 1
                and not any(i.mnemonic in ("RTS", "RTI", "JMP", "JSR", "BRK") for i in instructions[:-1])):
            self.synthesised = True  # once: a second run on its own result would search the same space again
            yield 0, n - 1, "synthesis"
        targets = listing.targets
        for length in range(1, min(self.options.window, n) + 1):  # short windows first: cheap, and most gains
            for start in range(n - length + 1):
                stop = start + length
                if all(windowable(i) for i in instructions[start:stop]) and not any(
                        k in targets for k in range(start + 1, stop)):
                    yield start, stop, "window"

    def search_window(self, listing: Listing, start: int, stop: int, kind: str, deadline: float,
                      outcome: Outcome, best_score: tuple):
        cpu, objective = self.routine.cpu, self.options.objective
        outcome.windows += 1
        code = assemble(listing, cpu)
        addresses = [listing.origin]
        for i in listing.instructions:
            addresses.append(addresses[-1] + i.length)
        cpu_began = time.process_time()
        state, lanes, probe = self.window_states(code, addresses[start])
        if not len(lanes):
            return None
        window = listing.instructions[start:stop]
        executor = Executor(cpu, bytes(probe.runner.call_image), len(lanes), addresses[start])
        pool = instruction_pool(cpu, listing, window, self.addresses) + self.table_pool
        if kind == "synthesis":
            state, lanes = _first_lanes(state, lanes, SYNTHESIS_LANES)
            target, live = self.synthesis_target(state, lanes)
            worst_cycles = outcome.best_proof.cycles["max"] - cycles_of(cpu, listing.instructions[-1])
            mean_cycles = outcome.best_proof.cycles["mean"] - cycles_of(cpu, listing.instructions[-1])
            size = addresses[stop] - addresses[start]
            bound = {"worst": (worst_cycles, size + 1), "mean": (mean_cycles, size + 1), "bytes": (size, worst_cycles + 1)}[
                objective]
            length = max(self.options.window, SYNTHESIS_LENGTH)
            pool = [i for i in pool if i.mode != "rel"] + [Instruction(b, "rel", target=END) for b in BRANCHES]
        else:
            target = state
            for instruction in window:
                target = executor.step(target, instruction)
            live = live_after(listing, self.at_return)[stop - 1]
            bound = rank(objective, target.filled().cycles[None, :], addresses[stop] - addresses[start])[0]
            length = stop - start
        share = max(self.options.budget / (2 if kind == "synthesis" else WINDOW_SHARE), MIN_WINDOW_SECONDS)
        found = enumerate_window(executor, cpu, state, target, live, pool, length, bound,
                                 min(deadline, time.monotonic() + share), objective)
        outcome.tested += found.tested
        outcome.complete &= found.complete
        outcome.search_seconds += time.process_time() - cpu_began
        for _, sequence in found.found:
            if time.monotonic() > deadline:  # candidates left untested: the search is not complete
                outcome.complete = False
                break
            if kind == "window" and tuple(sequence) == tuple(window):
                continue
            new = self.replaced(listing, start, stop, sequence)
            new_code = assemble(new, cpu)
            if new_code is None or len(new_code) > self.size:
                continue
            outcome.routine_tests += 1
            if not self.sample_ok(new_code):
                continue
            proof = self.proven(new_code, outcome, listing, new)
            if not proof.passed:
                continue
            if self.options.no_slower and proof.slower:
                continue
            new_score = score(objective, proof, self.weight(new))
            if new_score < best_score:
                return new, new_score, Change(start, tuple(window), tuple(sequence), kind, proof)
        return None

    def proven(self, code: bytes, outcome: Outcome, old: Listing | None = None, new: Listing | None = None) -> Proof:
        """The proof of a candidate (`new` in place of `old`); a counterexample joins the samples."""
        began = time.process_time()
        proof = self.prover.prove(code, self.routine.entry_address)
        if proof.passed and proof.kind == "sampled" and self.options.smt and old is not None:
            proof = self.proven_formally(proof, code, old, new, outcome)
        outcome.prove_seconds += time.process_time() - began
        outcome.proofs += 1
        if not proof.passed and proof.counterexample is not None:
            outcome.failed_proofs += 1
            outcome.counterexamples += 1
            columns, expected, index = proof.counterexample
            self.samples.add(columns, expected, index)
            self.refresh_kept(assemble(self.listing, self.routine.cpu))
        return proof

    def proven_formally(self, proof: Proof, code: bytes, old: Listing, new: Listing, outcome: Outcome) -> Proof:
        """A change the spec's cases passed, proven by z3 (kind "smt"); a counterexample of the whole
        routine replayed on the batched core, and kept when the candidate fails it there."""
        from retro.optimize.formal import Formal  # z3 loads only when a proof needs it
        if self.formal is None:
            runner = self.prover.baseline.runner
            self.formal = Formal(self.routine, runner.call_image, self.size, self.at_return, runner.memory_values)
        verdict = self.formal.prove(old, new)
        if verdict is None:
            return proof
        result = verdict.result
        outcome.smt_seconds += result.seconds
        if result.status == "proven":
            # the whole routine's cycles are z3's too: slower on some entry state the cases may have missed
            slower = proof.slower or (verdict.scope == "routine" and result.no_slower is False)
            return replace(proof, kind="smt", smt=[verdict.record()], slower=slower,
                           note=f"z3 proved the {verdict.scope} equal on the outputs from every entry state "
                                "in the domain")
        witness = verdict.counterexample
        if witness is not None:
            columns = [np.asarray([v], dtype=np.int64) for v in witness.inputs]
            expected, counted = answered(self.routine, columns, self.lanes.runner.memory_values)
            if counted.all():
                index = PINNED_INDEX + len(self.samples.pinned)
                self.samples.add(columns, expected, index, witness)
                outcome.counterexamples += 1
                self.refresh_kept(assemble(self.listing, self.routine.cpu))
                if not self.sample_ok(code):
                    outcome.failed_proofs += 1
                    return replace(proof, passed=False, smt=[verdict.record()],
                                   note="z3's counterexample fails on the batched core")
        return replace(proof, smt=[verdict.record()], note=f"random and boundary cases only (z3: {result.status}"
                       f"{': ' + result.reason if result.reason else ''})")

    @staticmethod
    def replaced(listing: Listing, start: int, stop: int, sequence) -> Listing:
        """The listing with the window replaced; a synthesised branch's END becomes a label at the
        instruction after the window (the one there, or a new one)."""
        if not any(i.target == END for i in sequence):
            return listing.with_window(start, stop, sequence)
        names = [name for name, at in listing.labels if at == stop]
        taken = {name for name, _ in listing.labels}
        name = names[0] if names else next(f"done{k or ''}" for k in range(len(taken) + 1) if f"done{k or ''}" not in taken)
        sequence = tuple(replace(i, target=name) if i.target == END else i for i in sequence)
        labels = listing.labels if names else listing.labels + ((name, stop),)
        return replace(listing, labels=labels).with_window(start, stop, sequence)

    def synthesis_target(self, state, lanes):
        """The state the whole routine must end in: the reference's answers in the output places."""
        target = type(state)(state.a.copy(), state.x.copy(), state.y.copy(), state.p.copy(), dict(state.memory))
        live = set()
        for port, expected in zip(self.routine.outputs, self.samples.expected):
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
        if self.preserve:
            for port, kept in zip(self.preserve, self.kept_samples):
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


def chained(outcome: Outcome) -> Proof:
    """The proof of the best routine against the original: "smt" only when every change on the way
    was proven by z3 (each step equal to the one before it), else as its own cases have it."""
    best = outcome.best_proof
    if best.kind != "smt":
        return best
    records = [record for change in outcome.changes for record in change.proof.smt]
    if all(change.proof.kind == "smt" for change in outcome.changes):
        return replace(best, smt=records)
    return replace(best, kind="sampled", smt=records,
                   note="random and boundary cases only (an earlier change was not proven by z3)")


def optimize(routine: Routine, options: Options, progress: Callable[[str], None] | None = None) -> Outcome:
    return Search(routine, options, progress).run()
