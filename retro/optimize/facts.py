"""What is known about the machine state where a window starts, from the code alone, and a window
change checked on every state those facts allow.

The search's samples say what a window's entry state looks like on 256 cases; a replacement that
matches the window there may still differ on a state the samples missed (a value like A = 1 that
only a boundary case reaches). So a window's replacement is also run against the window on every
combination of what the two read (and what one writes that the other leaves, if live after), each
register or memory byte over all 256 values and each flag over both, keeping only the states the
facts allow (`window_agrees`). The facts, gathered forward over the routine's control flow and
intersected where paths join (`facts_before`), are:
- a constant: `("const", place, value)`: the carry after SEC, a flag after a branch on it (taken
  or not), a register after an immediate load, the caller's [entry] guarantees;
- an equality: `("eq", place, place)`: A and X after TXA, X and a byte after STX (so a load of the
  byte is a transfer);
- a compare's carry: `("carry", register, operand)`: C = register >= operand after CMP/CPX/CPY,
  while none of them changes (so a CMP repeating a carry the code holds is seen as such);
- N and Z of a register: `("nz", register)`: after a load, a transfer or an operation on it.
Places are "A", "X", "Y", a flag letter, or an address; an immediate operand is `("#", value)`.
A read indexed by X or Y from the routine's own tables (bytes of its program it never writes) reads
the index over all its values and the table itself; other indexed or indirect reads get no such
check (the caller decides what stands behind them).
"""

from __future__ import annotations

import numpy as np

from retro.optimize.code import Listing
from retro.optimize.effects import ALL_MEMORY, READ_MODIFY_WRITE, effects, known

MAX_LOCAL_STATES = 1 << 20  # beyond this many combinations the check runs on a random part of them
RANDOM_LOCAL_STATES = 1 << 16
REGISTERS = ("A", "X", "Y")
LOADS = {"LDA": "A", "LDX": "X", "LDY": "Y"}
STORES = {"STA": "A", "STX": "X", "STY": "Y"}
TRANSFERS = {"TAX": ("X", "A"), "TAY": ("Y", "A"), "TXA": ("A", "X"), "TYA": ("A", "Y")}
COMPARES = {"CMP": "A", "CPX": "X", "CPY": "Y"}
FLAG_SETS = {"CLC": ("C", 0), "SEC": ("C", 1), "CLV": ("V", 0), "CLD": ("D", 0), "SED": ("D", 1)}
BRANCH_FLAG = {"BCC": ("C", 0), "BCS": ("C", 1), "BEQ": ("Z", 1), "BNE": ("Z", 0), "BMI": ("N", 1), "BPL": ("N", 0),
               "BVC": ("V", 0), "BVS": ("V", 1)}
NZ_FROM = {"ADC": "A", "SBC": "A", "AND": "A", "ORA": "A", "EOR": "A", "INX": "X", "DEX": "X", "INY": "Y", "DEY": "Y"}


def _places(fact: tuple) -> tuple:
    """The places a fact is about (it no longer holds once one of them is written)."""
    kind = fact[0]
    if kind == "const":
        return (fact[1],)
    if kind == "eq":
        return fact[1], fact[2]
    if kind == "carry":
        return ("C", fact[1]) + (() if isinstance(fact[2], tuple) else (fact[2],))
    return fact[1], "N", "Z"  # nz


def _written(instruction) -> set:
    _, writes, _, written = effects(instruction)
    out = set(writes) | set(written)
    if instruction.mode not in ("imp", "acc", "imm", "rel", "zpg", "abs") and (
            instruction.mnemonic in STORES or instruction.mnemonic in READ_MODIFY_WRITE):
        out.add(ALL_MEMORY)  # an indexed or indirect write: any byte may change
    return out


