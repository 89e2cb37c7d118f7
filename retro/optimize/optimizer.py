"""The superoptimiser's loop: the routine's windows searched within a time budget, each change run
on the samples and proven on the whole routine before it is kept (retro.optimize.search,
retro.optimize.evaluate). The search may miss a routine; it never admits one that fails a proof."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from retro.errors import InputError, RunError
from retro.optimize.code import Instruction, Listing, assemble, code_bytes, program_with, read_listing
from retro.optimize.effects import ALL_MEMORY, windowable, writes_through_index
from retro.optimize.evaluate import LaneRunner, Proof, Prover, answered, outputs_equal, sample_cases, scratch_of
from retro.optimize.facts import entry_facts, facts_before, window_agrees
from retro.optimize.flow import rewrites as flow_rewrites
from retro.optimize.search import BRANCHES, END, FLAG_BITS, Executor
from retro.optimize.stochastic import WALK_MOVES
from retro.optimize.tables import allowed_tables, table_bytes, table_pool
from retro.optimize.units import SearchContext, WalkResult, WindowResult, run_walk, run_window
from retro.routines.places import FLAGS, Place, Port
from retro.routines.spec import Routine
from retro.workers import MAX_WORKERS, Workers, run_in_order, session

OBJECTIVES = ("worst", "mean", "bytes")
PRESERVABLE = ("A", "X", "Y", "C", "Z", "N", "V", "D")
DEFAULT_WINDOW = 3
WINDOW_SHARE = 8  # a window's enumeration takes at most 1/this of the budget (synthesis: half) ...
MIN_WINDOW_SECONDS = 0.5  # ... but at least this long
SYNTHESIS_LENGTH = 6
STOCHASTIC_MIN_LIMIT = 200  # cycles a rewrite's call may take at least (else 4 x the best's worst case)
WALKS_PER_ROUND = 4  # stochastic walks run from the same best routine before the results are looked at
PINNED_INDEX = 1 << 40  # the case numbers of SMT counterexamples (their entry state is their own)


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
    jobs: int = 1  # local worker processes for the work units (1: this process)
    scheduler: str | None = None  # a Dask scheduler's address: the work units run on that cluster
    smt: bool = True  # past the sweep's reach, prove each change with z3 (retro.optimize.formal)
    tables: tuple[str, ...] = ()  # [memory] blocks a candidate may read, their bytes counted (retro.optimize.tables)


def check_options(options: Options) -> None:
    if options.objective not in OBJECTIVES:
        raise InputError(f"--objective: {options.objective!r} is not one of {', '.join(OBJECTIVES)}")
    if not options.budget > 0:
        raise InputError(f"--budget: {options.budget:g} seconds: give a time above 0")
    if not 1 <= options.window <= 8:
        raise InputError(f"--window: {options.window}: give 1 to 8 instructions")
    if not 1 <= options.jobs <= MAX_WORKERS:
        raise InputError(f"--jobs: {options.jobs}: give 1 to {MAX_WORKERS} worker processes")
    for name in options.preserve:
        if name not in PRESERVABLE:
            raise InputError(f"--preserve: {name!r} is not one of {', '.join(PRESERVABLE)}")


@dataclass
class Change:
    start: int
    removed: tuple[Instruction, ...]
    added: tuple[Instruction, ...]
    kind: str  # "window", "synthesis", "flow" or "stochastic"
    proof: Proof
    what: str = ""  # a flow rewrite: which (retro.optimize.flow)


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
    local_rejections: int = 0  # window changes that differ from the window on an entry state the facts allow
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
    found.update(b for i in listing.instructions if i.mode == "iny" for b in (i.operand, (i.operand + 1) & 0xFF))
    for port in routine.inputs + routine.outputs:
        if port.via is None:
            found.update(p.address for p in port.places if p.kind == "memory")
    return tuple(sorted(found))


def constant_bytes(routine: Routine, listing: Listing) -> frozenset[int]:
    """The program's bytes that no instruction of the routine writes (directly; a routine writing
    through an index has none) and no input sits on: the same on every case."""
    if any(writes_through_index(i) for i in listing.instructions):
        return frozenset()
    program = routine.program
    written = {i.operand for i in listing.instructions if i.mode in ("zpg", "abs") and i.target is None
               and i.mnemonic in ("STA", "STX", "STY", "INC", "DEC", "ASL", "LSR", "ROL", "ROR")}
    written.update(place.address for port in routine.inputs + routine.outputs for place in port.places
                   if place.kind == "memory")
    return frozenset(range(program.origin, program.origin + len(program.code))) - written


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
        # a window may read through an index when every byte it can read that differs between cases
        # is one the search's states hold: nothing written through an index, no input behind a pointer
        self.indexed_reads = not any(writes_through_index(i) for i in self.listing.instructions) and not any(
            port.via is not None for port in routine.inputs + routine.outputs)
        self.scratch = scratch_of(routine, self.addresses)
        preserve = preserved_ports(options.preserve)
        self.preserve = preserve
        self.lanes = LaneRunner(replace(routine, outputs=routine.outputs + preserve), self.seed, self.scratch)
        self.samples = sample_cases(routine, self.seed, self.lanes.runner.memory_values)
        self.prover = Prover(routine, self.seed, self.scratch, preserve)
        self.at_return = live_at_return(routine, options.preserve)
        self.kept_samples = None
        self.synthesised = False
        self.workers = Workers(options.jobs, options.scheduler)
        self.constant = constant_bytes(routine, self.listing)
        self.formal = None  # made when a change needs it (retro.optimize.formal)
        self.tables = allowed_tables(routine, options.tables, self.lanes.runner.memory_values)
        self.table_pool = table_pool(routine.cpu, self.tables)

    def weight(self, listing: Listing) -> int:
        """A routine's size: its code's bytes and those of every allowed table it reads."""
        return code_bytes(listing) + table_bytes(listing, self.tables)

    def static(self, low: int, high: int) -> bool:
        """Whether bytes low..high are the routine's own tables: the same on every case, never written."""
        return all(a in self.constant for a in range(low, high + 1))

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
        with session():  # one cluster for every pass (when the units run on one)
            while improved and self.options.windows and time.monotonic() < deadline:
                improved = False
                flowed = self.flow_change(current, outcome, best_score)
                if flowed is None:
                    flowed = self.window_pass(current, deadline, outcome, best_score)
                if flowed is not None:
                    current, best_score, change = flowed
                    outcome.changes.append(change)
                    outcome.best, outcome.best_proof = current, change.proof
                    what = change.what or (f"{change.kind} at instruction {change.start}: {len(change.removed)} -> "
                                           f"{len(change.added)} instructions")
                    self.progress(f"{what}; worst {change.proof.cycles['max']}, mean "
                                  f"{change.proof.cycles['mean']:.2f}, {self.weight(current)} bytes")
                    improved = True
            if self.options.stochastic and time.monotonic() < deadline:
                self.rewrite(outcome, deadline)
        outcome.seconds = time.monotonic() - began
        outcome.best_proof = chained(outcome)
        outcome.table_bytes = (table_bytes(self.listing, self.tables), table_bytes(outcome.best, self.tables))
        outcome.program = program_with(routine.program, outcome.best, routine.cpu, self.size)
        return outcome

    def context(self) -> SearchContext:
        """What the work units share (retro.optimize.units), as of now (samples grow by counterexamples)."""
        return SearchContext(str(self.routine.spec_path.resolve()), self.seed, self.options.objective, self.scratch,
                             self.addresses, self.at_return, self.preserve, self.samples, self.kept_samples,
                             self.routine, tuple(self.table_pool))

    def rewrite(self, outcome: Outcome, deadline: float) -> None:
        """Stochastic rewriting of the best routine for the rest of the budget (retro.optimize.stochastic):
        rounds of WALKS_PER_ROUND walks (work units) from the best routine so far, each with its own
        seed; their rewrites are proven here in task order and the best proven one is kept."""
        objective = self.options.objective
        limit = max(4 * outcome.best_proof.cycles["max"], STOCHASTIC_MIN_LIMIT)
        best_score = [score(objective, outcome.best_proof, self.weight(outcome.best))]
        walks = [0]

        def report(result: WalkResult) -> bool:
            outcome.rewrites += result.tried
            outcome.routine_tests += result.runs
            for listing in result.candidates:
                if time.monotonic() > deadline:
                    return True
                better = self.better(outcome.best, listing, outcome, best_score[0])
                if better is not None:
                    best_score[0] = better[0]
                    outcome.changes.append(Change(0, outcome.best.instructions, listing.instructions, "stochastic",
                                                  better[1]))
                    outcome.best, outcome.best_proof = listing, better[1]
                    self.progress(f"stochastic rewrite: worst {better[1].cycles['max']}, mean "
                                  f"{better[1].cycles['mean']:.2f}, {self.weight(listing)} bytes")
            return time.monotonic() > deadline

        while time.monotonic() < deadline:
            context, start = self.context(), outcome.best
            tasks = [(context, start, limit, self.size, self.seed * 7919 + walks[0] + k, WALK_MOVES)
                     for k in range(WALKS_PER_ROUND)]
            walks[0] += WALKS_PER_ROUND
            run_in_order(run_walk, tasks, self.workers, report)

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
        where = dict(listing.labels)

        def fits(instruction, stop: int) -> bool:  # straight-line, or a branch to the window's end (a join)
            if instruction.is_branch:
                return (instruction.mnemonic in BRANCHES and isinstance(instruction.target, str)
                        and where[instruction.target] == stop)
            return windowable(instruction, self.indexed_reads)

        for length in range(1, min(self.options.window, n) + 1):  # short windows first: cheap, and most gains
            for start in range(n - length + 1):
                stop = start + length
                if all(fits(i, stop) for i in instructions[start:stop]) and not any(
                        k in targets for k in range(start + 1, stop)) and not instructions[stop - 1].is_branch:
                    yield start, stop, "window"

    def window_pass(self, listing: Listing, deadline: float, outcome: Outcome, best_score: tuple):
        """Every window of the listing as a work unit (retro.optimize.units.run_window), their results
        taken in window order: the first window whose candidate is proven and better ends the pass,
        as (listing, score, change); None when none is (or the budget ran out)."""
        taken: list = []
        facts = facts_before(listing, entry_facts(self.routine.entry_state))
        executor = Executor(self.routine.cpu, bytes(self.lanes.runner.call_image), 1, listing.origin)

        def tasks():
            context = self.context()
            best_cycles = (outcome.best_proof.cycles["max"], outcome.best_proof.cycles["mean"])
            for start, stop, kind in self.windows(listing):
                left = deadline - time.monotonic()
                if left <= 0:
                    outcome.complete = False
                    return
                share = max(self.options.budget / (2 if kind == "synthesis" else WINDOW_SHARE), MIN_WINDOW_SECONDS)
                length = max(self.options.window, SYNTHESIS_LENGTH) if kind == "synthesis" else stop - start
                yield context, listing, start, stop, kind, min(share, left), best_cycles, length

        def report(result: WindowResult) -> bool:
            outcome.windows += 1
            outcome.tested += result.tested
            outcome.complete &= result.complete
            outcome.search_seconds += result.cpu_seconds
            found = self.window_candidates(listing, result, facts[result.start] or frozenset(), executor, deadline,
                                           outcome, best_score)
            if found is not None:
                taken.append(found)
                return True
            if time.monotonic() > deadline:
                outcome.complete = False
                return True
            return False

        run_in_order(run_window, tasks(), self.workers, report)
        return taken[0] if taken else None

    def window_candidates(self, listing: Listing, result: WindowResult, facts: frozenset, executor: Executor,
                          deadline: float, outcome: Outcome, best_score: tuple):
        """The first of a window's sequences that is proven and better, as (listing, score, change)."""
        start, stop, kind, window = result.start, result.stop, result.kind, result.window
        for sequence in result.found:
            if time.monotonic() > deadline:  # candidates left untested: the search is not complete
                outcome.complete = False
                break
            if kind == "window" and tuple(sequence) == tuple(window):
                continue
            if kind == "window" and self.prover.kind != "exhaustive" and not window_agrees(
                    executor, window, sequence, result.live, facts, self.static):
                outcome.local_rejections += 1  # a sampled proof alone would not stand behind it
                continue
            new = self.replaced(listing, start, stop, sequence)
            better = self.better(listing, new, outcome, best_score)
            if better is not None:
                return new, better[0], Change(start, tuple(window), tuple(sequence), kind, better[1])
        return None

    def better(self, old: Listing, new: Listing, outcome: Outcome, best_score: tuple) -> tuple[tuple, Proof] | None:
        """(score, proof) of a candidate listing (`new` in place of `old`) that fits, passes the samples and its proof (and
        --no-slower) with a better score than `best_score`; else None."""
        new_code = assemble(new, self.routine.cpu)
        if new_code is None or len(new_code) > self.size:
            return None
        outcome.routine_tests += 1
        if not self.sample_ok(new_code):
            return None
        proof = self.proven(new_code, outcome, old, new)
        if not proof.passed or (self.options.no_slower and proof.slower):
            return None
        new_score = score(self.options.objective, proof, self.weight(new))
        return (new_score, proof) if new_score < best_score else None

    def flow_change(self, listing: Listing, outcome: Outcome, best_score: tuple):
        """The first control-flow rewrite (retro.optimize.flow) that is proven and better, as
        (listing, score, change), or None."""
        for what, new in flow_rewrites(listing):
            better = self.better(listing, new, outcome, best_score)
            if better is not None:
                return new, better[0], Change(0, listing.instructions, new.instructions, "flow", better[1], what)
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
                fails = not self.sample_ok(code)
                # z3 refuted the whole routine on an entry state in the domain: refused even when the
                # core's run of that state passes (z3 and the core disagree: trust neither to admit it)
                if fails or verdict.scope == "routine":
                    outcome.failed_proofs += 1
                    return replace(proof, passed=False, smt=[verdict.record()],
                                   note="z3's counterexample fails on the batched core" if fails else
                                   "z3 refuted the routine on an entry state in the domain (its run on the "
                                   "batched core passed: refused all the same)")
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
