"""The coverage-guided search: after a check's planned cases, candidate cases are made by mutating
inputs (bit flips, +-1, the inputs' boundary values, the constants the code compares with, fresh
random values, crossover of two cases), always inside each input's `values` and the spec's `where`
domain, and run in generations on the check's engine. A candidate that goes a way at a branch no case
went before, or that is slower (or faster) than every case so far, is kept: it becomes a parent of
the next generations and a case of the check, checked against the reference like every other.

Parents are chosen toward what is missing: cases that ran a branch whose other way no case has
gone, the slowest and the fastest cases, and the cases kept. The search is a pure function of the
routine, the seed and what the cases before it covered; both engines give it the same feedback
(cycles per case, and per branch direction the first candidate that went that way), so it finds
the same cases on either. It ends when its budget is spent (N candidates, or N * CYCLES_PER_CANDIDATE
cycles run), when a call stops (that case is kept: the check reports it), or after STALE_GENERATIONS
generations that found nothing."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from retro.analysis.check.coverage import code_instructions, directions_of
from retro.analysis.coverage_model import CodeCoverage
from retro.cpu.timing import timing_table
from retro.errors import RunError
from retro.routines import cases as case_sets
from retro.routines.runner import RoutineRunner
from retro.routines.spec import Port, Routine

DEFAULT_SEARCH = 4_096  # candidates a check's search may run (--search N, [cases] search = N)
CYCLES_PER_CANDIDATE = 250  # and at most this many emulated cycles per candidate of the budget, all told:
# a slow routine's search ends sooner (a bound in cycles, not seconds, keeps it the same on every machine)
GENERATION = 256  # candidates run together (one batch on the batched core)
STALE_GENERATIONS = 6  # generations in a row that find nothing end the search
KEPT_EXTREMES = 8  # the slowest and the fastest cases kept as parents
REACHERS_KEPT = 4  # cases kept per branch that ran it (parents toward its other way, while no case went there)
SEARCH_RNG_OFFSET = 3  # the search draws from seed + 3 (cases from seed, memory from seed + 1, exhaustive + 2)
OPERATORS = ("flip", "step", "edge", "constant", "random", "cross")

Direction = tuple[int, bool]  # (branch address, taken)


@dataclass
class SearchResult:
    budget: int
    candidates: int = 0  # candidates run
    cycles: int = 0  # the cycles they ran
    generations: int = 0
    found: list[tuple] = field(default_factory=list)  # the cases kept, in the order found
    new_directions: int = 0
    slowest: int | None = None  # the most / fewest cycles of any case before and during the search
    fastest: int | None = None
    ended: str = "off"  # "budget", "stale" (nothing found for STALE_GENERATIONS), "stopped" (a call stopped), "off"


@dataclass(frozen=True)
class _Probe:
    """What a generation did: cycles of the calls that returned (in order; a call that stopped ends
    it) and, per branch direction, the first candidate that went that way."""

    cycles: np.ndarray
    first: dict[Direction, int]
    stopped: bool


def _probe(runner: RoutineRunner, cases: list[tuple], on_batch: bool) -> _Probe:
    if on_batch:
        outcome = runner.run_batch(case_sets.cases_to_columns(runner.routine, cases), first_lanes=True)
        stops = np.flatnonzero(outcome.error)
        returned = int(stops[0]) if len(stops) else len(cases)
        first = {d: i for d, i in outcome.coverage.first_lane.items() if i < returned}
        return _Probe(outcome.cycles[:returned].copy(), first, returned < len(cases))
    read = runner.machine.memory.__getitem__
    cycles: list[int] = []
    first: dict[Direction, int] = {}
    for i, case in enumerate(cases):
        steps: list = []
        try:
            _, spent = runner.run(case, steps)
        except RunError:
            return _Probe(np.asarray(cycles, dtype=np.int64), first, True)
        cycles.append(spent)
        for direction in directions_of(read, steps, runner.routine.cpu):
            first.setdefault(direction, i)
    return _Probe(np.asarray(cycles, dtype=np.int64), first, False)


def code_constants(runner: RoutineRunner) -> tuple[int, ...]:
    """The immediate operands of the routine's code, with their neighbours: values a compare tests."""
    table = timing_table(runner.routine.cpu)
    read = runner.call_image.__getitem__
    found = set()
    for pc, opcode in code_instructions(runner).items():
        op = table.get(opcode)
        if op is not None and op.mode == "imm":
            value = read((pc + 1) & 0xFFFF)
            found.update(v & 0xFF for v in (value - 1, value, value + 1))
    return tuple(sorted(found))


