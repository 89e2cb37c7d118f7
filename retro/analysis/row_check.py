"""A spec's expected rows (retro.routines.rows), run on the check's engine and compared.

Each row's call must give the outputs the row states, its exact `cycles` and stay within its
`max_cycles`; what it gives is compared with the row only, never with the reference (a row the
reference disagrees with makes one of the two fail; a wrong row shows the reference's answer, to
say which). Rows run before the generated cases, as a
part of the check named "rows": they count among its cases and in its cycle figures (inside the
domain), and on `Machine` every call is held against the timing model. On the batched core the rows
run in one batch and, as every part, the first AGREEMENT_PER_PART of them also on `Machine`, which
must agree call for call. As in the rest of the check, the first call that does not return (BRK,
JAM, a runaway) stops it: the rows after it are not checked, on either engine, so both engines give
the same report.

A spec of rows only has no reference: its static bounds are computed when the routine needs no
loop bounds (or the spec gives them); otherwise the report says why they are unknown, in place of
refusing the spec for want of loop bounds it need not give.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from retro.analysis.check.engines import (AGREEMENT_PER_PART, BATCH_LANES, CallBlock, SceneStart, run_on_batched_core,
                                         run_on_machine, runner_for)
from retro.analysis.check.reference import reference_answers
from retro.analysis.check.results import Failure, describe_case, describe_outputs, inputs_by_name
from retro.analysis.check.tally import Tally, count_block
from retro.analysis.check.verdicts import static_bounds
from retro.analysis.coverage_model import CodeCoverage
from retro.cpu.flow import Bounds
from retro.errors import InputError
from retro.routines.cases import cases_to_columns
from retro.routines.rows import Row
from retro.routines.outputs import describe_value, row_of
from retro.routines.runner import RoutineRunner
from retro.routines.spec import Routine

ROWS_SHOWN = 10  # failing rows listed in the text report (JSON lists every one)


@dataclass(frozen=True)
class RowOutcome:
    """What one row's call gave and how it differs from the row (no problems: the row holds)."""

    row: Row
    outputs: tuple | None  # None: the call did not return, or was not run
    cycles: int | None
    problems: tuple[str, ...] = ()
    stopped: bool = False  # the call did not return (a run error, counted with the check's run errors)
    checked: bool = True  # False: an earlier row's call stopped the check
    reference: tuple | None = None  # a wrong row of a spec with a reference: what the reference answers

    @property
    def holds(self) -> bool:
        return self.checked and not self.problems


@dataclass
class RowsCheck:
    outcomes: list[RowOutcome]
    static_note: str = ""  # a spec of rows only: why the static bounds are unknown
    agreement: Tally | None = field(default=None, repr=False)

    @property
    def failing(self) -> list[RowOutcome]:
        """Rows checked and found wrong (a call that stopped included)."""
        return [o for o in self.outcomes if o.problems and o.checked]

    @property
    def unchecked(self) -> list[RowOutcome]:
        return [o for o in self.outcomes if not o.checked]

    @property
    def wrong(self) -> int:
        """Rows whose call returned something other than stated (a call that stopped is a run error)."""
        return sum(1 for o in self.failing if not o.stopped)


@dataclass(frozen=True)
class _Call:
    outputs: tuple | None
    cycles: int | None
    cpu_cycles: int | None = None  # Machine only: cycles without stalls, and what the timing model says
    modelled: int | None = None
    error: str = ""


def _calls_of(block: CallBlock, timed: bool) -> list[_Call]:
    """A block's calls as the rows read them: each returned call, then the one that stopped it."""
    calls = []
    for i in range(block.returned):
        cycles = int(block.cycles[i])
        calls.append(_Call(block.row(i), cycles, cycles - int(block.stolen[i]), int(block.modelled[i]))
                     if timed else _Call(block.row(i), cycles))
    if block.stop is not None:
        calls.append(_Call(None, None, error=block.stop_message))
    return calls


