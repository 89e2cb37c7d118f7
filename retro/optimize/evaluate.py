"""Candidates run on the batched core (retro.cpu.batch, through the check's RoutineRunner) with the
candidate's code swapped into the routine's memory image, against the reference's answers.

Everything the spec leaves free is arbitrary here, never 0: each test case runs with its own random
free registers and flags (retro.routines.entry's random variant), untouched memory is the random
variant's bytes, and every address a candidate may reach that nothing sets (`scratch`) gets its own
random byte per case. A candidate that relies on "X = 0 on entry" (the check's baseline) fails.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from retro.analysis.check.reference import reference_answers
from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines.entry import variant_values
from retro.routines.places import Port
from retro.routines.runner import BatchOutcome, RoutineRunner
from retro.routines.spec import Routine

SAMPLE = 256  # test cases a candidate runs on during the search (counterexamples are added to them)
PROOF_SPACE = 1 << 20  # an input space this small is swept whole by a proof
PROOF_BLOCK = 1 << 16  # cases per batched-core run in a proof
SCRATCH_SALT = 0x5C  # the seed offset of the scratch bytes (cases: seed, memory: seed + 1, entry: seed + 3)


def fixed_addresses(routine: Routine) -> set[int]:
    """Addresses whose bytes a call does not leave arbitrary: the program, the inputs, [memory]."""
    program = routine.program
    fixed = set(range(program.origin, program.origin + len(program.code)))
    for port in routine.inputs:
        fixed.update(place.address for place in port.places if place.kind == "memory")
    for block in routine.memory:
        fixed.update(range(block.address, block.address + (len(block.data) if block.data is not None else block.size)))
    return fixed


def scratch_of(routine: Routine, addresses) -> tuple[int, ...]:
    """The addresses among `addresses` nothing sets before a call, and the output places in memory
    (a routine must write its outputs, not find them written by the last call)."""
    fixed = fixed_addresses(routine)
    outputs = {place.address for port in routine.outputs for place in port.places if place.kind == "memory"}
    inputs = {place.address for port in routine.inputs for place in port.places if place.kind == "memory"}
    return tuple(sorted(a for a in set(addresses) | outputs if (a not in fixed or a in outputs) and a not in inputs
                        and 0 <= a <= 0xFFFF and not 0x100 <= a < 0x200))


class LaneRunner:
    """A routine's runner whose calls start from a random entry state per case (see the module's
    docstring): `run(code, columns, indices)` with `code` in place of the routine's bytes."""

    def __init__(self, routine: Routine, seed: int, scratch: tuple[int, ...] = (), fill: str | None = "random") -> None:
        self.routine, self.seed, self.fill = routine, seed, fill
        self.runner = RoutineRunner(routine, seed, fill=fill)
        if fill is None:  # the baseline: what `retro check` runs first (free state 0, memory as loaded)
            scratch = ()
        written_by_init = {a for a in scratch if self.runner.call_image[a] != self.runner.code_image[a]}
        self.scratch = tuple(a for a in scratch if a not in written_by_init)
        extra = len(routine.inputs)
        plan = self.runner.plan
        self.runner.plan = replace(plan, bytes=plan.bytes + tuple((extra + k, a, 0) for k, a in enumerate(self.scratch)))
        self.origin = routine.program.origin

    def run(self, code: bytes, at: int, columns: list, indices: np.ndarray, pinned: dict | None = None) -> BatchOutcome:
        """Run the cases (`indices`: their numbers, which fix their entry state) with `code` at `at`;
        `pinned`: index -> an entry state of its own (`registers`, P `bits`, scratch `memory`), as an
        SMT counterexample gives it."""
        image = self.runner.call_image
        kept = bytes(image[at:at + len(code)])
        image[at:at + len(code)] = code
        try:
            entry = None
            if self.fill is not None:
                state = self.runner.entry_state
                registers, bits = variant_values(state, "random", self.seed, indices)
                entry = (registers, bits, state.free_mask)
            extra = []
            if self.scratch:
                rng = np.random.default_rng([self.seed + SCRATCH_SALT, int(indices[0]) if len(indices) else 0])
                extra = [rng.integers(0, 256, len(indices), dtype=np.int64) for _ in self.scratch]
            for lane, index in enumerate(indices.tolist()) if pinned and self.fill is not None else ():
                if index in pinned:
                    state = pinned[index]
                    for name, values in registers.items():
                        values[lane] = state.registers[name]
                    bits[lane] = state.bits & entry[2]
                    for k, address in enumerate(self.scratch):
                        extra[k][lane] = state.memory.get(address, extra[k][lane])
            return self.runner.run_batch(list(columns) + extra, entry=entry)
        finally:
            image[at:at + len(code)] = kept


