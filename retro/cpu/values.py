"""What the static analysis knows about the 6502's registers, flags and memory at a point of a routine:
an abstract interpretation over sets of byte values (retro.cpu.flow drives it along the paths).

A byte is a set of the values it may hold, kept as a 256-bit integer (bit v set: v is possible), so
a join is an OR and INX a rotation. A flag is a 2-bit set (bit 0: may be clear, bit 1: may be set).
Memory is the routine's view of it: bytes it stored on the way (`State.stored`), else what
`MemoryModel.initial` says (the program and tables as loaded, the inputs' `values`, anything else
unknown). Results that would need too many combinations of operands are taken as unknown: the sets
only ever grow toward "any value", so every answer holds for every run that starts inside the
entry state (the analysis over-approximates, it never guesses).

Assumptions, stated where the static analysis is documented (docs/specs.md): a store whose address
is unknown (a pointer or index with too many values) writes neither the program's own bytes nor
the stack; the stack page is never read as data; decimal-mode ADC/SBC on the NMOS CPUs give an
unknown result (their timing does not change).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

ANY = (1 << 256) - 1  # a byte that may hold any value
NONE = 0
LOW_HALF = (1 << 128) - 1  # values 0..127 (bit 7 clear)
HIGH_HALF = ANY ^ LOW_HALF
CLEAR, SET, EITHER = 1, 2, 3  # a flag's possible values
MAX_COMBINATIONS = 4096  # operand combinations enumerated before a result is taken as unknown
MAX_ADDRESSES = 512  # addresses an indexed or indirect access may touch before it is taken as unknown
STACK_PAGE = 0x0100


def single(value: int) -> int:
    return 1 << (value & 0xFF)


def span(lo: int, hi: int) -> int:
    """The set lo..hi (bytes)."""
    return ((1 << (hi + 1)) - 1) ^ ((1 << lo) - 1)


def members(mask: int) -> Iterator[int]:
    while mask:
        low = mask & -mask
        yield low.bit_length() - 1
        mask ^= low


def lowest(mask: int) -> int:
    return (mask & -mask).bit_length() - 1


def highest(mask: int) -> int:
    return mask.bit_length() - 1


def is_single(mask: int) -> bool:
    return mask != 0 and mask & (mask - 1) == 0


def of_values(values) -> int:
    mask = 0
    for v in values:
        mask |= 1 << (v & 0xFF)
    return mask


def flag_of(bits: set[bool] | tuple[bool, ...]) -> int:
    return (SET if True in bits else 0) | (CLEAR if False in bits else 0)


def zero_flag(mask: int) -> int:
    return (SET if mask & 1 else 0) | (CLEAR if mask & ~1 else 0)


def negative_flag(mask: int) -> int:
    return (SET if mask & HIGH_HALF else 0) | (CLEAR if mask & LOW_HALF else 0)


def increment(mask: int) -> int:
    return ((mask << 1) & ANY) | (mask >> 255)


def decrement(mask: int) -> int:
    return (mask >> 1) | ((mask & 1) << 255)


def mapped(mask: int, function: Callable[[int], int]) -> int:
    if mask == ANY:
        return of_values(function(v) for v in range(256))
    return of_values(function(v) for v in members(mask))


def flag_values(flag: int) -> tuple[int, ...]:
    return tuple(v for v, bit in ((0, CLEAR), (1, SET)) if flag & bit)


@dataclass(frozen=True)
class MemoryModel:
    """Memory when the routine is entered: `initial(address)` -> the set of values a byte may hold;
    `program` (start, end): bytes a store through an unknown address is assumed not to reach."""

    initial: Callable[[int], int]
    program: tuple[int, int] = (0, 0)

    def protected(self, address: int) -> bool:
        return self.program[0] <= address < self.program[1]


def unknown_memory(address: int) -> int:
    return ANY


@dataclass(frozen=True)
class State:
    """The registers, flags, stack and stored bytes at one point; immutable (each step makes a new one)."""

    a: int = ANY
    x: int = ANY
    y: int = ANY
    c: int = EITHER
    z: int = EITHER
    n: int = EITHER
    v: int = EITHER
    d: int = EITHER
    stored: tuple[tuple[int, int], ...] = ()  # (address, set) the routine wrote, sorted by address
    wild: bool = False  # a store went to an unknown address: unprotected memory is unknown
    stack: tuple | None = ()  # pushed items (("a", set) or ("p", flags)); None: unknown (after TXS)
    nz: str = ""  # the register ("a", "x", "y") whose value N and Z were last set from ("": none)
    _index: dict = field(default=None, compare=False, hash=False, repr=False)

    def read(self, memory: MemoryModel, address: int) -> int:
        address &= 0xFFFF
        if address >> 8 == STACK_PAGE >> 8:
            return ANY
        index = self._lookup()
        if address in index:
            return index[address]
        if self.wild and not memory.protected(address):
            return ANY
        return memory.initial(address)

    def _lookup(self) -> dict:
        if self._index is None:
            object.__setattr__(self, "_index", dict(self.stored))
        return self._index

    def written(self, memory: MemoryModel, addresses: set[int] | None, value: int) -> "State":
        """The state after a store of `value` to one of `addresses` (None: an unknown address)."""
        if addresses is None:
            kept = tuple((a, v) for a, v in self.stored if memory.protected(a))
            return replace(self, stored=kept, wild=True, _index=None)
        index = dict(self._lookup())
        strong = len(addresses) == 1
        for address in addresses:
            if address >> 8 == STACK_PAGE >> 8:
                continue
            index[address] = value if strong else value | self.read(memory, address)
        return replace(self, stored=tuple(sorted(index.items())), _index=None)

    def join(self, other: "State", memory: MemoryModel) -> "State":
        if other is self:
            return self
        mine, theirs = self._lookup(), other._lookup()
        stored = []
        for address in sorted(set(mine) | set(theirs)):
            stored.append((address, (mine[address] if address in mine else self.read(memory, address))
                           | (theirs[address] if address in theirs else other.read(memory, address))))
        if self.stack is not None and other.stack is not None and len(self.stack) == len(other.stack):
            stack = tuple(_join_item(p, q) for p, q in zip(self.stack, other.stack))
        else:
            stack = None
        return State(self.a | other.a, self.x | other.x, self.y | other.y, self.c | other.c, self.z | other.z,
                     self.n | other.n, self.v | other.v, self.d | other.d, tuple(stored), self.wild or other.wild,
                     stack, self.nz if self.nz == other.nz else "")

    def pushed(self, item: tuple) -> "State":
        return replace(self, stack=None if self.stack is None else (*self.stack, item))

    def pulled(self) -> tuple[tuple | None, "State"]:
        if not self.stack:
            return None, replace(self, stack=None)
        return self.stack[-1], replace(self, stack=self.stack[:-1])

    def flags(self) -> tuple[int, int, int, int, int]:
        return self.c, self.z, self.n, self.v, self.d


def _join_item(p: tuple, q: tuple) -> tuple:
    if p[0] == q[0] == "a":
        return ("a", p[1] | q[1])
    if p[0] == q[0] == "p":
        return ("p", tuple(f | g for f, g in zip(p[1], q[1])))
    return ("a", ANY)


def narrowed(state: State, register: str, mask: int) -> State:
    """The state with a register (a, x, y) or flag (c, z, n, v, d) known to lie in `mask`; N and Z
    and the register they were set from narrow each other (after `LDA / BEQ`, A is 0 where taken)."""
    changes = {register: getattr(state, register) & mask}
    source = state.nz
    if register == source:
        changes["z"] = state.z & zero_flag(changes[register])
        changes["n"] = state.n & negative_flag(changes[register])
    elif register in ("z", "n") and source:
        value = getattr(state, source)
        if register == "z":
            value &= {SET: single(0), CLEAR: ANY ^ single(0)}.get(mask, ANY)
        else:
            value &= {SET: HIGH_HALF, CLEAR: LOW_HALF}.get(mask, ANY)
        changes[source] = value
    return replace(state, **changes)


def is_empty(state: State) -> bool:
    return not (state.a and state.x and state.y and state.c and state.z and state.n and state.v and state.d)


# ---- one instruction ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class Step:
    """What one instruction does from a state: the state after it (for a branch, after each way: None
    where that way cannot happen), the extra cycles it may take beyond its base count (least, most:
    page crossings, the 65C02's decimal ADC/SBC), and where it may write (None: unknown)."""

    after: State | None
    extra: tuple[int, int] = (0, 0)
    taken: State | None = None  # branches: the state when taken
    writes: frozenset[int] | None = frozenset()


def _combine(*masks: int) -> list[int] | None:
    """The addresses lo | hi << 8 of every pair of byte sets (None when too many)."""
    lo, hi = masks
    if lo.bit_count() * hi.bit_count() > MAX_ADDRESSES:
        return None
    his = [h << 8 for h in members(hi)]
    return [l | h for l in members(lo) for h in his]


def _indexed(bases: list[int] | None, index: int, wrap: int = 0xFFFF) -> set[int] | None:
    if bases is None or len(bases) * index.bit_count() > MAX_ADDRESSES:
        return None
    indexes = list(members(index))
    return {(b + i) & wrap for b in bases for i in indexes}


def _crossing(low_bytes: int, index: int) -> tuple[int, int]:
    """(certain, possible) page crossing of base + index, base's low byte in `low_bytes`."""
    if not low_bytes or not index:
        return 0, 0
    return int(lowest(low_bytes) + lowest(index) > 0xFF), int(highest(low_bytes) + highest(index) > 0xFF)


def _pointers(state: State, memory: MemoryModel, zero_page: int, index: int = 1) -> list[int] | None:
    """The 16-bit pointers in zero page at (zp + index) for every zp in the set (index 1: none)."""
    places = sorted({(z + i) & 0xFF for z in members(zero_page) for i in members(index)})
    if len(places) > MAX_ADDRESSES:
        return None
    found: set[int] = set()
    for place in places:
        pointers = _combine(state.read(memory, place), state.read(memory, (place + 1) & 0xFF))
        if pointers is None:
            return None
        found.update(pointers)
        if len(found) > MAX_ADDRESSES:
            return None
    return sorted(found)


def effective(state: State, memory: MemoryModel, pc: int, mode: str) -> tuple[set[int] | None, tuple[int, int]]:
    """The addresses an instruction's operand may name, and its page crossing (certain, possible)."""
    b1 = state.read(memory, pc + 1)
    if mode == "zpg":
        return set(members(b1)), (0, 0)
    if mode in ("zpx", "zpy"):
        return _indexed(list(members(b1)), state.x if mode == "zpx" else state.y, 0xFF), (0, 0)
    b2 = state.read(memory, pc + 2)
    if mode == "abs":
        found = _combine(b1, b2)
        return (None if found is None else set(found)), (0, 0)
    if mode in ("abx", "aby"):
        index = state.x if mode == "abx" else state.y
        return _indexed(_combine(b1, b2), index), _crossing(b1, index)
    if mode == "inx":
        pointers = _pointers(state, memory, b1, state.x)
        return (None if pointers is None else set(pointers)), (0, 0)
    if mode in ("iny", "zpi"):
        pointers = _pointers(state, memory, b1)
        if mode == "zpi":
            return (None if pointers is None else set(pointers)), (0, 0)
        lows = 0
        for place in members(b1):
            lows |= state.read(memory, place)
        return _indexed(pointers, state.y), _crossing(lows, state.y)
    raise ValueError(mode)


def read_value(state: State, memory: MemoryModel, addresses: set[int] | None) -> int:
    if addresses is None:
        return ANY
    value = 0
    for address in addresses:
        value |= state.read(memory, address)
        if value == ANY:
            break
    return value


def _pairs(first: int, second: int, carry: int) -> list[tuple[int, int, int]] | None:
    carries = flag_values(carry)
    if first.bit_count() * second.bit_count() * len(carries) > MAX_COMBINATIONS:
        return None
    seconds = list(members(second))
    return [(p, q, c) for p in members(first) for q in seconds for c in carries]


def _with_nz(state: State, register: str | None, value: int, **flags: int) -> State:
    changes = {"z": zero_flag(value), "n": negative_flag(value), **flags}
    if register:
        changes[register] = value
    return replace(state, **changes)


def _add(state: State, operand: int, subtract: bool, decimal: bool) -> State:
    """ADC/SBC of `operand` into A (binary; decimal mode: an unknown result)."""
    if decimal:
        return replace(state, a=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
    combos = _pairs(state.a, operand, state.c)
    if combos is None:
        return replace(state, a=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
    result, carries, overflows = 0, set(), set()
    for a, m, c in combos:
        m = m ^ 0xFF if subtract else m
        total = a + m + c
        r = total & 0xFF
        result |= 1 << r
        carries.add(total > 0xFF)
        overflows.add(bool((a ^ r) & (m ^ r) & 0x80))
    return _with_nz(state, "a", result, c=flag_of(carries), v=flag_of(overflows))


def _compare(state: State, register: int, operand: int) -> State:
    if not register or not operand:
        return replace(state, c=NONE)
    c = (SET if highest(register) >= lowest(operand) else 0) | (CLEAR if lowest(register) < highest(operand) else 0)
    both = register & operand
    z = (SET if both else 0) | (CLEAR if not (is_single(register) and register == operand) else 0)
    combos = _pairs(register, operand, CLEAR)
    n = EITHER if combos is None else flag_of({bool((r - m) & 0x80) for r, m, _ in combos})
    return replace(state, c=c, z=z, n=n)


def _logic(first: int, second: int, function: Callable[[int, int], int]) -> int:
    if is_single(second):
        m = lowest(second)
        return mapped(first, lambda v: function(v, m))
    if is_single(first):
        m = lowest(first)
        return mapped(second, lambda v: function(m, v))
    combos = _pairs(first, second, CLEAR)
    if combos is None:
        return ANY
    return of_values(function(p, q) for p, q, _ in combos)


def _shift(value: int, carry: int, mnemonic: str) -> tuple[int, int]:
    """(result, carry out) of ASL/LSR/ROL/ROR over every value and carry."""
    result, out = 0, set()
    carries = flag_values(carry) if mnemonic in ("ROL", "ROR") else (0,)
    for v in (range(256) if value == ANY else members(value)):
        for c in carries:
            if mnemonic in ("ASL", "ROL"):
                result |= 1 << (((v << 1) | c) & 0xFF)
                out.add(bool(v & 0x80))
            else:
                result |= 1 << ((v >> 1) | (c << 7))
                out.add(bool(v & 1))
    return result, flag_of(out)


BRANCH_FLAGS = {"BPL": ("n", CLEAR), "BMI": ("n", SET), "BVC": ("v", CLEAR), "BVS": ("v", SET),
                "BCC": ("c", CLEAR), "BCS": ("c", SET), "BNE": ("z", CLEAR), "BEQ": ("z", SET)}
READ_MODIFY_WRITE = {"ASL", "LSR", "ROL", "ROR", "INC", "DEC"}
UNDOCUMENTED_RMW = {"SLO", "RLA", "SRE", "RRA", "DCP", "ISC"}
LOADS = {"LDA": "a", "LDX": "x", "LDY": "y"}
STORES = {"STA": "a", "STX": "x", "STY": "y"}
TRANSFERS = {"TAX": ("a", "x"), "TAY": ("a", "y"), "TXA": ("x", "a"), "TYA": ("y", "a"), "TSX": (None, "x")}
FLAG_OPS = {"CLC": ("c", CLEAR), "SEC": ("c", SET), "CLD": ("d", CLEAR), "SED": ("d", SET), "CLV": ("v", CLEAR),
            "CLI": (None, 0), "SEI": (None, 0)}
COUNTERS = {"INX": ("x", increment), "INY": ("y", increment), "DEX": ("x", decrement), "DEY": ("y", decrement)}


NZ_FROM = {"LDA": "a", "LDX": "x", "LDY": "y", "TAX": "x", "TAY": "y", "TXA": "a", "TYA": "a", "TSX": "x",
           "INX": "x", "INY": "y", "DEX": "x", "DEY": "y", "PLA": "a", "PLX": "x", "PLY": "y", "ADC": "a",
           "SBC": "a", "AND": "a", "ORA": "a", "EOR": "a", "LAX": "a"}
NZ_KEPT = {"STA", "STX", "STY", "STZ", "SAX", "CLC", "SEC", "CLD", "SED", "CLV", "CLI", "SEI", "NOP", "PHA", "PHP",
           "PHX", "PHY", "TXS", "BRA", *BRANCH_FLAGS}


def execute(state: State, memory: MemoryModel, pc: int, mnemonic: str, mode: str, cpu: str,
            binary_only: bool = False, page_penalty: bool = True) -> Step:
    """One instruction (not JSR, RTS or JMP, which the flow handles) from `state`. `binary_only`:
    the CPU ignores D (the 2A03); `page_penalty`: the instruction pays a page crossing (indexed reads;
    stores and most read-modify-writes take the longer count always, retro.cpu.opcodes)."""
    step = _execute(state, memory, pc, mnemonic, mode, cpu, binary_only, page_penalty)
    if mnemonic in NZ_KEPT or mode == "zpr" or mnemonic[:3] in ("RMB", "SMB"):
        return step
    source = NZ_FROM.get(mnemonic, "a" if mode == "acc" else "")
    return replace(step, after=None if step.after is None else replace(step.after, nz=source))


def _execute(state: State, memory: MemoryModel, pc: int, mnemonic: str, mode: str, cpu: str,
             binary_only: bool, page_penalty: bool) -> Step:
    if mode == "rel":  # a branch: the flag it tests, narrowed on each way
        if mnemonic == "BRA":
            return Step(None, taken=state)
        flag, wanted = BRANCH_FLAGS[mnemonic]
        other = EITHER ^ wanted
        value = getattr(state, flag)
        return Step(narrowed(state, flag, other) if value & other else None,
                    taken=narrowed(state, flag, wanted) if value & wanted else None)
    if mode == "zpr":  # 65C02 BBRn/BBSn zp, target: the bit of a zero-page byte
        bit = 1 << int(mnemonic[3])
        byte = state.read(memory, pc + 1)
        tested = read_value(state, memory, set(members(byte)))
        ones = any(v & bit for v in members(tested))
        zeros = any(not v & bit for v in members(tested))
        set_taken = mnemonic.startswith("BBS")
        return Step(state if (zeros if set_taken else ones) else None,
                    taken=state if (ones if set_taken else zeros) else None)
    if mode in ("imp", "acc"):
        return Step(_implied(state, mnemonic, mode))
    if mode == "imm":
        operand = state.read(memory, pc + 1)
        addresses, crossing = frozenset(), (0, 0)
    else:
        found, crossing = effective(state, memory, pc, mode)
        addresses = None if found is None else frozenset(found)
        operand = None  # read below only by the instructions that read
    decimal = (not binary_only) and mnemonic in ("ADC", "SBC", "ISC", "RRA") and bool(state.d & SET)
    extra = crossing if page_penalty else (0, 0)
    if cpu == "65c02" and mnemonic in ("ADC", "SBC") and state.d & SET:
        extra = (extra[0] + (1 if state.d == SET else 0), extra[1] + 1)

    def value() -> int:
        return operand if operand is not None else read_value(state, memory, addresses)

    def store(s: State, written: int) -> Step:
        return Step(s.written(memory, None if addresses is None else set(addresses), written), extra,
                    writes=addresses)

    if mnemonic in LOADS:
        return Step(_with_nz(state, LOADS[mnemonic], value()), extra)
    if mnemonic == "LAX":
        v = value()
        return Step(_with_nz(replace(state, x=v), "a", v), extra)
    if mnemonic in STORES:
        return store(state, getattr(state, STORES[mnemonic]))
    if mnemonic == "STZ":
        return store(state, single(0))
    if mnemonic == "SAX":
        return store(state, _logic(state.a, state.x, lambda p, q: p & q))
    if mnemonic in ("ADC", "SBC"):
        return Step(_add(state, value(), mnemonic == "SBC", decimal), extra)
    if mnemonic in ("AND", "ORA", "EOR"):
        function = {"AND": lambda p, q: p & q, "ORA": lambda p, q: p | q, "EOR": lambda p, q: p ^ q}[mnemonic]
        return Step(_with_nz(state, "a", _logic(state.a, value(), function)), extra)
    if mnemonic in ("CMP", "CPX", "CPY"):
        register = {"CMP": state.a, "CPX": state.x, "CPY": state.y}[mnemonic]
        return Step(_compare(state, register, value()), extra)
    if mnemonic == "BIT":
        m = value()
        z = EITHER if _pairs(state.a, m, CLEAR) is None else flag_of(
            {not (p & q) for p, q, _ in _pairs(state.a, m, CLEAR)})
        if mode == "imm":  # the 65C02's BIT #imm sets only Z
            return Step(replace(state, z=z), extra)
        v = flag_of({bool(q & 0x40) for q in members(m)}) if m != ANY else EITHER
        return Step(replace(state, z=z, n=negative_flag(m), v=v), extra)
    if mnemonic in READ_MODIFY_WRITE:
        m = value()
        if mnemonic in ("INC", "DEC"):
            result = increment(m) if mnemonic == "INC" else decrement(m)
            after = _with_nz(state, None, result)
        else:
            result, carry = _shift(m, state.c, mnemonic)
            after = _with_nz(state, None, result, c=carry)
        return store(after, result)
    if mnemonic in ("TSB", "TRB"):
        m = value()
        z = EITHER if _pairs(state.a, m, CLEAR) is None else flag_of(
            {not (p & q) for p, q, _ in _pairs(state.a, m, CLEAR)})
        result = _logic(m, state.a, (lambda p, q: p | q) if mnemonic == "TSB" else (lambda p, q: p & ~q & 0xFF))
        return store(replace(state, z=z), result)
    if mnemonic[:3] in ("RMB", "SMB"):
        bit = 1 << int(mnemonic[3])
        result = mapped(value(), (lambda v: v & ~bit) if mnemonic.startswith("R") else (lambda v: v | bit))
        return store(state, result)
    if mnemonic == "NOP":
        return Step(state, extra)
    unknown = replace(state, a=ANY, x=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
    if mnemonic in UNDOCUMENTED_RMW:  # their arithmetic is not followed: the byte and A become unknown
        return store(unknown, ANY)
    return Step(unknown, extra)  # ANC, ALR, ARR, SBX and the like: A, X and the flags unknown


def _implied(state: State, mnemonic: str, mode: str) -> State:
    if mnemonic in TRANSFERS:
        source, target = TRANSFERS[mnemonic]
        return _with_nz(state, target, ANY if source is None else getattr(state, source))
    if mnemonic == "TXS":
        return replace(state, stack=None)
    if mnemonic in COUNTERS:
        register, function = COUNTERS[mnemonic]
        return _with_nz(state, register, function(getattr(state, register)))
    if mnemonic in FLAG_OPS:
        flag, value = FLAG_OPS[mnemonic]
        return state if flag is None else replace(state, **{flag: value})
    if mode == "acc":  # ASL A and friends; the 65C02's INC A and DEC A
        if mnemonic in ("INC", "DEC"):
            return _with_nz(state, "a", increment(state.a) if mnemonic == "INC" else decrement(state.a))
        result, carry = _shift(state.a, state.c, mnemonic)
        return _with_nz(state, "a", result, c=carry)
    if mnemonic in ("PHA", "PHX", "PHY"):
        return state.pushed(("a", getattr(state, mnemonic[2].lower())))
    if mnemonic == "PHP":
        return state.pushed(("p", state.flags()))
    if mnemonic in ("PLA", "PLX", "PLY"):
        item, after = state.pulled()
        value = item[1] if item is not None and item[0] == "a" else ANY
        return _with_nz(after, mnemonic[2].lower(), value)
    if mnemonic == "PLP":
        item, after = state.pulled()
        c, z, n, v, d = item[1] if item is not None and item[0] == "p" else (EITHER,) * 5
        return replace(after, c=c, z=z, n=n, v=v, d=d)
    if mnemonic == "NOP":
        return state
    return replace(state, a=ANY, x=ANY, y=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