def check_rows(spec: str, seed: int, start: SceneStart | None, batched: bool) -> tuple[RowsCheck, Tally]:
    """Run the rows of the routine `spec` names; the rows' verdicts, and their part of the check's
    totals (cases, cycles, timing-model mismatches, run errors, the first failure). On the batched
    core, `RowsCheck.agreement` holds the calls also run on Machine."""
    runner = runner_for(spec, seed, start)
    routine = runner.routine
    rows = routine.rows
    totals = Tally()
    if batched:
        calls, agreement, totals.code_coverage = _batched(runner, rows)
    else:
        block = run_on_machine(runner, [row.case for row in rows])
        calls, agreement, totals.code_coverage = _calls_of(block, timed=True), None, block.coverage
    outcomes = []
    for row, call in zip(rows, calls):
        outcomes.append(_outcome(row, call, routine))
        _count(totals, routine, row, call, timing_model=not batched)
        if outcomes[-1].problems and not call.error:
            totals.failure = totals.failure or Failure(row.case, "row", call.outputs, row.expected,
                                                       f"{row.label}: {'; '.join(outcomes[-1].problems)}")
    outcomes += [RowOutcome(row, None, None, checked=False) for row in rows[len(calls):]]
    if routine.reference is not None:  # say who is wrong, the row or the routine, when the row's outputs differ
        outcomes = [replace(o, reference=_reference_answer(runner, o.row))
                    if o.outputs is not None and o.outputs != _stated(o) else o for o in outcomes]
    return RowsCheck(outcomes, agreement=agreement), totals


def _stated(outcome: RowOutcome) -> tuple:
    """The call's outputs with the row's stated values in place (equal to them: the outputs hold)."""
    return tuple(got if want is None else want for want, got in zip(outcome.row.expected, outcome.outputs))


def _reference_answer(runner: RoutineRunner, row: Row) -> tuple | None:
    """The reference's answer for a row's inputs; None when it gives none (it may refuse inputs
    outside its domain: a row is not held to the domain)."""
    routine = runner.routine
    columns = cases_to_columns(routine, [row.case])
    calls = None
    if routine.world.recorded:  # the reference takes the mocks' calls: those of this row's call
        runner.run(row.case)
        calls = [runner.last_calls]
    answers, answered = reference_answers(routine, columns, [row.case], runner.memory_values, np.zeros(1, dtype=bool),
                                          calls)
    return row_of(answers, 0) if answered[0] else None


def _batched(runner: RoutineRunner, rows: tuple[Row, ...]) -> tuple[list[_Call], Tally, CodeCoverage]:
    """The rows on the batched core in batches at most as wide as the check's, up to the first call
    that stops; the first AGREEMENT_PER_PART of them also on Machine, compared call for call; what
    they ran of the code."""
    routine = runner.routine
    agreement = Tally()
    calls: list[_Call] = []
    coverage = CodeCoverage()
    for first in range(0, len(rows), BATCH_LANES):
        cases = [row.case for row in rows[first:first + BATCH_LANES]]
        batch = run_on_batched_core(runner, cases_to_columns(routine, cases))
        coverage = coverage.merge(batch.coverage)
        compared = min(batch.calls, AGREEMENT_PER_PART - first)
        if compared > 0:  # Machine's calls held against the timing model and the batched core's, as any part's
            machine = run_on_machine(runner, cases[:compared], coverage=False)
            agreement.merge(count_block(routine, machine, cases_to_columns(routine, cases[:compared]), cases[:compared],
                                        runner.memory_values, against=batch,
                                        row_keys=[row.key for row in rows[first:first + compared]]))
        calls += _calls_of(batch, timed=False)
        if batch.stop is not None:
            break
    return calls, agreement, coverage


def _outcome(row: Row, call: _Call, routine: Routine) -> RowOutcome:
    if call.error:
        return RowOutcome(row, None, None, (call.error,), stopped=True)
    problems = [f"{port.name}: expected {describe_value(port, want)}, got {describe_value(port, got)}"
                for port, want, got in zip(routine.outputs, row.expected, call.outputs)
                if want is not None and want != got]
    if row.cycles is not None and call.cycles != row.cycles:
        problems.append(f"cycles: expected {row.cycles}, got {call.cycles}")
    if row.max_cycles is not None and call.cycles > row.max_cycles:
        problems.append(f"cycles: {call.cycles} is over max_cycles {row.max_cycles}")
    return RowOutcome(row, call.outputs, call.cycles, tuple(problems))


