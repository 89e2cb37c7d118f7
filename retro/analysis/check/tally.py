"""The one tally of a check: what a `CallBlock` of either engine shows against the reference's
answers and the domain, counted the same way for both. What counts as a mismatch is written here:

- result: inside the domain, an output differs from the reference's answer;
- cycles: the timing model's count differs from the cycles the CPU ran (Machine only);
- engine: Machine and the batched core differ on a call (outputs, cycles, or whether it returned);
- run: a call did not return (BRK, JAM, a runaway), which ends the check;
- row: a spec's expected row whose call gave other outputs or cycles than the row states (the rows
  are compared with what they state, not with the reference: retro.analysis.row_check, which adds
  its calls' cycle figures to the same Tally; on the batched core the rows' calls also run on
  Machine are counted here, `count_block(..., row_keys=...)`: held to the timing model and to the
  other engine only).

Cases outside the domain are counted (per condition they break, and how many of them the routine
gets wrong) but are no mismatch. To add a statistic: a field of `Tally`, its line in `Tally.merge`,
its count in `count_block`, and its key in the report (retro/commands/check.py: check_record).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from retro.analysis.check.engines import CallBlock, disagreements
from retro.analysis.check.entry_runs import EntryBaseline, EntryBlock, EntryFinding, changed_calls, run_baselines
from retro.analysis.check.reference import reference_answers
from retro.analysis.check.results import Failure, describe_case, describe_outputs
from retro.analysis.coverage_model import CodeCoverage
from retro.routines import cases as case_sets
from retro.routines.outputs import row_of
from retro.routines.spec import Routine

EXAMPLES_KEPT = 5
_KIND_ORDER = {"engine": 0, "cycles": 1, "result": 2}  # of one call: as Machine's check met them


@dataclass
class Tally:
    """What a block of calls showed, merged over the blocks into a routine's totals. A statistic is
    added here: a field, its line in `merge`, and its count in `count_block` below."""

    cases: int = 0
    result_mismatches: int = 0
    cycle_mismatches: int = 0
    run_errors: int = 0
    outside: int = 0
    outside_wrong: int = 0
    constraint_cases: dict[str, int] = field(default_factory=dict)
    constraint_wrong: dict[str, int] = field(default_factory=dict)
    cycles_min: int | None = None
    cycles_max: int | None = None
    min_case: tuple | None = None
    max_case: tuple | None = None
    cycles_sum: int = 0
    cycles_count: int = 0
    cpu_min: int | None = None  # cycles the CPU ran (stalls excluded): what the static bounds bound
    cpu_max: int | None = None
    stolen_max: int = 0  # with a scene: the most cycles one call lost to Bad Lines and sprite DMA
    engine_cases: int = 0  # calls run on both engines and compared
    engine_mismatches: int = 0
    fallbacks: dict[int, int] = field(default_factory=dict)  # compiled engine: calls run on the batched core, by reason
    examples: list[str] = field(default_factory=list)
    outside_examples: list[str] = field(default_factory=list)
    failure: Failure | None = None
    code_coverage: CodeCoverage = field(default_factory=CodeCoverage)  # what the calls ran of the code
    entry_cases: int = 0  # cases rerun with the entry state varied (retro.analysis.check.entry_runs)
    entry_changed: int = 0  # of them, those whose outputs or cycles changed in a variant
    entry_first: dict[str, EntryFinding] = field(default_factory=dict)  # variant -> its first changed case

    def merge(self, other: "Tally") -> None:
        self.cases += other.cases
        self.result_mismatches += other.result_mismatches
        self.cycle_mismatches += other.cycle_mismatches
        self.run_errors += other.run_errors
        self.outside += other.outside
        self.outside_wrong += other.outside_wrong
        for target, source in ((self.constraint_cases, other.constraint_cases),
                               (self.constraint_wrong, other.constraint_wrong)):
            for key, value in source.items():
                target[key] = target.get(key, 0) + value
        if other.cycles_count:
            if self.cycles_min is None or other.cycles_min < self.cycles_min:
                self.cycles_min, self.min_case = other.cycles_min, other.min_case
            if self.cycles_max is None or other.cycles_max > self.cycles_max:
                self.cycles_max, self.max_case = other.cycles_max, other.max_case
        self.cycles_sum += other.cycles_sum
        self.cycles_count += other.cycles_count
        if other.cpu_min is not None:
            self.cpu_min = other.cpu_min if self.cpu_min is None else min(self.cpu_min, other.cpu_min)
            self.cpu_max = other.cpu_max if self.cpu_max is None else max(self.cpu_max, other.cpu_max)
        self.stolen_max = max(self.stolen_max, other.stolen_max)
        self.engine_cases += other.engine_cases
        self.engine_mismatches += other.engine_mismatches
        for code, count in other.fallbacks.items():
            self.fallbacks[code] = self.fallbacks.get(code, 0) + count
        self.examples = (self.examples + other.examples)[:EXAMPLES_KEPT]
        self.outside_examples = (self.outside_examples + other.outside_examples)[:EXAMPLES_KEPT]
        self.failure = self.failure or other.failure
        self.code_coverage = self.code_coverage.merge(other.code_coverage)
        self.entry_cases += other.entry_cases
        self.entry_changed += other.entry_changed
        for variant, finding in other.entry_first.items():
            if variant not in self.entry_first or finding.index < self.entry_first[variant].index:
                self.entry_first[variant] = finding


@dataclass(frozen=True)
class _Calls:
    """A block's returned calls with what the tally needs of each: inputs, domain, answers."""

    routine: Routine
    block: CallBlock
    columns: list
    cases: list[tuple] | None
    holds: list[np.ndarray]  # per condition of the domain, the calls whose case meets it
    inside: np.ndarray
    expected: list[np.ndarray]
    answerable: np.ndarray
    equal: np.ndarray
    row_keys: Sequence[str] | None = None  # the calls are a spec's rows (these their keys): no reference
    everywhere: bool = True  # every call's case lies inside the domain
    all_equal: bool = True  # every call gave the reference's answer (or has none to compare: rows)

    def case(self, i: int) -> tuple:
        return self.cases[i] if self.cases is not None else case_sets.case_of(self.columns, i)

    def described(self, i: int) -> str:
        return f"{self.routine.name}({describe_case(self.routine, self.case(i))})"

    def keyed(self, i: int, message: str) -> str:
        """A message about call i, naming its row first when the calls are rows."""
        return message if self.row_keys is None else f"{self.row_keys[i]}: {message}"

    def expected_row(self, i: int) -> tuple | None:
        return row_of(self.expected, i) if self.answerable[i] else None


