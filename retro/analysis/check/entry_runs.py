"""Entry-state runs: a sample of a check's cases run again with everything the spec leaves arbitrary
on entry (registers and flags no input or `[entry]` sets, untouched memory) set to all ones and to
random values (retro.routines.entry), on the engine that runs the check; a case whose outputs or
cycles change (inside the domain) is a failure, and the first such case of each variant is run again
on Machine with one thing varied at a time to name what the routine depends on.

Which cases are rerun is a function of their index in the check (every `every`-th), and their random
state a function of (seed, index): both engines, any block size and any number of workers rerun the
same cases with the same state and reach the same verdict.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.cpu.batch import LaneError
from retro.errors import RunError
from retro.routines.batch_runs import BatchOutcome
from retro.routines.cases import case_of, in_domain
from retro.routines.entry import VARIANTS, advice, memory_advice, stack_advice, variant_stack, variant_values
from retro.routines.places import FLAGS
from retro.routines.runner import RoutineRunner

ENTRY_SAMPLE = 2_000  # cases rerun (in each variant) when a check plans more; fewer: all of them
SWEEP_EVERY = 64  # with a sweep (its count unknown beforehand), at most one case in this many is rerun


@dataclass(frozen=True)
class VariantRun:
    """What the rerun cases of a block did in one variant: per output an array, cycles, and which
    calls did not return (their outputs and cycles mean nothing)."""

    outputs: list
    cycles: np.ndarray
    stopped: np.ndarray
    messages: dict  # position among the rerun cases -> why the call stopped

    def head(self, count: int) -> "VariantRun":
        """The first `count` rerun cases."""
        return VariantRun([o[:count] for o in self.outputs], self.cycles[:count], self.stopped[:count], self.messages)


@dataclass(frozen=True)
class EntryBlock:
    """A block's rerun cases: their positions in the block, the block's first case's index in the
    check, and per variant what they did."""

    first: int
    positions: np.ndarray
    runs: dict  # variant -> VariantRun


@dataclass
class EntryFinding:
    """The first case of a variant whose outputs or cycles changed, and what it depends on."""

    variant: str
    index: int  # the case's place in the check
    case: tuple
    baseline: tuple  # (outputs, cycles) as the check ran it
    varied: tuple  # (outputs, cycles), or (None, why the call stopped)
    needs: tuple[str, ...] | None = None  # one line per thing the routine depends on (None: not yet named)


def entry_every(planned: int, exhaustive: bool, everything: int, sweep: bool = False) -> int:
    """Every how many cases one is rerun: all of a check of at most ENTRY_SAMPLE cases (with
    --exhaustive: of at most `everything`), else a sample of about ENTRY_SAMPLE; with a sweep, whose
    cases are not counted beforehand, at most one in SWEEP_EVERY."""
    every = 1 if planned <= ENTRY_SAMPLE or (exhaustive and planned <= everything) else -(-planned // ENTRY_SAMPLE)
    return max(every, SWEEP_EVERY) if sweep else every


ENTRY_COMPILED_RERUNS = 1_000_000  # planned reruns (all variants) from which a check on the compiled engine runs
# them there: loading its entry-state function costs 0.57 CPU s (numba's cache), about what the batched core
# takes for this many (250-670 ns a call: EntryBaseline). Not a sweep's (its count unknown): measured on
# aabb8's 1/256 slice (50 M calls, 790,000 reruns), the whole check took 2.5 CPU s more with them compiled
# (8.2-8.8 s against 5.6-6.0) although the reruns alone cost 2.2 ns a call of the sweep against 4.3


def rerun_engine(engine: str, planned: int, sweep: bool, every: int) -> str:
    """The engine of a check's entry-state reruns on an array engine: the compiled engine when the
    check runs on it and plans ENTRY_COMPILED_RERUNS of them or more, else the batched core."""
    if engine != "compiled" or not every or sweep:
        return "batch"
    return "compiled" if planned // every * len(VARIANTS) >= ENTRY_COMPILED_RERUNS else "batch"


def rerun_positions(first: int, n: int, every: int) -> np.ndarray:
    """Positions within a block (whose first case has index `first`) of the cases to rerun."""
    start = (-first) % every
    return np.arange(start, n, every, dtype=np.int64)


def entry_block_on_machine(variants: dict[str, RoutineRunner], cases: list[tuple], first: int, every: int,
                           seed: int) -> EntryBlock:
    positions = rerun_positions(first, len(cases), every)
    runs = {}
    for variant, runner in variants.items():
        state = runner.entry_state
        registers, bits = variant_values(state, variant, seed, positions + first)
        answers, cycles, stopped, messages = [], [], [], {}
        for k, position in enumerate(positions.tolist()):
            entry = ({name: int(v[k]) for name, v in registers.items()}, int(bits[k]), state.free_mask)
            try:
                answer, spent = runner.run(cases[position], entry=entry)
            except RunError as exc:
                answer, spent = None, -1
                messages[k] = str(exc)
            answers.append(answer)
            cycles.append(spent)
            stopped.append(answer is None)
        runs[variant] = VariantRun(_columns(runner, answers), np.asarray(cycles, dtype=np.int64),
                                   np.asarray(stopped, dtype=bool), messages)
    return EntryBlock(first, positions, runs)


@dataclass(frozen=True)
class EntryBaseline:
    """A block's rerun cases (those that returned) as the check's own run left them, held until they run
    with the entry state varied together with other blocks' (`run_baselines`): the batched core's cost
    per call falls with its lanes (aabb8: about 670 ns a call per variant on one block's 1,024 rerun
    cases, 250 ns from 4,096: benchmarks/compiled_speed.py), and the reruns are the same cases in the
    same states, so the verdicts are the same."""

    first: int  # the block's first case's index in the check
    positions: np.ndarray  # the rerun cases' positions in the block
    columns: list  # their inputs
    outputs: list  # their outputs in the check's own run
    cycles: np.ndarray
    compared: np.ndarray  # inside the domain: the cases whose change counts

    def case(self, k: int) -> tuple:
        return case_of(self.columns, k)


def entry_baseline(routine, outputs: list, cycles: np.ndarray, returned: int, columns: list, first: int,
                   every: int, inside: np.ndarray | None = None) -> EntryBaseline:
    """The rerun cases among a block's first `returned` calls (its cases `columns`, its first case's
    index `first`) with what the check's run gave for them; `inside`: which of the block's calls lie
    inside the domain, when the tally has it (else worked out for the rerun cases)."""
    positions = rerun_positions(first, returned, every)
    picked = slice(int(positions[0]) if len(positions) else returned, returned, every)  # the same cases as
    # `positions`, copied by stride rather than gathered (and copied: the block's arrays are not held)
    subset = [c[picked].copy() for c in columns]
    return EntryBaseline(first, positions, subset, [o[picked].copy() for o in outputs], cycles[picked].copy(),
                         in_domain(routine, subset) if inside is None else inside[picked].copy())


def joined_baselines(baselines: list[EntryBaseline]) -> EntryBaseline:
    """Blocks' baselines as one, their cases in the blocks' order: its `first` 0, its positions the cases'
    indexes in the check."""
    if len(baselines) == 1:
        one = baselines[0]
        return EntryBaseline(0, one.positions + one.first, one.columns, one.outputs, one.cycles, one.compared)
    return EntryBaseline(0, np.concatenate([b.positions + b.first for b in baselines]),
                         [np.concatenate(parts) for parts in zip(*(b.columns for b in baselines))],
                         [np.concatenate(parts) for parts in zip(*(b.outputs for b in baselines))],
                         np.concatenate([b.cycles for b in baselines]),
                         np.concatenate([b.compared for b in baselines]))


def run_baselines(variants: dict[str, RoutineRunner], baselines: list[EntryBaseline],
                  seed: int, engine: str = "batch") -> tuple[EntryBaseline, dict[str, VariantRun]]:
    """Every baseline's cases in every variant, all blocks' in one run per variant on `engine` ("batch",
    or "compiled": then its first CROSS_CHECKED cases, more for many blocks, on the batched core too,
    `_rerun`): the baselines joined into one (`joined_baselines`) and per variant its run over them, as
    runs of each block's cases alone would give them (a stopped call's message kept for the first of its
    block)."""
    joined = joined_baselines(baselines)
    sizes = [len(b.positions) for b in baselines]
    runs: dict[str, VariantRun] = {}
    if not len(joined.positions):
        return joined, runs
    for variant, runner in variants.items():
        state = runner.entry_state
        registers, bits = variant_values(state, variant, seed, joined.positions)
        outcome = _rerun(runner, variant, joined.columns, (registers, bits, state.free_mask), engine, joined.positions,
                         CROSS_CHECKED * max(1, len(baselines) // CROSS_CHECKED_BLOCKS))
        runs[variant] = _variant_run(outcome.outputs, outcome.cycles, outcome.error, sizes)
    return joined, runs


CROSS_CHECKED = 256  # of each compiled rerun, the cases also run on the batched core and compared (the engines
# stay cross-checked on varied entry states: the first 256 of each task's reruns) ...
CROSS_CHECKED_BLOCKS = 32  # ... and 256 more for each further 32 blocks a task holds (as many as tasks of 32 blocks
# check, whatever the task's size: run.LONG_SWEEP_FACTOR)


def _rerun(runner: RoutineRunner, variant: str, columns: list, entry: tuple, engine: str,
           indexes: np.ndarray, cross_checked: int) -> BatchOutcome:
    """The cases in one variant's entry state on `engine`; on the compiled engine the first `cross_checked`
    run on the batched core too, whose outputs, cycles and stops must be the same (a RunError if not)."""
    if engine != "compiled":
        return runner.run_batch(columns, entry=entry)
    outcome = runner.run_compiled(columns, entry)
    k = min(len(indexes), cross_checked)
    if not k:
        return outcome
    registers, bits, mask = entry
    sample = runner.run_batch([c[:k] for c in columns], entry=({n: v[:k] for n, v in registers.items()}, bits[:k], mask))
    stopped, also = outcome.error[:k] != 0, sample.error != 0
    differ = stopped != also
    for compiled, batched in zip(outcome.outputs, sample.outputs):
        unequal = compiled[:k] != batched
        differ |= (unequal.any(axis=1) if unequal.ndim == 2 else unequal) & ~stopped
    differ |= (outcome.cycles[:k] != sample.cycles) & ~stopped
    if differ.any():
        i = int(np.flatnonzero(differ)[0])
        raise RunError(f"the engines disagree on case {int(indexes[i])} run with the entry state varied ({variant}): "
                       f"compiled engine {_shown(outcome, i)}, batched core {_shown(sample, i)}")
    return outcome


def _shown(outcome: BatchOutcome, i: int) -> str:
    if outcome.error[i]:
        return f"stopped ({LaneError(int(outcome.error[i])).name})"
    return f"outputs {[o[i].tolist() for o in outcome.outputs]} in {int(outcome.cycles[i])} cycles"


def _variant_run(outputs: list, cycles: np.ndarray, error: np.ndarray, sizes: list[int]) -> VariantRun:
    """A variant's run of blocks' rerun cases (`sizes` of them each, in order), the message of the first
    stopped call of each block kept."""
    stopped = error != 0
    messages = {}
    if stopped.any():
        end = 0
        for size in sizes:
            first = np.flatnonzero(stopped[end:end + size])[:1]
            if len(first):
                k = end + int(first[0])
                messages[k] = f"the batched core stopped the call ({LaneError(int(error[k])).name})"
            end += size
    return VariantRun(outputs, cycles, stopped, messages)


def _columns(runner: RoutineRunner, answers: list) -> list[np.ndarray]:
    outputs = runner.routine.outputs
    n = len(answers)
    columns = []
    for k, port in enumerate(outputs):
        width = len(port.places) if port.table else None
        filler = (0,) * width if width else 0
        column = np.asarray([a[k] if a is not None else filler for a in answers], dtype=np.int64)
        columns.append(column.reshape((n, width) if width else (n,)))
    return columns


def changed_calls(outputs: list, cycles: np.ndarray, compared: np.ndarray, run: VariantRun) -> np.ndarray:
    """Which rerun cases (of those `compared`: returned in the check, inside the domain) changed, given
    their `outputs` and `cycles` in the check's own run."""
    changed = run.stopped.copy()
    for baseline, varied in zip(outputs, run.outputs):
        differ = baseline != varied
        changed |= differ.any(axis=1) if differ.ndim == 2 else differ
    changed |= cycles != run.cycles
    return changed & compared


