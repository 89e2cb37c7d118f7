"""The routine's code with its coverage, one row per instruction: what every coverage report (the
text listing, LCOV, HTML) renders. Built from plain data only: the program's bytes, the addresses of
the entry and init, the user's labels, the source map when there is one, and a `CodeCoverage`.

Rows are the instructions the coverage names (every instruction reachable from the entry and init,
0 when no case ran it), in address order, disassembled from the program's bytes as loaded (a
self-modifying routine shows its bytes as the program holds them)."""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from retro.analysis.coverage_model import CodeCoverage
from retro.cpu.disassembly import Instruction, decode_at
from retro.loaders.source_lines import SourceLine, SourceMap

_SEPARATORS = re.compile(r"::|[.:]")  # how assemblers spell a scoped name: proc::loop, proc.loop, proc:loop


@dataclass(frozen=True)
class RoutineCode:
    """What the reports need of a routine besides its coverage."""

    name: str
    code: bytes
    origin: int
    entry: int
    cpu: str = "6510"
    init: int | None = None
    symbols: dict[str, int] = field(default_factory=dict)  # the user's names (Program.symbols)
    program_file: str = ""
    source_map: SourceMap | None = None

    def holds(self, address: int, length: int = 1) -> bool:
        return self.origin <= address and address + length <= self.origin + len(self.code)

    def read(self, address: int) -> int:
        return self.code[address - self.origin] if self.holds(address) else 0


@dataclass(frozen=True)
class Row:
    address: int
    instruction: Instruction | None  # None: the address is outside the program's bytes
    labels: tuple[str, ...]
    hits: int
    taken: int | None  # None for an instruction that is not a conditional branch
    not_taken: int | None
    cycles_min: int | None  # None when no case ran it
    cycles_max: int | None
    on_worst_path: bool
    source: SourceLine | None

    @property
    def is_branch(self) -> bool:
        return self.taken is not None

    @property
    def run(self) -> bool:
        return self.hits > 0

    @property
    def partial(self) -> bool:
        """A branch that ran but went only one way."""
        return self.is_branch and self.run and not (self.taken and self.not_taken)


@dataclass(frozen=True)
class Gap:
    """Bytes between two listed instructions: data, or code no path from the entry reaches."""

    start: int
    end: int  # one past the last byte; below `start` when the next instruction overlaps this one


@dataclass(frozen=True)
class Annotated:
    code: RoutineCode
    rows: tuple[Row, ...]
    worst_cycles: int | None
    worst_length: int

    @property
    def instructions(self) -> int:
        return len(self.rows)

    @property
    def instructions_run(self) -> int:
        return sum(row.run for row in self.rows)

    @property
    def branch_directions(self) -> int:
        return 2 * sum(row.is_branch for row in self.rows)

    @property
    def directions_run(self) -> int:
        return sum(bool(row.taken) + bool(row.not_taken) for row in self.rows if row.is_branch)

    def pieces(self) -> Iterable[Row | Gap]:
        """The rows in address order with the gaps between them."""
        previous: Row | None = None
        for row in self.rows:
            if previous is not None and previous.instruction is not None:
                end = previous.address + previous.instruction.length
                if end != row.address:
                    yield Gap(end, row.address)
            yield row
            previous = row

    def summary(self) -> str:
        return (f"instructions: {self.instructions_run} of {self.instructions} run ({percent(self.instructions_run, self.instructions)}); "
                f"branch directions: {self.directions_run} of {self.branch_directions} "
                f"({percent(self.directions_run, self.branch_directions)})")


def percent(part: int, whole: int) -> str:
    return f"{100 * part / whole:.1f}%" if whole else "none"


def labels_by_address(symbols: dict[str, int]) -> dict[int, tuple[str, ...]]:
    """The user's names of each address, one spelling per name: `fill::loop` and the file's own
    `fill.loop` are one name (the qualified one kept), and a bare `loop` beside `fill::loop` at the
    same address is the same label."""
    by_address: dict[int, dict[str, str]] = {}
    for name, address in symbols.items():
        key = _SEPARATORS.sub("::", name.lstrip(":"))
        names = by_address.setdefault(address, {})
        if key not in names or "::" in name:  # prefer the qualified spelling of one name
            names[key] = name
    labels = {}
    for address, names in by_address.items():
        keys = set(names)
        kept = [names[key] for key in keys
                if "::" in key or not any(other.endswith("::" + key) for other in keys)]
        labels[address] = tuple(sorted(kept, key=lambda n: (n.count("::"), n)))
    return labels


def annotate(code: RoutineCode, coverage: CodeCoverage) -> Annotated:
    addresses = sorted(coverage.executed.keys() | coverage.taken.keys() | coverage.not_taken.keys())
    labels = labels_by_address(code.symbols)
    worst = set(coverage.worst_path)
    rows = []
    for address in addresses:
        instruction = decode_at(code.read, address, code.cpu) if code.holds(address) else None
        if instruction is not None and not code.holds(address, instruction.length):
            instruction = None  # its operand would run past the program's bytes
        branch = instruction.is_branch if instruction is not None else (address in coverage.taken
                                                                         or address in coverage.not_taken)
        rows.append(Row(
            address=address, instruction=instruction, labels=labels.get(address, ()),
            hits=coverage.executed.get(address, 0),
            taken=coverage.taken.get(address, 0) if branch else None,
            not_taken=coverage.not_taken.get(address, 0) if branch else None,
            cycles_min=coverage.cycles_min.get(address), cycles_max=coverage.cycles_max.get(address),
            on_worst_path=address in worst,
            source=code.source_map.line_of(address) if code.source_map is not None else None))
    return Annotated(code, tuple(rows), coverage.worst_cycles, len(coverage.worst_path))