def count_block(routine: Routine, block: CallBlock, columns: list, cases: list[tuple] | None, memory: dict,
                against: CallBlock | None = None, entry: EntryBlock | None = None,
                row_keys: Sequence[str] | None = None, outside_wanted: int = EXAMPLES_KEPT) -> Tally:
    """Tally the calls of one block (either engine) against the reference's answers. `cases`: the
    block's cases as tuples when they are at hand (else made when the reference or a condition needs
    them); `against`: the batched core's block for the same calls, compared call for call; `entry`:
    the entry-state runs of some of its cases, compared with the block's own calls. `row_keys`: the
    calls are a spec's rows (retro.analysis.row_check), held to the timing model and to `against`
    only, never to the reference or the domain; every example and failure names the row.
    `outside_wanted`: how many examples of cases outside the domain the caller can still keep (a sweep
    task whose earlier blocks gave EXAMPLES_KEPT passes 0: the merge would drop these)."""
    return _count(routine, block, columns, cases, memory, against, entry, row_keys, outside_wanted)[0]


def count_array_block(routine: Routine, block: CallBlock, columns: list, memory: dict,
                      outside_wanted: int = EXAMPLES_KEPT) -> tuple[Tally, np.ndarray]:
    """count_block of an array engine's block, and which of its returned calls lie inside the domain
    (what the entry-state reruns of its cases compare: entry_runs.entry_baseline)."""
    tally, calls = _count(routine, block, columns, None, memory, outside_wanted=outside_wanted)
    return tally, calls.inside