def outputs_equal(outcome: BatchOutcome, expected: list, skip: bool = False) -> np.ndarray:
    """Per case: it returned and every output equals the expected one (`skip`: None expects anything)."""
    ok = outcome.error == 0
    for got, want in zip(outcome.outputs, expected):
        if skip and want is None:
            continue
        same = got == want
        ok &= same.all(axis=1) if same.ndim > 1 else same
    return ok


@dataclass
class Samples:
    """The test set: cases (columns), their numbers (entry state), the reference's answers."""

    columns: list
    indices: np.ndarray
    expected: list
    added: int = 0  # counterexamples added by proofs
    pinned: dict = field(default_factory=dict)  # index -> its own entry state (LaneRunner.run)

    def __len__(self) -> int:
        return len(self.indices)

    def add(self, columns: list, expected: list, index: int, entry=None) -> None:
        if entry is not None:
            self.pinned[index] = entry
        self.columns = [np.concatenate([c, extra]) for c, extra in zip(self.columns, columns)]
        self.expected = [np.concatenate([e, extra]) for e, extra in zip(self.expected, expected)]
        self.indices = np.concatenate([self.indices, np.asarray([index], dtype=np.int64)])
        self.added += 1


def answered(routine: Routine, columns: list, memory: dict) -> tuple[list, np.ndarray]:
    """The reference's answers and which cases count (inside the domain and answered)."""
    inside = case_sets.in_domain(routine, columns)
    answers, answerable = reference_answers(routine, columns, None, memory, inside)
    return answers, inside & answerable


def sample_cases(routine: Routine, seed: int, memory: dict, size: int = SAMPLE) -> Samples:
    """Random cases inside the domain (size - size // 4 of them), then the spec's boundary cases, up
    to `size` (an exhaustive part's first cases when there are too few)."""
    parts = case_sets.plan(routine, exhaustive=False, seed=seed, random=max(size, 64))
    parts = [p for p in parts if p.name in ("boundary", "random", "exhaustive")]
    taken: list = []
    count = 0
    order = {"boundary": 1, "random": 0, "exhaustive": 2}  # random first: an exhaustive part's first cases share inputs
    for part in sorted(parts, key=lambda p: order[p.name]):
        block_iter = part.blocks()
        for block in block_iter:
            answers, keep = answered(routine, block, memory)
            wanted = size - count if part.name != "random" else size - size // 4 - count
            keep = np.flatnonzero(keep)[:max(wanted, 0)]
            if len(keep):
                taken.append(([c[keep] for c in block], [a[keep] for a in answers]))
                count += len(keep)
            if count >= size or part.name == "exhaustive":
                break
        if count >= size:
            break
    if not count:
        raise InputError(f"{routine.shown_path or routine.spec_path}: cases: no case inside the domain has an answer "
                         "from the reference: nothing to search against")
    columns = [np.concatenate([t[0][k] for t in taken]) for k in range(len(routine.inputs))]
    expected = [np.concatenate([t[1][k] for t in taken]) for k in range(len(routine.outputs))]
    return Samples(columns, np.arange(count, dtype=np.int64), expected)


@dataclass
class Proof:
    """What stands behind a routine: `kind` "exhaustive" (every input of the space, each with the
    baseline and a random entry state), "smt" (the spec's cases, and every change from the original
    proven by z3: retro.optimize.formal), "sampled" (the spec's random and boundary cases only);
    calls run, the engine, and the first counterexample when it failed."""

    kind: str
    space: int
    cases: int = 0
    calls: int = 0
    engine: str = "batch"
    passed: bool = True
    counterexample: tuple | None = None  # (columns of one case, expected, index)
    slower: bool = False  # some case takes more cycles than the original (for --no-slower)
    cycles: dict = field(default_factory=dict)  # min, mean, max over the proof's cases (the baseline run)
    note: str = ""
    per_case: list = field(default_factory=list)  # the baseline run's cycles per block (for --no-slower)
    smt: list = field(default_factory=list)  # kind "smt": the z3 proofs of the changes (retro.optimize.formal)

    def record(self) -> dict:
        return {"kind": self.kind, "space": self.space, "cases": self.cases, "calls": self.calls,
                "engine": self.engine, "passed": self.passed, "note": self.note, "smt": self.smt}


