"""What a check found: the first failure, the parts of the case plan, and a routine's whole check
(its totals are a retro.analysis.check.tally.Tally)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from retro.analysis.coverage_model import CodeCoverage
from retro.cpu.flow import Bounds
from retro.routines.outputs import describe_value
from retro.routines.runner import RasterStart
from retro.routines.size import Size
from retro.routines.spec import Routine

if TYPE_CHECKING:
    from retro.analysis.check.search import SearchResult
    from retro.analysis.check.tally import Tally
    from retro.analysis.row_check import RowsCheck

EXAMPLES_KEPT = 5


@dataclass
class Failure:
    """The first failing case of a chunk: what the routine and the reference said."""

    case: tuple
    kind: str  # "result", "cycles", "run", "engine" or "row"
    outputs: tuple | None = None
    expected: tuple | None = None
    message: str = ""


@dataclass(frozen=True)
class PartRun:
    name: str
    cases: int
    total: int  # cases of the space the part stands for (exhaustive: the whole product)
    inside: int | None = None  # exhaustive: the combinations inside the domain, when only those run


@dataclass
class RoutineCheck:
    routine: Routine
    size: Size
    static: Bounds | None
    totals: Tally
    bounds_violations: list[str]
    budget_violations: list[str] = field(default_factory=list)
    parts: list[PartRun] = field(default_factory=list)
    trace: list[str] = field(default_factory=list)  # the first failing case's instructions
    start: RasterStart | None = None  # with --scene: the beam position every call started at
    engine: str = "scalar"  # which engine ran the cases: "scalar" (Machine), "batch" or "compiled"
    engine_note: str = ""  # why Machine ran a check the batched core was asked for or would have run
    engine_reason: str = ""  # why that engine (the rule, the option, the scene, or why the compiled engine was refused)
    compile_seconds: float | None = None  # the compiled engine: building or loading the routine's code
    agreement: Tally | None = None  # with the batched core: the cases also run on Machine
    rows: RowsCheck | None = None  # the spec's expected rows (retro.analysis.row_check)
    seconds: float = 0.0  # wall time of the check (JUnit reports)
    code_coverage: CodeCoverage | None = None  # what the cases ran of the code (retro.analysis.check.coverage)
    search: SearchResult | None = None  # the coverage-guided search (retro.analysis.check.search)
    entry_every: int = 0  # every how many cases one ran again with the entry state varied (0: none did)
    random_draw: object = None  # retro.routines.cases.DomainDraw: how the random part met the domain (or None)

    @property
    def mismatches(self) -> int:
        t = self.totals
        found = (t.result_mismatches + t.cycle_mismatches + t.run_errors + len(self.bounds_violations)
                 + len(self.budget_violations))
        if self.agreement is not None:  # its result mismatches and run errors are among the batch's own
            found += self.agreement.engine_mismatches + self.agreement.cycle_mismatches
        if self.rows is not None:  # rows whose call returned something else (a stopped call is a run error)
            found += self.rows.wrong
        return found + t.entry_changed  # cases whose outputs or cycles change with the entry state

    @property
    def mean(self) -> float:
        return self.totals.cycles_sum / self.totals.cycles_count if self.totals.cycles_count else 0.0

    @property
    def worst_reached(self) -> bool:
        return self.static is not None and self.totals.cpu_max == self.static.worst

    @property
    def best_reached(self) -> bool:
        return self.static is not None and self.totals.cpu_min == self.static.best

    @property
    def every_input_run(self) -> bool:
        """Whether the cases ran the whole input space (an exhaustive part over every input, complete):
        then a static bound no case reached cannot be reached."""
        space = self.routine.input_space()
        return set(self.routine.exhaustive) == set(self.routine.input_names) and any(
            p.name == "exhaustive" and p.cases == p.total == space for p in self.parts)

    def domain_report(self) -> list[str]:
        t = self.totals
        lines = [f"inside the domain: {t.cases - t.outside} cases, {t.result_mismatches} wrong"]
        for condition in self.routine.domain:
            violating = t.constraint_cases.get(condition.text, 0)
            wrong = t.constraint_wrong.get(condition.text, 0)
            verdict = "needed" if wrong else "not shown to be needed by these cases"
            lines.append(f"  condition {condition.text}: {violating} cases break it, {wrong} of them wrong: {verdict}")
        return lines



def entry_needs(check: RoutineCheck) -> list[str]:
    """What the routine depends on, one line each, from every variant's first changed case."""
    needs: list[str] = []
    for finding in check.totals.entry_first.values():
        needs += [line for line in finding.needs or () if line not in needs]
    return needs


def inputs_by_name(routine: Routine, case: tuple) -> dict:
    return {port.name: list(value) if port.table else value for port, value in zip(routine.inputs, case)}


def describe_case(routine: Routine, case: tuple) -> str:
    return ", ".join(f"{port.name}={describe_value(port, value)}" for port, value in zip(routine.inputs, case))


def describe_outputs(routine: Routine, values: tuple) -> str:
    return ", ".join(f"{port.name}={describe_value(port, value)}" for port, value in zip(routine.outputs, values)
                     if value is not None)  # None: an output an expected row does not state

