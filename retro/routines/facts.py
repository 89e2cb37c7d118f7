"""`[facts]`: what a spec states about its routine that the static analysis cannot derive, and the
check that holds every case to it (docs/specs.md, "Facts").

```toml
[facts]
loop_end = "taken"                  # the branch at this label is always taken ("not taken": never)
hit = { x = "0..7", c = 1 }         # each time the PC reaches `hit`: X in 0..7 and the carry set
```

A key is a label (`label+N`) or an address inside the program; a value is `"taken"` / `"not taken"`
(the instruction there must be a conditional branch), or a table of registers (`a`, `x`, `y`:
`"LO..HI"` or a list of bytes) and flags (`c`, `z`, `n`, `v`, `d`: 0 or 1), with `branch =
"taken" | "not taken"` for both at once. The analysis takes them as given (retro.cpu.flow.Fact);
every call on either engine is held to them before the instruction at the address runs, and a call
that contradicts one stops the check naming the fact and the case.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.cpu.flow import Fact
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_N, FLAG_V, FLAG_Z
from retro.cpu.timing import BRANCH_CONDITIONS, timing_of
from retro.cpu.values import CLEAR, SET, of_values
from retro.fields import Fields, describe
from retro.program import Program
from retro.routines.places import BYTE_VALUES, parse_values, resolve

REGISTERS = ("a", "x", "y")
FLAG_BITS = {"c": FLAG_C, "z": FLAG_Z, "n": FLAG_N, "v": FLAG_V, "d": FLAG_D}
BRANCH_WORDS = {"taken": True, "always taken": True, "not taken": False, "never taken": False}
FACT_KEYS = {*REGISTERS, *FLAG_BITS, "branch"}


@dataclass(frozen=True)
class StatedFact:
    """One `[facts]` entry: where, what, and how the check tells it is contradicted."""

    key: str  # facts.KEY, as errors and failures name it
    address: int
    taken: bool | None  # the branch there: always (True) or never (False) taken
    registers: tuple[tuple[str, tuple[int, ...]], ...]  # ("x", allowed values) ...
    flags: tuple[tuple[str, int], ...]  # ("c", 0 or 1) ...
    text: str  # the fact as the spec wrote it, for messages

    @property
    def fact(self) -> Fact:
        """The fact as the static analysis takes it."""
        sets = [(r, of_values(values)) for r, values in self.registers]
        sets += [(f, SET if value else CLEAR) for f, value in self.flags]
        return Fact(self.taken, tuple(sets))

    def broken(self, a, x, y, p, opcode: int):
        """Whether registers (before the instruction at the address runs) contradict the fact: ints
        for one call, numpy arrays for lanes (then an array of booleans)."""
        values = {"a": a, "x": x, "y": y}
        bad = False
        for register, allowed in self.registers:
            bad = bad | ~_allowed_table(allowed)[values[register]]
        for flag, value in self.flags:
            bad = bad | (((p & FLAG_BITS[flag]) != 0) != bool(value))
        if self.taken is not None:
            bit, wanted = BRANCH_CONDITIONS[opcode]
            bad = bad | ((((p & bit) != 0) == bool(wanted)) != self.taken)
        return bad

    def describe_break(self) -> str:
        return f"contradicts facts.{self.key} ({self.text})"


_TABLES: dict[tuple[int, ...], np.ndarray] = {}


def _allowed_table(allowed: tuple[int, ...]) -> np.ndarray:
    table = _TABLES.get(allowed)
    if table is None:
        table = np.zeros(BYTE_VALUES, dtype=bool)
        table[list(allowed)] = True
        _TABLES[allowed] = table
    return table


def parse_facts(r: Fields, doc, program: Program, cpu: str) -> tuple[StatedFact, ...]:
    """`[facts]` -> StatedFacts, each bad entry one error naming `facts.KEY`."""
    facts = [_fact(r, key, value, program, cpu) for key, value in r.table(doc, "facts").items()]
    addresses = [f.address for f in facts]
    for fact in facts:
        if addresses.count(fact.address) > 1:
            raise r.error(f"facts.{fact.key}", f"${fact.address:04X} is stated twice (one entry per address)")
    return tuple(facts)


def _fact(r: Fields, key: str, value, program: Program, cpu: str) -> StatedFact:
    """One `[facts]` entry: its address inside the program, the branch, registers and flags it states."""
    field = f"facts.{key}"
    address = resolve(r, program, key, field)
    if not program.origin <= address < program.end:
        raise r.error(field, f"${address:04X} is outside the program (${program.origin:04X}-${program.end - 1:04X})")
    if isinstance(value, str):
        value = {"branch": value}
    if not isinstance(value, dict):
        raise r.error(field, f"expected \"taken\", \"not taken\" or a table {{ x = \"0..7\", c = 1 }}, got "
                             f"{describe(value)}")
    r.known(value, field, FACT_KEYS)
    if not value:
        raise r.error(field, "states nothing: give branch = \"taken\" | \"not taken\", a register or a flag")
    taken = _branch(r, field, value, program, address, cpu) if "branch" in value else None
    registers = [(register, _register_values(r, value[register], f"{field}.{register}"))
                 for register in REGISTERS if register in value]
    flags = [(flag, r.integer(value[flag], f"{field}.{flag}", 0, 1)) for flag in FLAG_BITS if flag in value]
    text = ", ".join([f"branch {'taken' if taken else 'not taken'}"] if taken is not None else []) or ""
    text = ", ".join(filter(None, [text, *(f"{n.upper()} in {_span(v)}" for n, v in registers),
                                   *(f"{n.upper()} = {v}" for n, v in flags)]))
    return StatedFact(key, address, taken, tuple(registers), tuple(flags), text)


def _branch(r: Fields, field: str, value: dict, program: Program, address: int, cpu: str) -> bool:
    """`branch = "taken" | "not taken"` (True: always taken), at a conditional branch."""
    word = value["branch"]
    if not isinstance(word, str) or word.strip().lower() not in BRANCH_WORDS:
        raise r.error(f"{field}.branch" if len(value) > 1 else field,
                      f"expected \"taken\" or \"not taken\", got {word!r:.40}")
    opcode = program.code[address - program.origin]
    if opcode not in BRANCH_CONDITIONS:
        raise r.error(field, f"the instruction at ${address:04X} is {_mnemonic(opcode, cpu)}, not a conditional branch "
                             f"(BPL BMI BVC BVS BCC BCS BNE BEQ)")
    return BRANCH_WORDS[word.strip().lower()]


def _register_values(r: Fields, value, field: str) -> tuple[int, ...]:
    """A register's stated values ("LO..HI" or a list of bytes), sorted."""
    values = parse_values(r, value, field)
    if values.hi >= BYTE_VALUES:
        raise r.error(field, f"{values.describe()} does not fit a register (0..255)")
    listed = values.listed if values.listed is not None else tuple(range(values.lo, values.hi + 1))
    return tuple(sorted(listed))


def _span(values: tuple[int, ...]) -> str:
    if values == tuple(range(values[0], values[-1] + 1)):
        return f"{values[0]}..{values[-1]}"
    return "[" + ", ".join(map(str, values[:8])) + (", ..." if len(values) > 8 else "") + "]"


def _mnemonic(opcode: int, cpu: str) -> str:
    try:
        return timing_of(opcode, cpu).mnemonic
    except ValueError:
        return f"${opcode:02X}"