# ---- naming what a changed case depends on ----------------------------------------------------------

def name_dependence(base: RoutineRunner, varied_image: bytes, finding: EntryFinding, seed: int) -> tuple[str, ...]:
    """Run the finding's case on Machine (`base`: a fresh runner of the baseline) with one part of
    the variant's entry state at a time: each register, each flag, then memory (halved until one
    address is left). The parts that alone change the call are named, each with what to do."""
    state = base.entry_state
    baseline_image = bytes(base.call_image)
    baseline_top, varied_top = base.machine.stack_top, variant_stack(finding.variant, seed)
    registers, bits = variant_values(state, finding.variant, seed, np.asarray([finding.index]))
    registers = {name: int(v[0]) for name, v in registers.items()}
    bits = int(bits[0])
    case = finding.case

    def outcome(entry, image: bytes, stack_top: int | None = None) -> tuple:
        base.reset_memory(image)
        base.machine.stack_top = baseline_top if stack_top is None else stack_top
        try:
            return base.run(case, entry=entry)
        except RunError:
            return (None, "stopped")
        finally:
            base.machine.stack_top = baseline_top

    reference = outcome(None, baseline_image)
    needs = []
    for name in state.free_registers:
        if registers[name] != state.registers[name] and outcome(({name: registers[name]}, 0, 0),
                                                               baseline_image) != reference:
            needs.append(advice(name.upper(), state.registers[name]))
    for name in state.free_flags:
        bit = FLAGS[name]
        if (bits & bit) != (state.flags & bit) and outcome(({}, bits & bit, bit), baseline_image) != reference:
            needs.append(advice(name, state.baseline_of(name)))
    if varied_top != baseline_top and outcome(None, baseline_image, varied_top) != reference:
        needs.append(stack_advice(baseline_top, varied_top))
    address = _memory_dependence(outcome, reference, baseline_image, varied_image)
    if address is not None:
        labels = {a: label for label, a in sorted(base.program.symbols.items(), key=lambda kv: -len(kv[0]))}
        if isinstance(address, int):
            needs.append(memory_advice(address, baseline_image[address], labels.get(address)))
        else:
            needs.append(f"reads memory in ${address[0]:04X}-${address[1]:04X} that nothing sets before the call: "
                         "declare it (an input, or a [memory] block), or write it before reading it")
    base.reset_memory(baseline_image)
    if not needs:
        varied = [n.upper() for n in state.free_registers] + list(state.free_flags) + ["S", "memory"]
        needs.append(f"changes only when several of {', '.join(varied)} change together: state what the routine "
                     "needs in [entry], or set it in the routine")
    return tuple(needs)


