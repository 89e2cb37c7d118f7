"""Each instruction's effect on what the static analysis knows (retro.cpu.values): the addresses
its operand may name and its page crossing (certain, possible), the state after it (after each
way of a branch), and where it may write. retro.cpu.flow drives it along the paths.

Results that would need too many combinations of operands or addresses are taken as unknown
(MAX_COMBINATIONS, MAX_ADDRESSES): the sets only ever grow toward "any value". The instructions
with an operand are dispatched by mnemonic (MEMORY_OPERATIONS), the implied ones too (IMPLIED_OPERATIONS);
the assumptions are values.py's (docs/specs.md).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from retro.cpu.values import (
    ANY,
    CLEAR,
    EITHER,
    NONE,
    SET,
    MemoryModel,
    State,
    decrement,
    flag_of,
    flag_values,
    highest,
    increment,
    is_single,
    lowest,
    mapped,
    members,
    narrowed,
    negative_flag,
    of_values,
    single,
    zero_flag,
)

MAX_COMBINATIONS = 4096  # operand combinations enumerated before a result is taken as unknown
MAX_ADDRESSES = 512  # addresses an indexed or indirect access may touch before it is taken as unknown


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
    return state.changed(**changes)


def _add(state: State, operand: int, subtract: bool, decimal: bool) -> State:
    """ADC/SBC of `operand` into A (binary; decimal mode: an unknown result)."""
    if decimal:
        return state.changed(a=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
    combos = _pairs(state.a, operand, state.c)
    if combos is None:
        return state.changed(a=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
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
        return state.changed(c=NONE)
    c = (SET if highest(register) >= lowest(operand) else 0) | (CLEAR if lowest(register) < highest(operand) else 0)
    both = register & operand
    z = (SET if both else 0) | (CLEAR if not (is_single(register) and register == operand) else 0)
    n = EITHER if register.bit_count() * operand.bit_count() > MAX_COMBINATIONS else difference_sign(register, operand)
    return state.changed(c=c, z=z, n=n)


HALF_RANGE = (1 << 128) - 1  # 128 consecutive byte values


def difference_sign(register: int, operand: int) -> int:
    """N of a compare over every pair of the two sets (bit 7 of r - m), as a flag: for each r, bit 7 is set
    for m in r+1..r+128 and clear for m in r+129..r+256 (mod 256), two windows of the operand's set,
    read from it doubled (no pair enumerated: a static analysis of tile_box's loops compared 1,027 sets)."""
    doubled = operand | (operand << 256)
    found = 0
    for r in members(register):
        if (doubled >> ((r + 1) & 0xFF)) & HALF_RANGE:
            found |= SET
        if (doubled >> ((r + 129) & 0xFF)) & HALF_RANGE:
            found |= CLEAR
        if found == EITHER:
            break
    return found


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
    return replace(step, after=None if step.after is None else step.after.changed(nz=source))


def _execute(state: State, memory: MemoryModel, pc: int, mnemonic: str, mode: str, cpu: str,
             binary_only: bool, page_penalty: bool) -> Step:
    if mode == "rel":
        return _branch(state, mnemonic)
    if mode == "zpr":
        return _bit_branch(state, memory, pc, mnemonic)
    if mode in ("imp", "acc"):
        return Step(_implied(state, mnemonic, mode))
    operand = _Operand.at(state, memory, pc, mode, page_penalty, cpu, binary_only)
    return MEMORY_OPERATIONS.get(mnemonic, _unknown)(operand, mnemonic)


def _branch(state: State, mnemonic: str) -> Step:
    """A branch: the flag it tests, narrowed on each way."""
    if mnemonic == "BRA":
        return Step(None, taken=state)
    flag, wanted = BRANCH_FLAGS[mnemonic]
    other = EITHER ^ wanted
    value = getattr(state, flag)
    return Step(narrowed(state, flag, other) if value & other else None,
                taken=narrowed(state, flag, wanted) if value & wanted else None)


def _bit_branch(state: State, memory: MemoryModel, pc: int, mnemonic: str) -> Step:
    """65C02 BBRn/BBSn zp, target: the bit of a zero-page byte."""
    bit = 1 << int(mnemonic[3])
    byte = state.read(memory, pc + 1)
    tested = read_value(state, memory, set(members(byte)))
    ones = any(v & bit for v in members(tested))
    zeros = any(not v & bit for v in members(tested))
    set_taken = mnemonic.startswith("BBS")
    return Step(state if (zeros if set_taken else ones) else None,
                taken=state if (ones if set_taken else zeros) else None)


@dataclass(frozen=True)
class _Operand:
    """An instruction's operand in a state: an immediate byte, or the addresses it may name (None:
    unknown), and the page crossing it pays (certain, possible); the CPU it runs on."""

    state: State
    memory: MemoryModel
    immediate: int | None
    addresses: frozenset[int] | None
    extra: tuple[int, int]
    cpu: str
    binary_only: bool  # the CPU ignores D (the 2A03)

    @classmethod
    def at(cls, state: State, memory: MemoryModel, pc: int, mode: str, page_penalty: bool, cpu: str,
           binary_only: bool) -> "_Operand":
        if mode == "imm":
            return cls(state, memory, state.read(memory, pc + 1), frozenset(), (0, 0), cpu, binary_only)
        found, crossing = effective(state, memory, pc, mode)
        return cls(state, memory, None, None if found is None else frozenset(found),
                   crossing if page_penalty else (0, 0), cpu, binary_only)

    def value(self) -> int:
        """The values the operand may read (read only by the instructions that read)."""
        return self.immediate if self.immediate is not None else read_value(self.state, self.memory, self.addresses)

    def giving(self, after: State) -> Step:
        return Step(after, self.extra)

    def storing(self, after: State, written: int) -> Step:
        addresses = None if self.addresses is None else set(self.addresses)
        return Step(after.written(self.memory, addresses, written), self.extra, writes=self.addresses)


def _and(p: int, q: int) -> int:
    return p & q


def _or(p: int, q: int) -> int:
    return p | q


def _eor(p: int, q: int) -> int:
    return p ^ q


def _load(operand: _Operand, mnemonic: str) -> Step:
    return operand.giving(_with_nz(operand.state, LOADS[mnemonic], operand.value()))


def _load_a_and_x(operand: _Operand, mnemonic: str) -> Step:  # LAX
    v = operand.value()
    return operand.giving(_with_nz(operand.state.changed(x=v), "a", v))


def _store(operand: _Operand, mnemonic: str) -> Step:
    return operand.storing(operand.state, getattr(operand.state, STORES[mnemonic]))


def _store_zero(operand: _Operand, mnemonic: str) -> Step:  # STZ
    return operand.storing(operand.state, single(0))


def _store_a_and_x(operand: _Operand, mnemonic: str) -> Step:  # SAX
    return operand.storing(operand.state, _logic(operand.state.a, operand.state.x, _and))


def _add_or_subtract(operand: _Operand, mnemonic: str) -> Step:
    """ADC, SBC; the 65C02 takes a cycle more in decimal mode."""
    state, extra = operand.state, operand.extra
    if operand.cpu == "65c02" and state.d & SET:
        extra = (extra[0] + (1 if state.d == SET else 0), extra[1] + 1)
    decimal = not operand.binary_only and bool(state.d & SET)
    return Step(_add(state, operand.value(), mnemonic == "SBC", decimal), extra)


LOGIC = {"AND": _and, "ORA": _or, "EOR": _eor}


def _logical(operand: _Operand, mnemonic: str) -> Step:
    state = operand.state
    return operand.giving(_with_nz(state, "a", _logic(state.a, operand.value(), LOGIC[mnemonic])))


COMPARED = {"CMP": "a", "CPX": "x", "CPY": "y"}


def _compared(operand: _Operand, mnemonic: str) -> Step:
    state = operand.state
    return operand.giving(_compare(state, getattr(state, COMPARED[mnemonic]), operand.value()))


def _zero_of_and(a: int, m: int) -> int:
    """Z after testing A & M (BIT, TSB, TRB)."""
    combos = _pairs(a, m, CLEAR)
    return EITHER if combos is None else flag_of({not (p & q) for p, q, _ in combos})


def _bit_test(operand: _Operand, mnemonic: str) -> Step:
    state, m = operand.state, operand.value()
    z = _zero_of_and(state.a, m)
    if operand.immediate is not None:  # the 65C02's BIT #imm sets only Z
        return operand.giving(state.changed(z=z))
    v = flag_of({bool(q & 0x40) for q in members(m)}) if m != ANY else EITHER
    return operand.giving(state.changed(z=z, n=negative_flag(m), v=v))


def _read_modify_write(operand: _Operand, mnemonic: str) -> Step:
    """ASL, LSR, ROL, ROR, INC, DEC on memory."""
    state, m = operand.state, operand.value()
    if mnemonic in ("INC", "DEC"):
        result = increment(m) if mnemonic == "INC" else decrement(m)
        return operand.storing(_with_nz(state, None, result), result)
    result, carry = _shift(m, state.c, mnemonic)
    return operand.storing(_with_nz(state, None, result, c=carry), result)


def _test_and_change_bits(operand: _Operand, mnemonic: str) -> Step:  # TSB, TRB
    state, m = operand.state, operand.value()
    change = _or if mnemonic == "TSB" else (lambda p, q: p & ~q & 0xFF)
    return operand.storing(state.changed(z=_zero_of_and(state.a, m)), _logic(m, state.a, change))


def _change_bit(operand: _Operand, mnemonic: str) -> Step:  # RMBn, SMBn
    bit = 1 << int(mnemonic[3])
    result = mapped(operand.value(), (lambda v: v & ~bit) if mnemonic.startswith("R") else (lambda v: v | bit))
    return operand.storing(operand.state, result)


def _no_operation(operand: _Operand, mnemonic: str) -> Step:
    return operand.giving(operand.state)


def _unknown(operand: _Operand, mnemonic: str) -> Step:
    """ANC, ALR, ARR, SBX and the like: A, X and the flags unknown; the undocumented read-modify-writes'
    arithmetic is not followed either: the byte they write becomes unknown too."""
    unknown = operand.state.changed(a=ANY, x=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)
    if mnemonic in UNDOCUMENTED_RMW:
        return operand.storing(unknown, ANY)
    return operand.giving(unknown)


# The instructions with an operand in memory or an immediate byte, by mnemonic (others: _unknown).
MEMORY_OPERATIONS: dict[str, Callable[[_Operand, str], Step]] = {
    **{m: _load for m in LOADS}, "LAX": _load_a_and_x,
    **{m: _store for m in STORES}, "STZ": _store_zero, "SAX": _store_a_and_x,
    "ADC": _add_or_subtract, "SBC": _add_or_subtract, **{m: _logical for m in LOGIC},
    **{m: _compared for m in COMPARED}, "BIT": _bit_test,
    **{m: _read_modify_write for m in READ_MODIFY_WRITE}, "TSB": _test_and_change_bits, "TRB": _test_and_change_bits,
    **{f"{kind}{n}": _change_bit for kind in ("RMB", "SMB") for n in range(8)}, "NOP": _no_operation,
}


def _implied(state: State, mnemonic: str, mode: str) -> State:
    """An instruction without an operand byte (the others of the 6502's rows: A, X, Y and the flags
    unknown)."""
    if mode == "acc":
        return _on_accumulator(state, mnemonic)
    return IMPLIED_OPERATIONS.get(mnemonic, _unknown_registers)(state, mnemonic)


def _on_accumulator(state: State, mnemonic: str) -> State:
    """ASL A and friends; the 65C02's INC A and DEC A."""
    if mnemonic in ("INC", "DEC"):
        return _with_nz(state, "a", increment(state.a) if mnemonic == "INC" else decrement(state.a))
    result, carry = _shift(state.a, state.c, mnemonic)
    return _with_nz(state, "a", result, c=carry)


def _transfer(state: State, mnemonic: str) -> State:
    source, target = TRANSFERS[mnemonic]
    return _with_nz(state, target, ANY if source is None else getattr(state, source))


def _count(state: State, mnemonic: str) -> State:
    register, function = COUNTERS[mnemonic]
    return _with_nz(state, register, function(getattr(state, register)))


def _set_flag(state: State, mnemonic: str) -> State:
    flag, value = FLAG_OPS[mnemonic]
    return state if flag is None else state.changed(**{flag: value})


def _push_register(state: State, mnemonic: str) -> State:  # PHA, PHX, PHY
    return state.pushed(("a", getattr(state, mnemonic[2].lower())))


def _pull_register(state: State, mnemonic: str) -> State:  # PLA, PLX, PLY
    item, after = state.pulled()
    value = item[1] if item is not None and item[0] == "a" else ANY
    return _with_nz(after, mnemonic[2].lower(), value)


def _pull_flags(state: State, mnemonic: str) -> State:  # PLP
    item, after = state.pulled()
    c, z, n, v, d = item[1] if item is not None and item[0] == "p" else (EITHER,) * 5
    return after.changed(c=c, z=z, n=n, v=v, d=d)


def _unknown_registers(state: State, mnemonic: str) -> State:
    return state.changed(a=ANY, x=ANY, y=ANY, c=EITHER, z=EITHER, n=EITHER, v=EITHER)


# The implied instructions by mnemonic (others: _unknown_registers).
IMPLIED_OPERATIONS: dict[str, Callable[[State, str], State]] = {
    **{m: _transfer for m in TRANSFERS}, "TXS": lambda state, _: state.changed(stack=None),
    **{m: _count for m in COUNTERS}, **{m: _set_flag for m in FLAG_OPS},
    **{m: _push_register for m in ("PHA", "PHX", "PHY")}, "PHP": lambda state, _: state.pushed(("p", state.flags())),
    **{m: _pull_register for m in ("PLA", "PLX", "PLY")}, "PLP": _pull_flags, "NOP": lambda state, _: state,
}
