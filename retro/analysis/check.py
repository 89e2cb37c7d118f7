"""Cross-check the 6502 routines against their references, for results and for cycles.

For every case: the routine's answer must equal the reference's (inside the routine's stated
domain), and the measured cycle count must equal the independent timing model summed over the
executed path (retro.cpu.timing). Cases outside the stated domain are run too: their failures are
what shows the domain is exact (each stated condition is needed), and a failure inside it is a
mismatch. Measured extremes must lie within the static best/worst case (retro.cpu.flow).

Long runs split the cases into chunks over worker processes (`jobs`), reporting progress.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

from retro.cpu.flow import Bounds, analyse
from retro.cpu.timing import model_cycles
from retro.routines.harness import RoutineRunner, Size
from retro.routines.registry import Routine, cases, get, world_for

CHUNK = 4_000
EXAMPLES_KEPT = 5


@dataclass
class ChunkResult:
    cases: int = 0
    result_mismatches: int = 0
    cycle_mismatches: int = 0
    outside: int = 0
    outside_wrong: int = 0
    constraint_cases: dict[str, int] = field(default_factory=dict)
    constraint_wrong: dict[str, int] = field(default_factory=dict)
    cycles_min: int | None = None
    cycles_max: int | None = None
    cycles_sum: int = 0
    cycles_count: int = 0
    examples: list[str] = field(default_factory=list)
    outside_examples: list[str] = field(default_factory=list)

    def merge(self, other: "ChunkResult") -> None:
        self.cases += other.cases
        self.result_mismatches += other.result_mismatches
        self.cycle_mismatches += other.cycle_mismatches
        self.outside += other.outside
        self.outside_wrong += other.outside_wrong
        for target, source in ((self.constraint_cases, other.constraint_cases),
                               (self.constraint_wrong, other.constraint_wrong)):
            for key, value in source.items():
                target[key] = target.get(key, 0) + value
        if other.cycles_count:
            self.cycles_min = other.cycles_min if self.cycles_min is None else min(self.cycles_min, other.cycles_min)
            self.cycles_max = other.cycles_max if self.cycles_max is None else max(self.cycles_max, other.cycles_max)
        self.cycles_sum += other.cycles_sum
        self.cycles_count += other.cycles_count
        self.examples = (self.examples + other.examples)[:EXAMPLES_KEPT]
        self.outside_examples = (self.outside_examples + other.outside_examples)[:EXAMPLES_KEPT]


@dataclass
class RoutineCheck:
    routine: Routine
    size: Size
    static: Bounds
    totals: ChunkResult
    bounds_violations: list[str]

    @property
    def mismatches(self) -> int:
        return self.totals.result_mismatches + self.totals.cycle_mismatches + len(self.bounds_violations)

    @property
    def mean(self) -> float:
        return self.totals.cycles_sum / self.totals.cycles_count if self.totals.cycles_count else 0.0

    @property
    def worst_reached(self) -> bool:
        return self.totals.cycles_max == self.static.worst

    def domain_report(self) -> list[str]:
        t = self.totals
        lines = []
        inside = t.cases - t.outside
        lines.append(f"inside the domain: {inside} cases, {t.result_mismatches} wrong")
        for name, _ in self.routine.domain:
            violating = t.constraint_cases.get(name, 0)
            wrong = t.constraint_wrong.get(name, 0)
            verdict = "needed" if wrong else "not shown to be needed by these cases"
            lines.append(f"  condition {name}: {violating} cases break it, {wrong} of them wrong: {verdict}")
        return lines


def _describe(routine: Routine, case: tuple) -> str:
    return ", ".join(f"{name}={value}" for name, value in zip(routine.inputs, case)) + (
        f", mask pair {case[2]}" if routine.name == "pixel" else "")


_RUNNERS: dict[tuple[str, int], RoutineRunner] = {}


def _runner(name: str, seed: int) -> RoutineRunner:
    key = (name, seed)
    if key not in _RUNNERS:
        _RUNNERS[key] = RoutineRunner(get(name), world_for(name, seed))
    return _RUNNERS[key]


def check_chunk(name: str, seed: int, chunk: list[tuple]) -> ChunkResult:
    """Run cases of one routine; pure function of its arguments (used in worker processes)."""
    runner = _runner(name, seed)
    routine = get(name)  # the registry's entry now (the runner keeps the one it was built from)
    read = runner.machine.memory.__getitem__
    out = ChunkResult()
    for case in chunk:
        steps: list = []
        answer, cycles = runner.run(case, steps)
        expected = routine.reference(case, runner.world)
        out.cases += 1
        modelled = model_cycles(read, steps)
        if modelled != cycles:
            out.cycle_mismatches += 1
            if len(out.examples) < EXAMPLES_KEPT:
                out.examples.append(f"{name}({_describe(routine, case)}): measured {cycles} cycles, "
                                    f"the timing model says {modelled}")
        broken = [rule_name for rule_name, rule in routine.domain if not rule(case)]
        for rule_name in broken:
            out.constraint_cases[rule_name] = out.constraint_cases.get(rule_name, 0) + 1
        if broken:
            out.outside += 1
            if answer != expected:
                out.outside_wrong += 1
                for rule_name in broken:
                    out.constraint_wrong[rule_name] = out.constraint_wrong.get(rule_name, 0) + 1
                if len(out.outside_examples) < EXAMPLES_KEPT:
                    out.outside_examples.append(f"{name}({_describe(routine, case)}): returned {answer}, "
                                                f"reference {expected} (outside: {', '.join(broken)})")
            continue
        if answer != expected:
            out.result_mismatches += 1
            if len(out.examples) < EXAMPLES_KEPT:
                out.examples.append(f"{name}({_describe(routine, case)}): returned {answer}, reference {expected}")
        out.cycles_min = cycles if out.cycles_min is None else min(out.cycles_min, cycles)
        out.cycles_max = cycles if out.cycles_max is None else max(out.cycles_max, cycles)
        out.cycles_sum += cycles
        out.cycles_count += 1
    return out


def static_bounds(routine: Routine) -> Bounds:
    runner_program = _runner(routine.name, 0).program
    memory = [0] * 0x10000
    memory[runner_program.origin:runner_program.end] = list(runner_program.code)
    bounds = {runner_program.symbols[label]: count for label, count in routine.loop_bounds.items()}
    return analyse(memory.__getitem__, runner_program.symbols[routine.name], bounds, name=routine.name)


def check_routine(name: str, *, exhaustive: bool = False, seed: int = 0, random_count: int | None = None,
                  jobs: int = 1, progress: Callable[[str], None] | None = None) -> RoutineCheck:
    routine = get(name)
    all_cases = cases(routine, exhaustive=exhaustive, seed=seed, random_count=random_count)
    chunks = [all_cases[i:i + CHUNK] for i in range(0, len(all_cases), CHUNK)]
    totals = ChunkResult()
    done = 0
    if jobs > 1 and len(chunks) > 1:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            for result in pool.map(check_chunk, [name] * len(chunks), [seed] * len(chunks), chunks):
                totals.merge(result)
                done += result.cases
                if progress:
                    progress(f"check {name}: {done}/{len(all_cases)} cases")
    else:
        for chunk in chunks:
            totals.merge(check_chunk(name, seed, chunk))
            done += len(chunk)
            if progress and len(chunks) > 1:
                progress(f"check {name}: {done}/{len(all_cases)} cases")
    static = static_bounds(routine)
    violations = []
    if totals.cycles_count and totals.cycles_min < static.best:
        violations.append(f"{name}: measured minimum {totals.cycles_min} is below the static best case {static.best}")
    if totals.cycles_count and totals.cycles_max > static.worst:
        violations.append(f"{name}: measured maximum {totals.cycles_max} is above the static worst case {static.worst}")
    runner = _runner(name, seed)
    size = runner.size()
    return RoutineCheck(routine, size, static, totals, violations)


def default_jobs() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def run_checks(names: list[str] | None, *, exhaustive: bool = False, seed: int = 0, random_count: int | None = None,
               jobs: int | None = None, progress: Callable[[str], None] | None = None) -> list[RoutineCheck]:
    """Check the named routines (all when none are named); unknown names fail before any work."""
    from retro.routines.registry import select

    routines = select(names)
    workers = default_jobs() if jobs is None else jobs
    return [check_routine(r.name, exhaustive=exhaustive, seed=seed, random_count=random_count, jobs=workers,
                          progress=progress) for r in routines]


def check_record(check: RoutineCheck) -> dict:
    """One routine's check as plain data (what `retro check --json` prints)."""
    t = check.totals
    return {"routine": check.routine.name, "cases": t.cases, "mismatches": check.mismatches,
            "result_mismatches": t.result_mismatches, "cycle_mismatches": t.cycle_mismatches,
            "bounds_violations": check.bounds_violations,
            "outside_domain": t.outside, "outside_domain_wrong": t.outside_wrong,
            "domain": [{"condition": name, "cases": t.constraint_cases.get(name, 0),
                        "wrong": t.constraint_wrong.get(name, 0)} for name, _ in check.routine.domain],
            "min": t.cycles_min, "mean": round(check.mean, 2), "max": t.cycles_max,
            "static_min": check.static.best, "static_max": check.static.worst, "worst_reached": check.worst_reached,
            "examples": t.examples, "outside_examples": t.outside_examples}


def format_check(check: RoutineCheck) -> list[str]:
    t = check.totals
    verdict = "OK" if not check.mismatches else f"{check.mismatches} MISMATCH(ES)"
    lines = [f"{check.routine.name}: {t.cases} cases, {verdict}; cycles {t.cycles_min}-{t.cycles_max} "
             f"(mean {check.mean:.2f}), static {check.static.best}-{check.static.worst}, worst case "
             f"{'reached' if check.worst_reached else 'not reached'}; timing model equal on "
             f"{t.cases - t.cycle_mismatches} of {t.cases} calls"]
    lines += [f"  {line}" for line in check.domain_report()[1:]] if check.routine.domain else []
    if t.outside:
        lines.append(f"  outside the stated domain: {t.outside} cases, {t.outside_wrong} wrong"
                     + (f", e.g. {t.outside_examples[0]}" if t.outside_examples else ""))
    lines += [f"  MISMATCH {example}" for example in t.examples]
    lines += [f"  MISMATCH {violation}" for violation in check.bounds_violations]
    return lines
