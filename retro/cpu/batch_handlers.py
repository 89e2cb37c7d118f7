"""The batched core's handlers (retro.cpu.batch): one function per opcode of the NMOS 6502's table,
built from its row (`retro.cpu.opcodes`: mnemonic, mode, cycles, page penalty, kind) and the branch
timing of `retro.cpu.timing`. A handler takes a group of lanes at one address (`retro.cpu.batch.Lanes`)
and the operand bytes, runs the instruction on every lane of the group with numpy, adds its cycles
and returns the next address (an int, or per-lane addresses that the core splits the group by).

The operand addresses by mode (`ADDRESSING`), the arithmetic (ADC/SBC with the NMOS decimal mode:
Bruce Clark, "Decimal Mode" tutorial, appendix A; compares, shifts) and the stable undocumented
opcodes ("NMOS 6510 Unintended Opcodes - No More Secrets", groepaz, 2024) are here;
`retro.cpu.batch65c02` builds the 65C02's table from these rows and its own.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum

import numpy as np

from retro.cpu.lane_memory import BYTE
from retro.cpu.mpu import FLAG_B, FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_U, FLAG_V, FLAG_Z, IRQ_VECTOR
from retro.cpu.opcodes import DOCUMENTED, MODE_LENGTH, OPCODE_TABLE, STABLE
from retro.cpu.timing import BRANCH_CONDITIONS, BRANCH_PAGE_CYCLES, BRANCH_TAKEN_CYCLES, PAGE_CROSS_CYCLES, PAGE_MASK

STACK_PAGE = 0x100
WORD = 0xFFFF
NZ = FLAG_N | FLAG_Z
NVZC = FLAG_N | FLAG_V | FLAG_Z | FLAG_C


class LaneError(IntEnum):
    """Why a lane stopped before returning (0 = running or returned)."""

    NONE = 0
    BRK = 1
    JAM = 2
    UNSTABLE = 3
    BUDGET = 4
    HALT = 5  # the 65C02's STP, or WAI with no interrupt source
    FACT = 6  # the lane contradicted a `watch` (a fact its spec states) before the instruction there


def _signed(offset):
    return offset - ((offset & 0x80) << 1)


def _uniform(values):
    """An int when every element of the array is the same (or it already is an int)."""
    if isinstance(values, (int, np.integer)):
        return int(values)
    if len(values) and values.min() == values.max():
        return int(values[0])
    return values


def _nz(p, value):
    return (p & ~NZ) | NZ_TABLE[value]


# ---- operand addresses ---------------------------------------------------------------------------------
# Each returns (address, crossed) for a group: crossed is whether indexing moved the address into
# another page (an int or per-lane array address; a bool or per-lane bools).

def _zpg(g, lo, hi):
    return lo, False


def _zpx(g, lo, hi):
    return (lo + g.x) & BYTE, False


def _zpy(g, lo, hi):
    return (lo + g.y) & BYTE, False


def _abs(g, lo, hi):
    return lo | hi << 8, False


def _indexed(base, index):
    address = (base + index) & WORD
    return address, (base & PAGE_MASK) != (address & PAGE_MASK)


def _abx(g, lo, hi):
    return _indexed(lo | hi << 8, g.x)


def _aby(g, lo, hi):
    return _indexed(lo | hi << 8, g.y)


def _inx(g, lo, hi):
    pointer = _uniform((lo + g.x) & BYTE)
    return _uniform(g.read(pointer) | g.read((pointer + 1) & BYTE) << 8), False


def _iny(g, lo, hi):
    base = _uniform(g.read(lo) | g.read((lo + 1) & BYTE) << 8)
    return _indexed(base, g.y)


ADDRESSING = {"zpg": _zpg, "zpx": _zpx, "zpy": _zpy, "abs": _abs, "abx": _abx, "aby": _aby,
              "inx": _inx, "iny": _iny}


# ---- arithmetic ------------------------------------------------------------------------------------------

def _adc_table() -> np.ndarray:
    """Binary ADC of every (A, operand, carry): result | (N V Z C) << 8, indexed A << 9 | operand << 1 | C."""
    a, value, carry = (axis.ravel() for axis in np.meshgrid(np.arange(256), np.arange(256), np.arange(2), indexing="ij"))
    total = a + value + carry
    result = total & BYTE
    overflow = (~(a ^ value) & (a ^ result) & 0x80) != 0
    flags = (result & FLAG_N) | overflow * FLAG_V | (result == 0) * FLAG_Z | (total > BYTE) * FLAG_C
    return (result | flags << 8).astype(np.uint16)  # 256 KiB: stays in cache


def _compare_table() -> np.ndarray:
    """N Z C of CMP for every (register, operand), indexed register << 8 | operand."""
    register, value = (axis.ravel() for axis in np.meshgrid(np.arange(256), np.arange(256), indexing="ij"))
    difference = (register - value) & BYTE
    return ((difference & FLAG_N) | (difference == 0) * FLAG_Z | (register >= value) * FLAG_C).astype(np.uint8)


ADC_TABLE = _adc_table()
COMPARE_TABLE = _compare_table()
NZ_TABLE = np.array([(v & FLAG_N) | (v == 0) * FLAG_Z for v in range(256)], dtype=np.int32)


def _binary_adc(a, value, p):
    packed = ADC_TABLE[(a << 9) | (value << 1) | (p & FLAG_C)].astype(np.int32)
    return packed & BYTE, (p & ~NVZC) | (packed >> 8)


def _adc(g, a, value, p):
    """(A, P) after ADC: binary, or NMOS decimal for lanes with D set on a CPU that has it."""
    carry = p & FLAG_C
    total = a + value + carry
    result, flags = _binary_adc(a, value, p)
    if not g.cpu.decimal:
        return result, flags
    decimal = (p & FLAG_D) != 0
    if not np.any(decimal):
        return result, flags
    # Bruce Clark, "Decimal Mode", appendix A, sequences 1 and 2 (6502): Z from the binary sum.
    low = (a & 0x0F) + (value & 0x0F) + carry
    low = np.where(low >= 0x0A, ((low + 0x06) & 0x0F) + 0x10, low)
    high = (a & 0xF0) + (value & 0xF0) + low
    signed = _signed(a & 0xF0) + _signed(value & 0xF0) + low  # sequence 2: N and V before the high adjust
    dec_overflow = (signed < -128) | (signed > 127)
    high = np.where(high >= 0xA0, high + 0x60, high)
    dec_result = high & BYTE
    dec_flags = ((p & ~NVZC) | (signed & FLAG_N) | (dec_overflow * FLAG_V) | ((total & BYTE) == 0) * FLAG_Z
                 | (high > BYTE) * FLAG_C)
    return np.where(decimal, dec_result, result), np.where(decimal, dec_flags, flags)


def _sbc(g, a, value, p):
    """(A, P) after SBC: flags from the binary difference in both modes (NMOS); A decimal-adjusted."""
    result, flags = _binary_adc(a, value ^ BYTE, p)
    if not g.cpu.decimal:
        return result, flags
    decimal = (p & FLAG_D) != 0
    if not np.any(decimal):
        return result, flags
    borrow = 1 - (p & FLAG_C)
    low = (a & 0x0F) - (value & 0x0F) - borrow  # Clark, sequence 3
    low = np.where(low < 0, ((low - 0x06) & 0x0F) - 0x10, low)
    high = (a & 0xF0) - (value & 0xF0) + low
    high = np.where(high < 0, high - 0x60, high)
    return np.where(decimal, high & BYTE, result), flags


def _compare(register, value, p):
    return (p & ~(NZ | FLAG_C)) | COMPARE_TABLE[(register << 8) | value]


def _asl(value, p):
    result = (value << 1) & BYTE
    return result, (_nz(p, result) & ~FLAG_C) | (value >> 7)


def _lsr(value, p):
    result = value >> 1
    return result, (_nz(p, result) & ~FLAG_C) | (value & FLAG_C)


def _rol(value, p):
    result = ((value << 1) | (p & FLAG_C)) & BYTE
    return result, (_nz(p, result) & ~FLAG_C) | (value >> 7)


def _ror(value, p):
    result = (value >> 1) | ((p & FLAG_C) << 7)
    return result, (_nz(p, result) & ~FLAG_C) | (value & FLAG_C)


def _inc(value, p):
    result = (value + 1) & BYTE
    return result, _nz(p, result)


def _dec(value, p):
    result = (value - 1) & BYTE
    return result, _nz(p, result)


SHIFTS = {"ASL": _asl, "LSR": _lsr, "ROL": _rol, "ROR": _ror, "INC": _inc, "DEC": _dec}


# ---- handlers -------------------------------------------------------------------------------------------
# A handler runs one opcode for a group of lanes (pc, lo, hi: ints or per-lane arrays), adds its cycles
# and returns the next PC (an int or per-lane array) or a list of (next pc, lanes). Registers are
# rebound, never changed in place (two registers may share one array after a transfer).

Handler = Callable[..., object]


def _next(pc, length: int):
    return (pc + length) & WORD


def _full(g, value) -> np.ndarray:
    """A per-lane register value (a constant becomes one per lane)."""
    if isinstance(value, (int, np.integer)):
        return np.full(len(g), value, dtype=np.int32)
    return value


def _add_cycles(g, base: int, crossed, penalised: bool) -> None:
    if penalised and crossed is not False:
        g.cycles += base + np.asarray(crossed, dtype=np.int64) * PAGE_CROSS_CYCLES
    else:
        g.cycles += base


def _operation(mnemonic: str):
    """What a reading instruction does with its operand value, as fn(group, value)."""
    if mnemonic in ("LDA", "LDX", "LDY", "LAX"):
        def load(g, value):
            value = _full(g, value)
            if mnemonic in ("LDA", "LAX"):
                g.a = value
            if mnemonic in ("LDX", "LAX"):
                g.x = value
            if mnemonic == "LDY":
                g.y = value
            g.p = _nz(g.p, value)
        return load
    if mnemonic in ("ORA", "AND", "EOR"):
        combine = {"ORA": np.bitwise_or, "AND": np.bitwise_and, "EOR": np.bitwise_xor}[mnemonic]

        def logic(g, value):
            g.a = combine(g.a, value)
            g.p = _nz(g.p, g.a)
        return logic
    if mnemonic == "ADC":
        def add(g, value):
            g.a, g.p = _adc(g, g.a, value, g.p)
        return add
    if mnemonic in ("SBC", "USBC"):
        def subtract(g, value):
            g.a, g.p = _sbc(g, g.a, value, g.p)
        return subtract
    if mnemonic in ("CMP", "CPX", "CPY"):
        register = {"CMP": "a", "CPX": "x", "CPY": "y"}[mnemonic]

        def compare(g, value):
            g.p = _compare(getattr(g, register), value, g.p)
        return compare
    if mnemonic == "BIT":
        def bit(g, value):
            g.p = ((g.p & ~(FLAG_N | FLAG_V | FLAG_Z)) | (value & (FLAG_N | FLAG_V)) | (((g.a & value) == 0) * FLAG_Z))
        return bit
    if mnemonic == "ANC":
        def anc(g, value):
            g.a = g.a & value
            g.p = (_nz(g.p, g.a) & ~FLAG_C) | (g.a >> 7)
        return anc
    if mnemonic == "ALR":
        def alr(g, value):
            g.a, g.p = _lsr(g.a & value, g.p)
        return alr
    if mnemonic == "ARR":
        def arr(g, value):
            g.a, g.p = _arr(g, g.a & value, g.p)
        return arr
    if mnemonic == "SBX":
        def sbx(g, value):
            both = g.a & g.x
            g.x = (both - value) & BYTE
            g.p = _compare(both, value, g.p)
        return sbx
    if mnemonic == "NOP":
        return lambda g, value: None
    raise AssertionError(mnemonic)  # pragma: no cover - READS lists only the mnemonics handled here


def _make_read(mnemonic: str, mode: str, cycles: int, penalised: bool, length: int, *,
               operate: Callable | None = None, address_of: Callable | None = None) -> Handler:
    """Instructions that read an operand (immediate or memory) and change registers and flags
    (`operate`, `address_of`: another CPU's operation or addressing mode, by default the NMOS ones)."""
    address_of = address_of or ADDRESSING.get(mode)
    operate = operate or _operation(mnemonic)
    if mode == "imm":
        def handler(g, pc, lo, hi):
            operate(g, lo)
            g.cycles += cycles
            return _next(pc, length)
    elif mode == "imp":  # the undocumented one-byte NOPs
        def handler(g, pc, lo, hi):
            g.cycles += cycles
            return _next(pc, length)
    else:
        def handler(g, pc, lo, hi):
            address, crossed = address_of(g, lo, hi)
            operate(g, g.read(_uniform(address)))
            _add_cycles(g, cycles, crossed, penalised)
            return _next(pc, length)
    return handler


def _arr(g, value, p):
    """ARR: AND then ROR A with its own flags (No More Secrets, "ARR"; decimal mode as 64doc)."""
    carry = p & FLAG_C
    result = (value >> 1) | (carry << 7)
    flags = ((p & ~NVZC) | (result & FLAG_N) | ((result == 0) * FLAG_Z) | ((result >> 6) & 1) * FLAG_C
             | (((result >> 6) ^ (result >> 5)) & 1) * FLAG_V)
    if not g.cpu.decimal:
        return result, flags
    decimal = (p & FLAG_D) != 0
    if not np.any(decimal):
        return result, flags
    low = value & 0x0F
    high = value >> 4
    dec_flags = ((p & ~NVZC) | (carry << 7) | ((result == 0) * FLAG_Z) | (((value ^ result) & 0x40) != 0) * FLAG_V)
    dec = np.where(low + (low & 1) > 5, (result & 0xF0) | ((result + 6) & 0x0F), result)
    high_carry = high + (high & 1) > 5
    dec = np.where(high_carry, (dec + 0x60) & BYTE, dec)
    dec_flags = dec_flags | high_carry * FLAG_C
    return np.where(decimal, dec, result), np.where(decimal, dec_flags, flags)


def _make_store(mnemonic: str, mode: str, cycles: int, length: int, *, address_of: Callable | None = None) -> Handler:
    """Instructions that write a register (or zero: the 65C02's STZ) to memory."""
    address_of = address_of or ADDRESSING[mode]
    source = {"STA": lambda g: g.a, "STX": lambda g: g.x, "STY": lambda g: g.y, "SAX": lambda g: g.a & g.x,
              "STZ": lambda g: 0}[mnemonic]

    def handler(g, pc, lo, hi):
        address, _ = address_of(g, lo, hi)
        g.write(_uniform(address), source(g))
        g.cycles += cycles
        return _next(pc, length)
    return handler


# Read-modify-write opcodes: the shift or step, then (undocumented ones) an ALU operation with A.
COMBINED = {"SLO": ("ASL", "ORA"), "RLA": ("ROL", "AND"), "SRE": ("LSR", "EOR"), "RRA": ("ROR", "ADC"),
            "DCP": ("DEC", "CMP"), "ISC": ("INC", "SBC")}


def _make_rmw(mnemonic: str, mode: str, cycles: int, length: int) -> Handler:
    shift, then = COMBINED.get(mnemonic, (mnemonic, None))
    change = SHIFTS[shift]
    operate = _operation(then) if then is not None else None
    if mode == "acc":
        def handler(g, pc, lo, hi):
            g.a, g.p = change(g.a, g.p)
            g.cycles += cycles
            return _next(pc, length)
        return handler
    address_of = ADDRESSING[mode]

    def handler(g, pc, lo, hi):
        address, _ = address_of(g, lo, hi)
        address = _uniform(address)
        result, g.p = change(g.read(address), g.p)
        g.write(address, result)
        if operate is not None:
            operate(g, result)
        g.cycles += cycles
        return _next(pc, length)
    return handler


def _make_branch(opcode: int, cycles: int) -> Handler:
    flag, wanted = BRANCH_CONDITIONS[opcode]
    extra_taken = BRANCH_TAKEN_CYCLES

    def handler(g, pc, lo, hi):
        flags = g.p & flag
        taken = flags.astype(bool) if wanted else flags == 0
        following = (pc + 2) & WORD
        target = (following + _signed(lo)) & WORD
        crossed = (following & PAGE_MASK) != (target & PAGE_MASK)
        g.cycles += cycles
        return _branch_split(g, taken, target, following, extra_taken + crossed * BRANCH_PAGE_CYCLES, pc, cycles)
    return handler


def _branch_split(g, taken: np.ndarray, target, following, extra, pc=None, base: int = 0):
    """Where a group goes at a branch (taken: per lane): one next PC, a list of (next pc, lanes) when
    the lanes part, or per-lane PCs when the addresses are per lane; the taken lanes pay `extra`.
    With coverage on, the branch at `pc` (of `base` cycles) is counted."""
    if isinstance(target, int) and isinstance(following, int):
        jump = np.flatnonzero(taken)
        coverage = g.cpu.coverage
        if coverage is not None and isinstance(pc, int):
            coverage.branch(pc, base, len(taken), len(jump), int(extra))
            if coverage.first_lane is not None:
                coverage.note_lanes(pc, g.ids, taken)
        if len(jump) == len(taken):
            g.cycles += extra
            return target
        if not len(jump):
            return following
        stay = np.ones(len(taken), dtype=bool)
        stay[jump] = False
        jumped = g.take(jump)
        jumped.cycles += extra
        return [(target, jumped), (following, g.take(np.flatnonzero(stay)))]
    g.cycles += taken * extra
    return np.where(taken, target, following)


FLAG_BITS = {"C": FLAG_C, "I": FLAG_I, "V": FLAG_V, "D": FLAG_D}


def _implied(mnemonic: str, cycles: int) -> Handler:
    if mnemonic in ("CLC", "SEC", "CLI", "SEI", "CLV", "CLD", "SED"):
        bit = FLAG_BITS[mnemonic[2]]
        setting = mnemonic[0] == "S"

        def operate(g):
            g.p = (g.p | bit) if setting else (g.p & ~bit)
    elif mnemonic in ("TAX", "TAY", "TXA", "TYA", "TSX"):
        source = {"A": "a", "X": "x", "Y": "y", "S": "sp"}[mnemonic[1]]
        target = {"A": "a", "X": "x", "Y": "y"}[mnemonic[2]]

        def operate(g):
            value = getattr(g, source)
            setattr(g, target, value)
            g.p = _nz(g.p, value)
    elif mnemonic == "TXS":
        def operate(g):
            g.sp = g.x
    else:  # INX INY DEX DEY
        register = "x" if mnemonic[2] == "X" else "y"
        step = 1 if mnemonic[0] == "I" else -1

        def operate(g):
            value = (getattr(g, register) + step) & BYTE
            setattr(g, register, value)
            g.p = _nz(g.p, value)

    def handler(g, pc, lo, hi):
        operate(g)
        g.cycles += cycles
        return _next(pc, 1)
    return handler


def _stack(mnemonic: str, cycles: int) -> Handler:
    def handler(g, pc, lo, hi):
        if mnemonic == "PHA":
            g.push(g.a)
        elif mnemonic == "PHP":
            g.push(g.p | FLAG_B | FLAG_U)
        elif mnemonic == "PLA":
            g.a = _full(g, g.pull())
            g.p = _nz(g.p, g.a)
        else:  # PLP: B and bit 5 exist only in pushed copies
            g.p = _full(g, (g.pull() | FLAG_U) & ~FLAG_B)
        g.cycles += cycles
        return _next(pc, 1)
    return handler


def _jump(mnemonic: str, mode: str, cycles: int) -> Handler:
    def handler(g, pc, lo, hi):
        g.cycles += cycles
        if mnemonic == "JMP":
            pointer = lo | hi << 8
            if mode == "abs":
                return pointer
            # NMOS: the high byte comes from the start of the pointer's page when the pointer ends one
            high_address = (pointer & PAGE_MASK) | ((pointer + 1) & BYTE)
            return _uniform(g.read(pointer) | g.read(_uniform(high_address)) << 8)
        if mnemonic == "JSR":
            back = (pc + 2) & WORD
            g.push(back >> 8)
            g.push(back & BYTE)
            return lo | hi << 8
        if mnemonic == "RTS":
            low = g.pull()
            return _uniform(((g.pull() << 8 | low) + 1) & WORD)
        if mnemonic == "RTI":
            g.p = _full(g, (g.pull() | FLAG_U) & ~FLAG_B)
            low = g.pull()
            return _uniform(g.pull() << 8 | low)
        raise AssertionError(mnemonic)  # pragma: no cover
    return handler


def _brk(cycles: int) -> Handler:
    def handler(g, pc, lo, hi):
        if g.cpu.stop_on_brk:
            g.stop(pc, LaneError.BRK)
            return []
        back = (pc + 2) & WORD
        g.push(back >> 8)
        g.push(back & BYTE)
        g.push(g.p | FLAG_B | FLAG_U)
        g.p = g.p | FLAG_I
        g.cycles += cycles
        return _uniform(g.read(IRQ_VECTOR) | g.read(IRQ_VECTOR + 1) << 8)
    return handler


READS = {"LDA", "LDX", "LDY", "LAX", "ORA", "AND", "EOR", "ADC", "SBC", "USBC", "CMP", "CPX", "CPY", "BIT",
         "ANC", "ALR", "ARR", "SBX", "NOP"}
STORES = {"STA", "STX", "STY", "SAX"}
RMW = set(SHIFTS) | set(COMBINED)
IMPLIED = {"CLC", "SEC", "CLI", "SEI", "CLV", "CLD", "SED", "TAX", "TAY", "TXA", "TYA", "TSX", "TXS",
           "INX", "INY", "DEX", "DEY"}
STACK = {"PHA", "PHP", "PLA", "PLP"}
JUMPS = {"JMP", "JSR", "RTS", "RTI"}


def _build() -> dict[int, Handler]:
    handlers: dict[int, Handler] = {}
    for opcode, op in OPCODE_TABLE.items():
        if op.kind not in (DOCUMENTED, STABLE):
            continue  # JAM and unstable opcodes stop their lanes (no handler)
        name, mode, length = op.mnemonic, op.mode, MODE_LENGTH[op.mode]
        if name in READS:
            handlers[opcode] = _make_read(name, mode, op.cycles, op.page_penalty, length)
        elif name in STORES:
            handlers[opcode] = _make_store(name, mode, op.cycles, length)
        elif name in RMW:
            handlers[opcode] = _make_rmw(name, mode, op.cycles, length)
        elif mode == "rel":
            handlers[opcode] = _make_branch(opcode, op.cycles)
        elif name in IMPLIED:
            handlers[opcode] = _implied(name, op.cycles)
        elif name in STACK:
            handlers[opcode] = _stack(name, op.cycles)
        elif name in JUMPS:
            handlers[opcode] = _jump(name, mode, op.cycles)
        elif name == "BRK":
            handlers[opcode] = _brk(op.cycles)
        else:  # pragma: no cover - a new table row needs its operation here
            raise AssertionError(f"no batch operation for {name} (${opcode:02X})")
    return handlers


HANDLERS: dict[int, Handler] = _build()