def _count(routine: Routine, block: CallBlock, columns: list, cases: list[tuple] | None, memory: dict,
           against: CallBlock | None = None, entry: EntryBlock | None = None,
           row_keys: Sequence[str] | None = None, outside_wanted: int = EXAMPLES_KEPT) -> tuple[Tally, _Calls]:
    calls = _calls(routine, block, columns, cases, memory, row_keys)
    out = Tally()
    n = block.returned
    out.cases = n
    if block.coverage is not None:
        out.code_coverage = block.coverage
    out.fallbacks = dict(block.fallbacks or {})
    # the timing model and the static bounds know no stalls (an array engine without a scene has none: None)
    stalled = block.stolen is not None and bool(block.stolen[:n].any())
    cpu = block.cycles[:n] - block.stolen[:n] if stalled else block.cycles[:n]
    cycle_wrong = (np.flatnonzero(block.modelled[:n] != cpu) if block.modelled is not None
                   else np.zeros(0, dtype=np.int64))
    out.cycle_mismatches = len(cycle_wrong)
    engine_wrong: dict[int, str] = {}
    if against is not None:
        out.engine_cases = block.calls
        engine_wrong = disagreements(routine, block, against)
        out.engine_mismatches = len(engine_wrong)
    wrong_inside = np.zeros(0, dtype=np.int64)
    if row_keys is None:
        wrong_inside = _reference_figures(out, calls, outside_wanted)
        _cycle_figures(out, calls, cpu, stalled)
    _examples(out, calls, wrong_inside, cycle_wrong, cpu, engine_wrong)
    if entry is not None:
        _entry_figures(out, calls, entry)
    if block.stop is not None:  # the call that did not return ends the block, as it ends the check
        case = cases[n] if cases is not None else case_sets.case_of(columns, n)
        _stop(out, calls, case, engine_wrong.get(n))
    return out, calls


def _reference_figures(out: Tally, calls: _Calls, outside_wanted: int = EXAMPLES_KEPT) -> np.ndarray:
    """The returned calls against the reference and the domain: result mismatches inside it, the
    cases outside it (per condition they break, and those the routine gets wrong) with examples;
    the positions of the wrong calls inside the domain. A block whose cases all lie inside, or whose
    answers are all right, skips the passes whose counts it knows to be 0."""
    routine = calls.routine
    n = calls.block.returned
    if calls.all_equal:
        wrong_inside = np.zeros(0, dtype=np.int64)
    else:
        wrong_inside = np.flatnonzero(~calls.equal if calls.everywhere else calls.inside & ~calls.equal)
    out.result_mismatches = len(wrong_inside)
    wrong_outside = None
    if not calls.everywhere:
        out.outside = n - int(np.count_nonzero(calls.inside))
        if not calls.all_equal:
            wrong_outside = ~calls.inside & ~calls.equal & calls.answerable
            out.outside_wrong = int(np.count_nonzero(wrong_outside))
    for condition, held in zip(routine.domain, calls.holds):
        out.constraint_cases[condition.text] = 0 if calls.everywhere else n - int(np.count_nonzero(held))
        out.constraint_wrong[condition.text] = (int(np.count_nonzero(wrong_outside & ~held)) if out.outside_wrong
                                                else 0)
    if outside_wanted > 0 and out.outside_wrong:
        _outside_examples(out, calls, wrong_outside, outside_wanted)
    return wrong_inside