def step(facts: frozenset, instruction) -> frozenset:
    """The facts after a straight-line instruction (a branch's edges: `edge`)."""
    if not known(instruction):
        return frozenset()
    written = _written(instruction)
    kept = {f for f in facts if not any(p in written or (ALL_MEMORY in written and isinstance(p, int))
                                        for p in _places(f))}
    name, mode, operand = instruction.mnemonic, instruction.mode, instruction.operand
    direct = mode in ("zpg", "abs") and instruction.target is None
    if name in LOADS:
        register = LOADS[name]
        if mode == "imm":
            kept.add(("const", register, operand))
        elif direct:
            kept.add(("eq", register, operand))
        kept.add(("nz", register))
    elif name in STORES and direct:
        kept.add(("eq", operand, STORES[name]))
    elif name in TRANSFERS:
        to, source = TRANSFERS[name]
        kept.add(("eq", to, source))
        kept.add(("nz", to))
    elif name in COMPARES and (mode == "imm" or direct):
        kept.add(("carry", COMPARES[name], ("#", operand) if mode == "imm" else operand))
    elif name in FLAG_SETS:
        kept.add(("const",) + FLAG_SETS[name])
    elif name in NZ_FROM and mode in ("imm", "imp", "zpg", "abs"):
        kept.add(("nz", NZ_FROM[name]))
    elif name in ("ASL", "LSR", "ROL", "ROR") and mode == "acc":
        kept.add(("nz", "A"))
    return frozenset(kept)


def edge(facts: frozenset, instruction, taken: bool) -> frozenset:
    """The facts along one way out of a conditional branch."""
    flag, value = BRANCH_FLAG[instruction.mnemonic]
    return frozenset(f for f in facts if not (f[0] == "const" and f[1] == flag)) | {
        ("const", flag, value if taken else 1 - value)}


def facts_before(listing: Listing, entry: frozenset = frozenset()) -> list[frozenset | None]:
    """Per instruction, the facts that hold whenever the routine reaches it (None: unreachable)."""
    instructions = listing.instructions
    where = dict(listing.labels)
    before: list[frozenset | None] = [None] * (len(instructions) + 1)
    before[0] = entry
    changed = True
    while changed:
        changed = False
        for i, instruction in enumerate(instructions):
            facts = before[i]
            if facts is None:
                continue
            outs = []
            name = instruction.mnemonic
            if instruction.is_branch and name in BRANCH_FLAG:
                outs.append((i + 1, edge(facts, instruction, False)))
                if isinstance(instruction.target, str):
                    outs.append((where[instruction.target], edge(facts, instruction, True)))
            elif name == "JMP" and isinstance(instruction.target, str):
                outs.append((where[instruction.target], facts))
            elif name not in ("RTS", "RTI", "JMP", "BRK", "JSR"):
                outs.append((i + 1, step(facts, instruction)))
            elif name == "JSR":
                outs.append((i + 1, frozenset()))
            for at, new in outs:
                old = before[at]
                merged = new if old is None else old & new
                if merged != old:
                    before[at] = merged
                    changed = True
    return before[:len(instructions)]


def entry_facts(entry_state: tuple) -> frozenset:
    """The caller's [entry] guarantees as constants (registers and flags)."""
    facts = set()
    for name, value in entry_state:
        place = name.upper()
        if place in REGISTERS or place in "CZIDVN" and len(place) == 1:
            facts.add(("const", place, int(value)))
    return frozenset(facts)


def _reads(instructions, static=None) -> set | None:
    """Places read before being written by the sequence; None when it reads memory it cannot name.
    `static(low, high)`: whether those bytes are the same on every case and never written (the
    routine's own tables): an absolute indexed read there reads the index and the call image."""
    read, written = set(), set()
    for instruction in instructions:
        if not known(instruction):
            return None
        reads, _, read_memory, _ = effects(instruction)
        if ALL_MEMORY in read_memory and instruction.mode in ("abx", "aby") and static is not None and static(
                instruction.operand, instruction.operand + 0xFF):
            read_memory = frozenset()
        if ALL_MEMORY in read_memory:
            return None
        read |= (set(reads) | set(read_memory)) - written
        written |= _written(instruction)
    return read


