"""The batched engine's handlers for the WDC 65C02 (`BatchCpu("65c02", ...)`), built from
`retro.cpu.opcodes.OPCODE_TABLE_65C02`.

Rows the 65C02 runs as the NMOS 6502 does (same mnemonic, mode, cycles and page penalty) take the
NMOS handler of `retro.cpu.batch_handlers`; the others are here: the new opcodes and the (zp) mode, ADC/SBC
with the 65C02's decimal mode (valid N and Z, one cycle more with D set), the fixed JMP (abs), shifts
abs,X with their page penalty, BRK clearing D, the reserved opcodes as NOPs, and STP/WAI stopping the
lane (LaneError.HALT). Semantics and cycles are those of the scalar core (`retro.cpu.mpu65c02.MPU65C02`,
where the sources are named).
"""

from __future__ import annotations

import numpy as np

from retro.cpu.batch_handlers import (
    ADDRESSING,
    BYTE,
    HANDLERS,
    NVZC,
    NZ,
    NZ_TABLE,
    SHIFTS,
    WORD,
    Handler,
    LaneError,
    _add_cycles,
    _binary_adc,
    _branch_split,
    _brk,
    _full,
    _make_read,
    _make_rmw,
    _make_store,
    _next,
    _nz,
    _signed,
    _uniform,
)
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_V, FLAG_Z
from retro.cpu.opcodes import DECIMAL_EXTRA_CYCLES, MODE_LENGTH, OPCODE_TABLE, OPCODE_TABLE_65C02, RESERVED
from retro.cpu.timing import BRANCH_PAGE_CYCLES, BRANCH_TAKEN_CYCLES, PAGE_MASK


def _zpi(g, lo, hi):
    """(zp): the 16-bit pointer in zero page, not indexed."""
    return _uniform(g.read(lo) | g.read((lo + 1) & BYTE) << 8), False


ADDRESSING_65C02 = {**ADDRESSING, "zpi": _zpi}


# ---- decimal mode (Bruce Clark, "Decimal Mode", appendix A, the 65C02) ----------------------------------

def _adc(g, a, value, p):
    result, flags = _binary_adc(a, value, p)
    decimal = (p & FLAG_D) != 0
    if not np.any(decimal):
        return result, flags
    carry = p & FLAG_C
    low = (a & 0x0F) + (value & 0x0F) + carry  # sequence 1: A and C
    low = np.where(low >= 0x0A, ((low + 0x06) & 0x0F) + 0x10, low)
    total = (a & 0xF0) + (value & 0xF0) + low
    signed = _signed(a & 0xF0) + _signed(value & 0xF0) + low  # sequence 2: V
    total = np.where(total >= 0xA0, total + 0x60, total)
    dec = total & BYTE
    dec_flags = ((p & ~NVZC) | NZ_TABLE[dec] | ((signed < -128) | (signed > 127)) * FLAG_V
                 | (total > BYTE) * FLAG_C)
    g.cycles += decimal * DECIMAL_EXTRA_CYCLES
    return np.where(decimal, dec, result), np.where(decimal, dec_flags, flags)


def _sbc(g, a, value, p):
    result, flags = _binary_adc(a, value ^ BYTE, p)  # C and V from the binary difference
    decimal = (p & FLAG_D) != 0
    if not np.any(decimal):
        return result, flags
    borrow = 1 - (p & FLAG_C)
    low = (a & 0x0F) - (value & 0x0F) - borrow  # sequence 4
    total = a - value - borrow
    total = np.where(total < 0, total - 0x60, total)
    total = np.where(low < 0, total - 0x06, total)
    dec = total & BYTE
    g.cycles += decimal * DECIMAL_EXTRA_CYCLES
    return np.where(decimal, dec, result), np.where(decimal, (flags & ~NZ) | NZ_TABLE[dec], flags)


def _add(g, value):
    g.a, g.p = _adc(g, g.a, value, g.p)