def _calls(routine: Routine, block: CallBlock, columns: list, cases: list[tuple] | None, memory: dict,
           row_keys: Sequence[str] | None = None) -> _Calls:
    """The block's returned calls with their domain and answers, in as few passes over the block as it
    allows (most blocks: every case inside, every answer right)."""
    n = block.returned
    if columns and len(columns[0]) != n:  # (most blocks: every call returned)
        columns = [c[:n] for c in columns]
    if cases is not None:
        cases = cases[:n]
    if row_keys is not None:  # rows: what they state is compared elsewhere; no reference, no domain
        nothing = np.zeros(n, dtype=bool)
        return _Calls(routine, block, columns, cases, [], ~nothing, [], nothing, ~nothing, row_keys)
    if cases is None and (not routine.reference_arrays or any(c.test_columns is None for c in routine.domain)):
        cases = case_sets.columns_to_cases(columns)
    holds = [condition.over(columns, cases) for condition in routine.domain]
    inside = np.ones(n, dtype=bool)
    for held in holds:
        inside &= held
    if n:
        expected, answerable = reference_answers(routine, columns, cases, memory, inside,
                                                 None if block.mock_calls is None else block.mock_calls[:n])
    else:
        expected, answerable = [np.zeros((0, *o.shape[1:]), dtype=np.int64) for o in block.outputs], inside
    equal = None
    for got, wanted in zip(block.outputs, expected):
        same = got[:n] == wanted
        same = same.all(axis=1) if same.ndim == 2 else same
        equal = same if equal is None else equal & same
    if equal is None:
        equal = np.ones(n, dtype=bool)
    return _Calls(routine, block, columns, cases, holds, inside, expected, answerable, equal,
                  everywhere=bool(inside.all()), all_equal=bool(equal.all()))


def _cycle_figures(out: Tally, calls: _Calls, cpu: np.ndarray, stalled: bool) -> None:
    """Fastest and slowest calls inside the domain (the first on a tie), the sum, CPU-only extremes."""
    block, n = calls.block, calls.block.returned
    cycles = block.cycles[:n]
    if calls.everywhere:  # (most blocks: no gather, no mask)
        count = n
    else:
        count = int(np.count_nonzero(calls.inside))
    if not count:
        return
    low, high = _first_extreme(cycles, calls, np.argmin, _NEVER_LOW), _first_extreme(cycles, calls, np.argmax, -1)
    out.cycles_min, out.min_case = int(cycles[low]), calls.case(low)
    out.cycles_max, out.max_case = int(cycles[high]), calls.case(high)
    out.cycles_sum = int(cycles.sum()) if calls.everywhere else int(cycles.sum() - cycles[~calls.inside].sum())
    out.cycles_count = count
    if not stalled:  # (no scene): the CPU's cycles are the cycles
        out.cpu_min, out.cpu_max, out.stolen_max = out.cycles_min, out.cycles_max, 0
        return
    positions = np.arange(n) if calls.everywhere else np.flatnonzero(calls.inside)
    inside_cpu = cpu[:n][positions]
    out.cpu_min, out.cpu_max = int(inside_cpu.min()), int(inside_cpu.max())
    out.stolen_max = int(block.stolen[:n][positions].max())


_NEVER_LOW = np.iinfo(np.int64).max  # no call runs this many cycles: what a case outside the domain counts as


def _first_extreme(cycles: np.ndarray, calls: _Calls, arg, never: int) -> int:
    """The position of the first call inside the domain with the fewest (np.argmin) or most (np.argmax)
    cycles: the block's own first extreme when that call lies inside (then no call before it ties),
    else the extreme with the calls outside counted as `never`."""
    first = int(arg(cycles))
    if calls.everywhere or calls.inside[first]:
        return first
    return int(arg(np.where(calls.inside, cycles, never)))


def _examples(out: Tally, calls: _Calls, wrong_inside: np.ndarray, cycle_wrong: np.ndarray, cpu: np.ndarray,
              engine_wrong: dict[int, str]) -> None:
    """The first examples and the first failure among the returned calls, in call order."""
    n = calls.block.returned
    events = [(i, "engine") for i in sorted(engine_wrong) if i < n][:EXAMPLES_KEPT]
    events += [(int(i), "cycles") for i in cycle_wrong[:EXAMPLES_KEPT]]
    events += [(int(i), "result") for i in wrong_inside[:EXAMPLES_KEPT]]
    events.sort(key=lambda event: (event[0], _KIND_ORDER[event[1]]))
    for i, kind in events:
        answer, expected = calls.block.row(i), calls.expected_row(i)
        if kind == "engine":
            message = calls.keyed(i, engine_wrong[i])
            example, failure = message, Failure(calls.case(i), "engine", answer, None, message)
        elif kind == "cycles":
            message = calls.keyed(i, f"measured {int(cpu[i])} cycles, the timing model says {int(calls.block.modelled[i])}")
            example, failure = message, Failure(calls.case(i), "cycles", answer, expected, message)
        else:
            example = (f"returned {describe_outputs(calls.routine, answer)}, "
                       f"reference {describe_outputs(calls.routine, expected)}")
            failure = Failure(calls.case(i), "result", answer, expected)
        if len(out.examples) < EXAMPLES_KEPT:
            out.examples.append(f"{calls.described(i)}: {example}")
        out.failure = out.failure or failure