def _count(totals: Tally, routine: Routine, row: Row, call: _Call, timing_model: bool) -> None:
    """The row's call in the check's totals, as the tally counts a generated case (retro.analysis.check.tally)."""
    totals.cases += 1
    if call.error:
        totals.run_errors += 1
        totals.examples.append(f"{routine.name}({describe_case(routine, row.case)}): {row.key}: {call.error}")
        totals.failure = totals.failure or Failure(row.case, "run", message=f"{row.key}: {call.error}")
        return
    if timing_model and call.modelled != call.cpu_cycles:
        totals.cycle_mismatches += 1
        message = f"measured {call.cpu_cycles} cycles, the timing model says {call.modelled}"
        totals.failure = totals.failure or Failure(row.case, "cycles", call.outputs, None, f"{row.key}: {message}")
        totals.examples.append(f"{routine.name}({describe_case(routine, row.case)}): {row.key}: {message}")
    if not routine.in_domain(row.case):  # the cycle figures are the domain's, as for generated cases
        return
    cycles = call.cycles
    cpu = call.cpu_cycles if call.cpu_cycles is not None else cycles
    totals.merge(Tally(cycles_min=cycles, cycles_max=cycles, min_case=row.case, max_case=row.case, cycles_sum=cycles,
                       cycles_count=1, cpu_min=cpu, cpu_max=cpu, stolen_max=cycles - cpu))  # the one way to add a call


def rows_only_static(routine: Routine, runner: RoutineRunner) -> tuple[Bounds | None, str]:
    """The static bounds of a spec without a reference, or None and why they are unknown."""
    try:
        return static_bounds(routine, runner), ""
    except InputError as exc:
        reason = str(exc).removeprefix(f"{routine.spec_path}: ").removeprefix("static analysis: ")
        return None, reason.split(" ([cycles] static = false")[0]


# ---- reports ---------------------------------------------------------------------------------------

def rows_record(routine: Routine, rows: RowsCheck) -> dict:
    """The rows' part of `retro check --json`: counts, and every failing row with what it stated."""
    return {"rows": len(rows.outcomes), "held": sum(1 for o in rows.outcomes if o.holds),
            "failed": len(rows.failing), "not_checked": [o.row.index for o in rows.unchecked],
            "static_note": rows.static_note or None, "failures": [_failure_record(routine, o) for o in rows.failing]}


def _failure_record(routine: Routine, outcome: RowOutcome) -> dict:
    row = outcome.row
    return {"row": row.index, "note": row.note or None, "inputs": inputs_by_name(routine, row.case),
            "expected": _by_name(routine, row.expected), "outputs": _by_name(routine, outcome.outputs),
            "cycles": outcome.cycles, "expected_cycles": row.cycles, "max_cycles": row.max_cycles,
            "reference": _by_name(routine, outcome.reference), "problems": list(outcome.problems)}


def _by_name(routine: Routine, values: tuple | None) -> dict | None:
    """Output values by name (tables as lists), leaving out those a row does not state (None)."""
    if values is None:
        return None
    return {port.name: list(value) if port.table else value
            for port, value in zip(routine.outputs, values) if value is not None}


def rows_lines(routine: Routine, rows: RowsCheck) -> list[str]:
    """The rows' lines of the text report: a count, then each failing row (inputs, stated, got)."""
    failing, unchecked = rows.failing, rows.unchecked
    lines = [f"  rows: {len(rows.outcomes)}, {len(rows.outcomes) - len(failing) - len(unchecked)} hold"
             + (f", {len(failing)} fail" if failing else "")
             + (f", {len(unchecked)} not checked (after the call of {failing[-1].row.key} stopped)"
                if unchecked else "")]
    if rows.static_note:
        lines.append(f"  static bounds unknown (a spec of rows only): {rows.static_note}")
    for outcome in failing[:ROWS_SHOWN]:
        row = outcome.row
        stated = describe_outputs(routine, row.expected)
        got = describe_outputs(routine, outcome.outputs) if outcome.outputs is not None else "-"
        lines.append(f"  ROW {row.label}: {describe_case(routine, row.case)}"
                     + (f" -> expected {stated}, got {got}" if stated and outcome.outputs is not None else "")
                     + f": {'; '.join(outcome.problems)}"
                     + (f" (the reference says {describe_outputs(routine, outcome.reference)})"
                        if outcome.reference is not None else ""))
    if len(failing) > ROWS_SHOWN:
        lines.append(f"  ... {len(failing) - ROWS_SHOWN} more failing rows (--json lists every one)")
    return lines


def merged_agreement(agreement: Tally | None, rows: RowsCheck | None) -> Tally | None:
    """The check's engine agreement with the rows' calls included (batched core only)."""
    if rows is None or rows.agreement is None or agreement is None:
        return agreement
    merged = Tally()
    merged.merge(rows.agreement)
    merged.merge(agreement)
    return merged

