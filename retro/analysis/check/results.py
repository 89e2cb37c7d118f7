"""What a check found: the tally of a chunk of cases (merged into the routine's totals), the first
failure, the parts of the case plan, and a routine's whole check."""

from __future__ import annotations

from dataclasses import dataclass, field

from retro.cpu.flow import Bounds
from retro.routines.runner import RasterStart, Size, describe_value
from retro.routines.spec import Routine

EXAMPLES_KEPT = 5


@dataclass
class Failure:
    """The first failing case of a chunk: what the routine and the reference said."""

    case: tuple
    kind: str  # "result", "cycles" or "run"
    outputs: tuple | None = None
    expected: tuple | None = None
    message: str = ""


@dataclass
class ChunkResult:
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
    examples: list[str] = field(default_factory=list)
    outside_examples: list[str] = field(default_factory=list)
    failure: Failure | None = None

    def merge(self, other: "ChunkResult") -> None:
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
        self.examples = (self.examples + other.examples)[:EXAMPLES_KEPT]
        self.outside_examples = (self.outside_examples + other.outside_examples)[:EXAMPLES_KEPT]
        self.failure = self.failure or other.failure


@dataclass(frozen=True)
class PartRun:
    name: str
    cases: int
    total: int  # cases of the space the part stands for (exhaustive: the whole product)


@dataclass
class RoutineCheck:
    routine: Routine
    size: Size
    static: Bounds | None
    totals: ChunkResult
    bounds_violations: list[str]
    budget_violations: list[str] = field(default_factory=list)
    parts: list[PartRun] = field(default_factory=list)
    trace: list[str] = field(default_factory=list)  # the first failing case's instructions
    start: RasterStart | None = None  # with --scene: the beam position every call started at
    engine: str = "scalar"  # which engine ran the cases: "scalar" (Machine) or "batch"
    agreement: ChunkResult | None = None  # with the batched core: the cases also run on Machine

    @property
    def mismatches(self) -> int:
        t = self.totals
        found = (t.result_mismatches + t.cycle_mismatches + t.run_errors + len(self.bounds_violations)
                 + len(self.budget_violations))
        if self.agreement is not None:  # its result mismatches and run errors are among the batch's own
            found += self.agreement.engine_mismatches + self.agreement.cycle_mismatches
        return found

    @property
    def mean(self) -> float:
        return self.totals.cycles_sum / self.totals.cycles_count if self.totals.cycles_count else 0.0

    @property
    def worst_reached(self) -> bool:
        return self.static is not None and self.totals.cpu_max == self.static.worst

    def domain_report(self) -> list[str]:
        t = self.totals
        lines = [f"inside the domain: {t.cases - t.outside} cases, {t.result_mismatches} wrong"]
        for condition in self.routine.domain:
            violating = t.constraint_cases.get(condition.text, 0)
            wrong = t.constraint_wrong.get(condition.text, 0)
            verdict = "needed" if wrong else "not shown to be needed by these cases"
            lines.append(f"  condition {condition.text}: {violating} cases break it, {wrong} of them wrong: {verdict}")
        return lines



def inputs_by_name(routine: Routine, case: tuple) -> dict:
    return {port.name: list(value) if port.table else value for port, value in zip(routine.inputs, case)}


def describe_case(routine: Routine, case: tuple) -> str:
    return ", ".join(f"{port.name}={describe_value(port, value)}" for port, value in zip(routine.inputs, case))


def describe_outputs(routine: Routine, values: tuple) -> str:
    return ", ".join(f"{port.name}={describe_value(port, value)}" for port, value in zip(routine.outputs, values))