def local_places(window, replacement, live: frozenset, static=None) -> list | None:
    """The places whose entry values decide whether the two sequences agree on `live`."""
    reads = [_reads(window, static), _reads(replacement, static)]
    if reads[0] is None or reads[1] is None:
        return None
    writes = set().union(*(_written(i) for i in tuple(window) + tuple(replacement)))
    if ALL_MEMORY in writes:
        return None
    places = reads[0] | reads[1] | {p for p in writes if p in live or (isinstance(p, int) and ALL_MEMORY in live)}
    return sorted(places, key=lambda p: (isinstance(p, int), str(p)))


def _value_of(fact_place, values: dict):
    return fact_place[1] if isinstance(fact_place, tuple) else values.get(fact_place)


def allowed_states(places: list, facts: frozenset, seed: int = 0) -> tuple[dict, bool]:
    """Every combination of the places' values the facts allow (place -> per-state values), and
    whether it is every one (else a random part of them, past MAX_LOCAL_STATES)."""
    sizes = [2 if isinstance(p, str) and p not in REGISTERS else 256 for p in places]
    total = int(np.prod(sizes, dtype=np.float64)) if sizes else 1
    whole = total <= MAX_LOCAL_STATES
    if whole:
        index = np.arange(total, dtype=np.int64)
        values = {}
        for place, size in zip(reversed(places), reversed(sizes)):
            values[place] = (index % size).astype(np.int32)
            index //= size
    else:
        rng = np.random.default_rng(seed)
        values = {p: rng.integers(0, s, RANDOM_LOCAL_STATES).astype(np.int32) for p, s in zip(places, sizes)}
    count = total if whole else RANDOM_LOCAL_STATES
    keep = np.ones(count, dtype=bool)
    for fact in facts:
        kind = fact[0]
        if kind == "const" and fact[1] in values:
            keep &= values[fact[1]] == fact[2]
        elif kind == "eq" and fact[1] in values and fact[2] in values:
            keep &= values[fact[1]] == values[fact[2]]
        elif kind == "carry" and "C" in values and fact[1] in values and (
                isinstance(fact[2], tuple) or fact[2] in values):
            keep &= values["C"] == (values[fact[1]] >= _value_of(fact[2], values))
        elif kind == "nz" and fact[1] in values:
            if "Z" in values:
                keep &= values["Z"] == (values[fact[1]] == 0)
            if "N" in values:
                keep &= values["N"] == (values[fact[1]] >> 7)
    return {p: v[keep] for p, v in values.items()}, whole


def window_agrees(executor, window, replacement, live: frozenset, facts: frozenset, static=None) -> bool | None:
    """Whether `replacement` leaves what is `live` as `window` does on every entry state the facts
    allow (see the module's docstring); None when the check cannot be made (indexed or indirect
    operands outside the routine's own tables (`static`; the executor's image holds them), an
    instruction the effects table does not know)."""
    from retro.optimize.search import FLAG_BITS, State, target_matches
    places = local_places(window, replacement, live, static)
    if places is None:
        return None
    values, _ = allowed_states(places, facts)
    count = len(next(iter(values.values()))) if values else 1
    if count == 0:
        return True  # no state the facts allow: the window is never reached
    zeros = np.zeros(count, dtype=np.int32)
    p = zeros | 0x20
    for flag, bit in FLAG_BITS.items():
        if flag in values:
            p = p | np.where(values[flag] != 0, bit, 0).astype(np.int32)
    memory = {a: values.get(a, zeros) for a in _addresses(tuple(window) + tuple(replacement)) | {
        a for a in values if isinstance(a, int)}}
    start = State(values.get("A", zeros), values.get("X", zeros), values.get("Y", zeros), p, memory)
    ends = []
    for sequence in (window, replacement):
        state = start
        for instruction in sequence:
            state = executor.step(state, instruction)
        ends.append(state)
    return bool(target_matches(ends[1], ends[0], live))


def _addresses(instructions) -> set:
    return {i.operand for i in instructions if i.mode in ("zpg", "abs") and i.target is None}