def _subtract(g, value):
    g.a, g.p = _sbc(g, g.a, value, g.p)


def _bit_immediate(g, value):  # BIT #imm sets only Z
    g.p = (g.p & ~FLAG_Z) | ((g.a & value) == 0) * FLAG_Z


# ---- handlers ---------------------------------------------------------------------------------------------

def _modify(mode: str, cycles: int, penalised: bool, change) -> Handler:
    """A read-modify-write: change(group, value) -> the value written (and sets flags)."""
    address_of = ADDRESSING_65C02[mode]
    length = MODE_LENGTH[mode]

    def handler(g, pc, lo, hi):
        address, crossed = address_of(g, lo, hi)
        address = _uniform(address)
        g.write(address, change(g, g.read(address)))
        _add_cycles(g, cycles, crossed, penalised)
        return _next(pc, length)
    return handler


def _shift(shift):
    def change(g, value):
        result, g.p = shift(value, g.p)
        return result
    return change


def _test_and(setting: bool):
    def change(g, value):  # TSB / TRB: Z from A AND M
        g.p = (g.p & ~FLAG_Z) | ((g.a & value) == 0) * FLAG_Z
        return (value | g.a) if setting else (value & ~g.a & BYTE)
    return change


def _memory_bit(mask: int, setting: bool):
    return lambda g, value: (value | mask) if setting else (value & ~mask & BYTE)


def _branch_always(cycles: int) -> Handler:
    def handler(g, pc, lo, hi):  # BRA
        following = (pc + 2) & WORD
        target = (following + _signed(lo)) & WORD
        crossed = (following & PAGE_MASK) != (target & PAGE_MASK)
        g.cycles += cycles + BRANCH_TAKEN_CYCLES + crossed * BRANCH_PAGE_CYCLES
        return target
    return handler


def _bit_branch(mask: int, when_set: bool, cycles: int) -> Handler:
    def handler(g, pc, lo, hi):  # BBRn / BBSn zp, offset
        value = g.read(lo)
        taken = ((value & mask) != 0) == when_set
        following = (pc + 3) & WORD
        target = (following + _signed(hi)) & WORD
        crossed = (following & PAGE_MASK) != (target & PAGE_MASK)
        g.cycles += cycles
        if not isinstance(taken, np.ndarray):  # the byte is the same in every lane
            taken = np.full(len(g), bool(taken))
        return _branch_split(g, taken, target, following, BRANCH_TAKEN_CYCLES + crossed * BRANCH_PAGE_CYCLES, pc,
                             cycles)
    return handler


def _push(register: str, cycles: int) -> Handler:
    def handler(g, pc, lo, hi):
        g.push(getattr(g, register))
        g.cycles += cycles
        return _next(pc, 1)
    return handler


def _pull(register: str, cycles: int) -> Handler:
    def handler(g, pc, lo, hi):
        value = _full(g, g.pull())
        setattr(g, register, value)
        g.p = _nz(g.p, value)
        g.cycles += cycles
        return _next(pc, 1)
    return handler


def _jump_indirect(indexed: bool, cycles: int) -> Handler:
    def handler(g, pc, lo, hi):  # JMP (abs), the page bug fixed; JMP (abs,X)
        pointer = lo | hi << 8
        if indexed:
            pointer = _uniform((pointer + g.x) & WORD)
        g.cycles += cycles
        return _uniform(g.read(pointer) | g.read(_uniform((pointer + 1) & WORD)) << 8)
    return handler


def _brk_clearing_d(cycles: int) -> Handler:
    nmos = _brk(cycles)

    def handler(g, pc, lo, hi):
        target = nmos(g, pc, lo, hi)
        if not isinstance(target, list):  # it ran (not stopped): the 65C02 clears D
            g.p = g.p & ~FLAG_D
        return target
    return handler


def _halt(g, pc, lo, hi):
    g.stop(pc, LaneError.HALT)
    return []