class _Mutator:
    """Children of parent cases, each inside every input's values (the domain is checked after)."""

    def __init__(self, routine: Routine, rng: np.random.Generator, constants: tuple[int, ...]) -> None:
        self.routine, self.rng, self.constants = routine, rng, constants

    def child(self, parent: tuple, other: tuple) -> tuple:
        rng = self.rng
        case = list(parent)
        for _ in range(min(int(rng.geometric(0.5)), 4)):  # one change, sometimes a few
            index = int(rng.integers(len(case)))
            port = self.routine.inputs[index]
            operator = OPERATORS[int(rng.integers(len(OPERATORS)))]
            if operator == "cross":
                case[index] = other[index]
            elif port.table:
                table = list(case[index])
                k = int(rng.integers(len(table)))
                table[k] = self._value(port, table[k], operator, 8)
                case[index] = tuple(table)
            else:
                case[index] = self._value(port, case[index], operator, port.bits)
        return tuple(case)

    def _value(self, port: Port, value: int, operator: str, bits: int) -> int:
        rng, values = self.rng, port.values
        byte = int(rng.integers(max(1, bits // 8))) * 8
        if operator == "flip":
            value ^= 1 << int(rng.integers(bits))
        elif operator == "step":
            value += 1 if rng.random() < 0.5 else -1
        elif operator == "edge":
            edges = (values.at(0), values.at(values.count - 1), values.at(min(1, values.count - 1)),
                     values.at(max(values.count - 2, 0)))
            value = edges[int(rng.integers(len(edges)))]
        elif operator == "constant" and self.constants:
            constant = self.constants[int(rng.integers(len(self.constants)))]
            value = (value & ~(0xFF << byte)) | constant << byte
        else:
            value = values.at(int(rng.integers(values.count)))
        return _inside(values, value)


def _inside(values, value: int) -> int:
    """The value itself when the input takes it, else the nearest value it takes."""
    if values.listed is None:
        return min(max(value, values.lo), values.hi)
    if value in values.listed:
        return value
    return min(values.listed, key=lambda v: (abs(v - value), v))


def _inside_domain(routine: Routine, cases: list[tuple]) -> list[tuple]:
    if not routine.domain or not cases:
        return cases
    columns = case_sets.cases_to_columns(routine, cases)
    keep = np.ones(len(cases), dtype=bool)
    for condition in routine.domain:
        keep &= condition.over(columns, cases)
    return [case for case, kept in zip(cases, keep) if kept]


def search(runner: RoutineRunner, *, on_batch: bool, seed: int, budget: int, covered: CodeCoverage,
           slowest: tuple[int, tuple] | None, fastest: tuple[int, tuple] | None) -> SearchResult:
    """Search for cases that go new ways at branches and that take more (or fewer) cycles than
    `slowest` / `fastest` ((cycles, case) of the check's cases so far); `covered`: what they ran."""
    result = SearchResult(budget, slowest=None if slowest is None else slowest[0],
                          fastest=None if fastest is None else fastest[0])
    if budget <= 0:
        return result
    return _Search(runner, on_batch, seed, covered, slowest, fastest, result).run()


class _Search:
    """One search between its generations: the directions gone so far, the parents it keeps (the
    cases that reached each branch, the extremes, the cases found) and what is left of its budget."""

    def __init__(self, runner: RoutineRunner, on_batch: bool, seed: int, covered: CodeCoverage,
                 slowest: tuple[int, tuple] | None, fastest: tuple[int, tuple] | None, result: SearchResult) -> None:
        self.runner, self.on_batch, self.result = runner, on_batch, result
        self.rng = np.random.default_rng(seed + SEARCH_RNG_OFFSET)
        self.gone: set[Direction] = ({(pc, True) for pc, n in covered.taken.items() if n}
                                     | {(pc, False) for pc, n in covered.not_taken.items() if n})
        self.mutate = _Mutator(runner.routine, self.rng, code_constants(runner))
        self.fresh = _fresh_cases(runner.routine, seed, result.budget)
        self.reachers: dict[int, list[tuple]] = {}  # branch address -> the first REACHERS_KEPT cases that ran it
        self.slow = [slowest] if slowest else []
        self.fast = [fastest] if fastest else []
        self.kept: list[tuple] = []
        self.stale = 0  # generations in a row that found nothing
        self.cycle_budget = result.budget * CYCLES_PER_CANDIDATE
        # cycles a call is expected to take (the slowest case's at first, then the last generation's mean):
        # a generation is sized to fit what is left of the budget
        self.per_call = max(1, result.slowest or 1)

    def run(self) -> SearchResult:
        result = self.result
        while result.candidates < result.budget and result.cycles < self.cycle_budget:
            ended = self._run_generation()
            if ended:
                result.ended = ended
                return result
        result.ended = "budget"
        return result

    def _run_generation(self) -> str | None:
        """One generation run and what it found kept; how the search ended, when it did."""
        result = self.result
        n = min(GENERATION, result.budget - result.candidates,
                max(1, (self.cycle_budget - result.cycles) // self.per_call))
        wanting = [case for pc in sorted(self.reachers) if ((pc, True) in self.gone) != ((pc, False) in self.gone)
                   for case in self.reachers[pc]]
        parents = [c for _, c in self.slow + self.fast] + self.kept
        cases = _inside_domain(self.runner.routine, _generation(self.mutate, self.rng, n, wanting, parents, self.fresh))
        result.candidates += n
        result.generations += 1
        if not cases:
            return self._found_nothing()
        probe = _probe(self.runner, cases, self.on_batch)
        found = self._new_directions(probe, cases) | self._new_extremes(probe, cases)
        if probe.stopped:
            found.add(len(probe.cycles))  # the call that stopped: the check reports it
        new = [cases[i] for i in sorted(found)]
        result.found += new
        self.kept += new
        if probe.stopped:
            return "stopped"
        if new:
            self.stale = 0
            return None
        return self._found_nothing()

    def _found_nothing(self) -> str | None:
        self.stale += 1
        return "stale" if self.stale >= STALE_GENERATIONS else None

    def _new_directions(self, probe: _Probe, cases: list[tuple]) -> set[int]:
        """The candidates that first went a way no case went before; each branch's first reachers kept."""
        found = set()
        for (pc, way), i in sorted(probe.first.items(), key=lambda item: (item[1], item[0])):
            known = self.reachers.setdefault(pc, [])
            if len(known) < REACHERS_KEPT:
                known.append(cases[i])
            if (pc, way) not in self.gone:
                self.gone.add((pc, way))
                self.result.new_directions += 1
                found.add(i)
        return found

    def _new_extremes(self, probe: _Probe, cases: list[tuple]) -> set[int]:
        """The candidates slower or faster than every case so far; the extremes kept as parents, the
        generation's cycles counted against the budget."""
        result, cycles = self.result, probe.cycles
        if not len(cycles):
            return set()
        found = set()
        high, low = int(np.argmax(cycles)), int(np.argmin(cycles))
        if result.slowest is None or cycles[high] > result.slowest:
            result.slowest = int(cycles[high])
            found.add(high)
        if result.fastest is None or cycles[low] < result.fastest:
            result.fastest = int(cycles[low])
            found.add(low)
        self.slow = _extremes(self.slow, cycles, cases, -1)
        self.fast = _extremes(self.fast, cycles, cases, 1)
        result.cycles += int(cycles.sum())
        self.per_call = max(1, int(cycles.sum()) // len(cycles))
        return found


def _extremes(kept: list[tuple[int, tuple]], cycles: np.ndarray, cases: list[tuple], sign: int) -> list:
    """The KEPT_EXTREMES slowest (sign -1) or fastest (sign 1) cases of `kept` and a generation."""
    order = np.argsort(sign * cycles, kind="stable")[:KEPT_EXTREMES]
    merged = kept + [(int(cycles[i]), cases[int(i)]) for i in order]
    merged.sort(key=lambda item: sign * item[0])
    return merged[:KEPT_EXTREMES]


def _fresh_cases(routine: Routine, seed: int, count: int):
    """New random cases, from the check's own random generation (its inputs' values, its domain)."""
    parts = case_sets.plan(routine, exhaustive=False, seed=seed + SEARCH_RNG_OFFSET, random=count)
    random_part = next((part for part in parts if part.name == "random"), None)
    return iter(()) if random_part is None else random_part.cases


def _generation(mutate: _Mutator, rng: np.random.Generator, n: int, wanting: list[tuple], parents: list[tuple],
                fresh) -> list[tuple]:
    """n candidates: children of the cases that ran a branch one way only (half, when there are any),
    of the extremes and the kept cases, and fresh random cases (a quarter, or all when no parent)."""
    out = []
    pool = parents or wanting
    for k in range(n):
        pick = rng.random()
        if wanting and pick < 0.5:
            parent = wanting[int(rng.integers(len(wanting)))]
        elif pool and pick < 0.75:
            parent = pool[int(rng.integers(len(pool)))]
        else:
            case = next(fresh, None)
            if case is not None:
                out.append(case)
                continue
            if not pool and not wanting:
                break
            parent = (wanting or pool)[int(rng.integers(len(wanting or pool)))]
        everyone = wanting + pool
        out.append(mutate.child(parent, everyone[int(rng.integers(len(everyone)))]))
    return out