def _outside_examples(out: Tally, calls: _Calls, wrong_outside: np.ndarray, wanted: int) -> None:
    routine = calls.routine
    for i in np.flatnonzero(wrong_outside)[:min(wanted, EXAMPLES_KEPT)].tolist():
        broken = [c.text for c, held in zip(routine.domain, calls.holds) if not held[i]]
        out.outside_examples.append(
            f"{calls.described(i)}: returned {describe_outputs(routine, calls.block.row(i))}, "
            f"reference {describe_outputs(routine, calls.expected_row(i))} (outside: {', '.join(broken)})")


def _entry_figures(out: Tally, calls: _Calls, entry: EntryBlock) -> None:
    """The rerun cases whose outputs or cycles changed with the entry state (inside the domain, among
    the calls that returned), and each variant's first."""
    n = calls.block.returned
    positions = entry.positions[entry.positions < n]
    baseline = EntryBaseline(entry.first, positions, [], [o[positions] for o in calls.block.outputs],
                             calls.block.cycles[positions], calls.inside[positions])
    _entry_counts(out, baseline, entry.runs, lambda k: calls.case(int(positions[k])))


def entry_tally(variants: dict, baselines: list[EntryBaseline], seed: int, engine: str = "batch") -> Tally:
    """The entry-state figures of blocks whose rerun cases were held (`entry_baseline`), run together
    on `engine` (entry_runs.run_baselines) and counted together: the figures each block's own
    `count_block(..., entry=...)` would give, merged."""
    out = Tally()
    if baselines:
        joined, runs = run_baselines(variants, baselines, seed, engine)
        _entry_counts(out, joined, runs, joined.case)
    return out


def _entry_counts(out: Tally, baseline: EntryBaseline, runs: dict, case_at) -> None:
    """The rerun cases compared, those changed in any variant, and per variant its changed case with the
    lowest index in the check (Tally.merge's rule)."""
    compared = baseline.compared
    out.entry_cases = int(compared.sum())
    any_changed = np.zeros(len(compared), dtype=bool)
    for variant, run in runs.items():
        run = run.head(len(compared))
        changed = changed_calls(baseline.outputs, baseline.cycles, compared, run)
        any_changed |= changed
        at = np.flatnonzero(changed)
        if len(at):
            k = int(at[np.argmin(baseline.positions[at])])
            varied = ((None, run.messages.get(k, "the call did not return")) if run.stopped[k]
                      else (row_of(run.outputs, k), int(run.cycles[k])))
            out.entry_first[variant] = EntryFinding(variant, baseline.first + int(baseline.positions[k]), case_at(k),
                                                    (row_of(baseline.outputs, k), int(baseline.cycles[k])), varied)
    out.entry_changed = int(any_changed.sum())


def _stop(out: Tally, calls: _Calls, case: tuple, engine_message: str | None) -> None:
    """The call that did not return: a run error (on Machine too), or an engine disagreement."""
    block = calls.block
    described = f"{calls.routine.name}({describe_case(calls.routine, case)})"
    out.cases += 1
    out.run_errors += 1
    if block.stop == "engine":
        out.engine_cases += 1
        out.engine_mismatches += 1
    for kind, message in ((block.stop, block.stop_message), ("engine", engine_message)):
        if message is None:
            continue
        message = calls.keyed(block.returned, message)
        if len(out.examples) < EXAMPLES_KEPT:
            out.examples.append(f"{described}: {message}")
        out.failure = out.failure or Failure(case, kind, message=message)