def proof_parts(routine: Routine, seed: int) -> tuple[str, int, list]:
    """(kind, space, parts): the whole input space when it is at most PROOF_SPACE (the check's
    exhaustive path over every input), else the spec's own cases (random and boundary)."""
    space = routine.input_space()
    if space <= PROOF_SPACE:
        whole = replace(routine, exhaustive=routine.input_names, exhaustive_values=(), sweep=None, random=0)
        return "exhaustive", space, case_sets.plan(whole, exhaustive=True, seed=seed, random=0)
    return "sampled", space, case_sets.plan(routine, exhaustive=False, seed=seed)


class Prover:
    """Runs a candidate over the proof's cases on two runners: the baseline (what `retro check`
    runs) and the random entry state; every case inside the domain must give the reference's
    answers on both, in the same cycles on both. The reference's answers are computed once."""

    def __init__(self, routine: Routine, seed: int, scratch: tuple[int, ...], preserve: tuple[Port, ...] = ()) -> None:
        self.routine, self.seed = routine, seed
        extended = replace(routine, outputs=routine.outputs + preserve)  # preserved: as the original leaves them
        self.baseline = LaneRunner(extended, seed, fill=None)
        self.random = LaneRunner(extended, seed, scratch)
        self.preserved = len(preserve)
        self.kept: dict = {}  # (block, runner) -> the original's preserved outputs
        self.kind, self.space, parts = proof_parts(routine, seed)
        self.blocks = []  # (columns, indices, expected, counted)
        first = 0
        for columns in case_sets.batches(parts, PROOF_BLOCK):
            expected, counted = answered(routine, columns, self.baseline.runner.memory_values)
            n = len(columns[0])
            self.blocks.append((columns, np.arange(first, first + n, dtype=np.int64), expected, counted))
            first += n
        self.reference_cycles: list | None = None

    def prove(self, code: bytes, at: int) -> Proof:
        proof = Proof(self.kind, self.space, engine="batch")
        lows, highs, total, counted_all = [], [], 0, 0
        per_block = []
        for columns, indices, expected, counted in self.blocks:
            base = self.baseline.run(code, at, columns, indices)
            varied = self.random.run(code, at, columns, indices)
            proof.calls += 2 * len(indices)
            ok = outputs_equal(base, expected) & outputs_equal(varied, expected) & (base.cycles == varied.cycles)
            if self.preserved:
                for name, outcome in (("baseline", base), ("random", varied)):
                    kept = self.kept.setdefault((int(indices[0]), name), outcome.outputs[-self.preserved:])
                    ok &= outputs_equal(outcome, [None] * len(self.routine.outputs) + list(kept), skip=True)
            bad = np.flatnonzero(counted & ~ok)
            if len(bad):
                i = int(bad[0])
                proof.passed = False
                proof.counterexample = ([c[i:i + 1] for c in columns], [e[i:i + 1] for e in expected], int(indices[i]))
                return proof
            cycles = base.cycles[counted]
            per_block.append(base.cycles.copy())
            proof.cases += int(counted.sum())
            counted_all += len(cycles)
            if len(cycles):
                lows.append(int(cycles.min()))
                highs.append(int(cycles.max()))
                total += int(cycles.sum())
        if self.reference_cycles is not None:
            proof.slower = any(bool(((mine > theirs) & block[3]).any())
                               for mine, theirs, block in zip(per_block, self.reference_cycles, self.blocks))
        proof.cycles = {"min": min(lows) if lows else None, "max": max(highs) if highs else None,
                        "mean": total / counted_all if counted_all else None}
        proof.per_case = per_block
        if self.kind == "sampled":
            proof.note = "random and boundary cases only"
        return proof