def _nop(cycles: int, length: int) -> Handler:
    def handler(g, pc, lo, hi):
        g.cycles += cycles
        return _next(pc, length)
    return handler


SHIFTS_ABX = {"ASL", "LSR", "ROL", "ROR"}


def _handler(opcode: int, row) -> Handler:
    name, mode, cycles = row.mnemonic, row.mode, row.cycles
    length = MODE_LENGTH[mode]
    nmos = OPCODE_TABLE[opcode]
    if row.kind == RESERVED:
        return _nop(cycles, length)
    if name in ("ADC", "SBC"):
        return _make_read(name, mode, cycles, row.page_penalty, length, operate=_add if name == "ADC" else _subtract,
                          address_of=ADDRESSING_65C02.get(mode))
    if nmos == row and name not in ("BRK", "JMP"):
        return HANDLERS[opcode]  # the NMOS 6502 runs it the same way
    if name in ("STA", "STZ"):  # STA (zp), STZ
        return _make_store(name, mode, cycles, length, address_of=ADDRESSING_65C02[mode])
    if mode == "zpi" or name == "BIT":
        return _make_read(name, mode, cycles, row.page_penalty, length, address_of=ADDRESSING_65C02.get(mode),
                          operate=_bit_immediate if mode == "imm" else None)
    if name in SHIFTS_ABX and mode == "abx":
        return _modify(mode, cycles, row.page_penalty, _shift(SHIFTS[name]))
    if name == "JMP" and mode == "abs":
        return HANDLERS[opcode]
    make = _NEW_OPERATIONS.get(name[:3] if name[:3] in ("RMB", "SMB", "BBR", "BBS") else name)
    if make is None:  # pragma: no cover - a new table row needs its operation here
        raise AssertionError(f"no 65C02 batch operation for {name} (${opcode:02X})")
    return make(name, mode, cycles, length)


# The 65C02's own operations by mnemonic (RMB/SMB/BBR/BBS by their first three letters, the bit
# number being the fourth): each makes the handler for one (mnemonic, mode, cycles, length).
_NEW_OPERATIONS = {
    "INC": lambda name, mode, cycles, length: _make_rmw(name, mode, cycles, length),  # INC A
    "DEC": lambda name, mode, cycles, length: _make_rmw(name, mode, cycles, length),  # DEC A
    "TSB": lambda name, mode, cycles, length: _modify(mode, cycles, False, _test_and(True)),
    "TRB": lambda name, mode, cycles, length: _modify(mode, cycles, False, _test_and(False)),
    "RMB": lambda name, mode, cycles, length: _modify(mode, cycles, False, _memory_bit(1 << int(name[3]), False)),
    "SMB": lambda name, mode, cycles, length: _modify(mode, cycles, False, _memory_bit(1 << int(name[3]), True)),
    "BBR": lambda name, mode, cycles, length: _bit_branch(1 << int(name[3]), False, cycles),
    "BBS": lambda name, mode, cycles, length: _bit_branch(1 << int(name[3]), True, cycles),
    "BRA": lambda name, mode, cycles, length: _branch_always(cycles),
    "PHX": lambda name, mode, cycles, length: _push("x", cycles),
    "PHY": lambda name, mode, cycles, length: _push("y", cycles),
    "PLX": lambda name, mode, cycles, length: _pull("x", cycles),
    "PLY": lambda name, mode, cycles, length: _pull("y", cycles),
    "JMP": lambda name, mode, cycles, length: _jump_indirect(mode == "iax", cycles),  # JMP (abs), (abs,X)
    "BRK": lambda name, mode, cycles, length: _brk_clearing_d(cycles),
    "STP": lambda name, mode, cycles, length: _halt,
    "WAI": lambda name, mode, cycles, length: _halt,
}


HANDLERS_65C02: dict[int, Handler] = {opcode: _handler(opcode, row) for opcode, row in OPCODE_TABLE_65C02.items()}