def _memory_dependence(outcome, reference, baseline_image: bytes, varied_image: bytes):
    """The address (or the range) of untouched memory whose variant byte alone changes the call."""
    base = np.frombuffer(baseline_image, dtype=np.uint8)
    varied = np.frombuffer(varied_image, dtype=np.uint8)
    candidates = np.flatnonzero(base != varied)

    def changes(addresses: np.ndarray) -> bool:
        image = base.copy()
        image[addresses] = varied[addresses]
        return outcome(None, image.tobytes()) != reference

    if not len(candidates) or not changes(candidates):
        return None
    while len(candidates) > 1:
        half = len(candidates) // 2
        low, high = candidates[:half], candidates[half:]
        if changes(low):
            candidates = low
        elif changes(high):
            candidates = high
        else:  # only bytes of both halves together change it
            return int(candidates[0]), int(candidates[-1])
    return int(candidates[0])


__all__ = ["ENTRY_COMPILED_RERUNS", "ENTRY_SAMPLE", "VARIANTS", "EntryBaseline", "EntryBlock", "EntryFinding", "VariantRun", "changed_calls",
           "entry_baseline", "entry_block_on_machine", "entry_every", "joined_baselines", "name_dependence",
           "rerun_engine", "rerun_positions", "run_baselines"]
