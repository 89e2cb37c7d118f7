"""The batched 6502: one routine run on many input lanes at once with numpy, exact to the cycle.

Every lane has its own A, X, Y, S, P and cycle count. Lanes that stand at the same program counter
run the instruction together (numpy operations over their index array); a branch splits them, and
lanes meet again when they reach the same address (the lowest waiting address runs first, so lanes
that took a forward branch wait for the others at the join). An RTS whose return addresses differ
splits the group by address.

Memory is one shared 64 KiB image plus, for every page some lane writes (zero page, stack, tables,
self-modifying code) or that holds per-lane inputs, a private copy per lane (`LaneMemory`). Opcodes
and operands are fetched from the private copy when their page has one, so code that rewrites
itself runs per lane.

Semantics and cycle counts are those of `retro.cpu.mpu` (the scalar core, the reference): base
cycles and page-crossing penalties from `retro.cpu.timing.OPCODES`, branch penalties, NMOS decimal
mode on the 6510 (Bruce Clark, "Decimal Mode" tutorial, appendix A: the 6502's A, C, N, V and Z in
decimal mode), binary-only ADC/SBC on the 2A03, and the stable undocumented opcodes ("NMOS 6510
Unintended Opcodes - No More Secrets", groepaz, 2024). A lane stops with an error code (`LaneError`)
on BRK (when calls stop on it), JAM, an unstable opcode, or a spent cycle budget; the others go on.
No device is modelled: the engine serves plain-RAM routines (a scene with chips runs on `Machine`).
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum

import numpy as np

from retro.cpu.mpu import (
    FLAG_B,
    FLAG_C,
    FLAG_D,
    FLAG_I,
    FLAG_N,
    FLAG_U,
    FLAG_V,
    FLAG_Z,
    IRQ_VECTOR,
    JAM_OPCODES,
    UNSTABLE_OPCODES,
    VARIANTS,
)
from retro.cpu.timing import (
    BRANCH_CONDITIONS,
    BRANCH_PAGE_CYCLES,
    BRANCH_TAKEN_CYCLES,
    OPCODES,
    PAGE_CROSS_CYCLES,
    PAGE_MASK,
)
from retro.errors import InputError

MEMORY_SIZE = 0x10000
PAGE_SIZE = 0x100
PAGES = MEMORY_SIZE // PAGE_SIZE
STACK_PAGE = 0x100
BYTE = 0xFF
WORD = 0xFFFF
MAX_PRIVATE_BYTES = 512 << 20  # per-lane bytes a batch may hold before it must be split
DENSE_AFTER = 24  # a page with more per-lane bytes than this is held as one block
NZ = FLAG_N | FLAG_Z
NVZC = FLAG_N | FLAG_V | FLAG_Z | FLAG_C


class LaneError(IntEnum):
    """Why a lane stopped before returning (0 = running or returned)."""

    NONE = 0
    BRK = 1
    JAM = 2
    UNSTABLE = 3
    BUDGET = 4


class LaneMemoryFull(Exception):
    """The per-lane page copies of this batch would pass MAX_PRIVATE_BYTES: run fewer lanes at a time."""


class LaneMemory:
    """A shared 64 KiB image and, per address that differs between lanes, a row of one value per lane.

    Rows are int32 (registers' type, so arithmetic never wraps early) and made on first write. A page
    that gets more than DENSE_AFTER rows (a table the routine writes) becomes one (256 x lanes) block,
    its rows views into it, so accesses with per-lane addresses stay one gather."""

    def __init__(self, image, lanes: int, limit: int = MAX_PRIVATE_BYTES) -> None:
        self.shared = np.frombuffer(bytes(image), dtype=np.uint8).copy()
        if len(self.shared) != MEMORY_SIZE:
            raise InputError(f"a memory image is {MEMORY_SIZE} bytes, got {len(self.shared)}")
        self.lanes = lanes
        self.limit = limit
        self.rows: dict[int, np.ndarray] = {}
        self.page_rows: dict[int, list[int]] = {}  # sparse pages: their addresses with rows
        self.dense: dict[int, np.ndarray] = {}
        self.is_private = np.zeros(PAGES, dtype=bool)  # the page has rows (sparse or dense)
        self.all_lanes = np.arange(lanes)

    def _held(self) -> int:
        return (len(self.rows) + (PAGE_SIZE - 1) * len(self.dense)) * self.lanes * 4

    def row(self, address: int) -> np.ndarray:
        """The per-lane row of an address (made from the shared image on first use)."""
        row = self.rows.get(address)
        if row is None:
            if self._held() + self.lanes * 4 > self.limit:
                raise LaneMemoryFull(f"{self.lanes} lanes with {len(self.rows) + 1} private bytes")
            row = np.full(self.lanes, self.shared[address], dtype=np.int32)
            self.rows[address] = row
            page = address >> 8
            self.is_private[page] = True
            listed = self.page_rows.setdefault(page, [])
            listed.append(address)
            if len(listed) > DENSE_AFTER:
                self._densify(page)
                row = self.rows[address]
        return row

    def _densify(self, page: int) -> None:
        if self._held() + PAGE_SIZE * self.lanes * 4 > self.limit:
            raise LaneMemoryFull(f"{self.lanes} lanes with a page of per-lane bytes more")
        base = page * PAGE_SIZE
        block = np.repeat(self.shared[base:base + PAGE_SIZE].astype(np.int32)[:, None], self.lanes, axis=1)
        for address in self.page_rows.pop(page, []):
            block[address & BYTE] = self.rows[address]
        for offset in range(PAGE_SIZE):
            self.rows[base + offset] = block[offset]
        self.dense[page] = block
        self.is_private[page] = True

    def lanes_of(self, idx) -> np.ndarray:
        return self.all_lanes[idx] if isinstance(idx, slice) else idx

    def read(self, idx, address):
        """The byte at address (an int, or an array aligned with idx) for the lanes idx (an index
        array or slice(None) for every lane)."""
        if isinstance(address, (int, np.integer)):
            row = self.rows.get(int(address))
            return int(self.shared[address]) if row is None else row[idx]
        values = self.shared[address].astype(np.int32)
        if self.rows:
            pages = address >> 8
            lanes = None
            for page in np.flatnonzero(self.is_private).tolist():
                hit = pages == page
                if not hit.any():
                    continue
                lanes = self.lanes_of(idx) if lanes is None else lanes
                block = self.dense.get(page)
                if block is not None:
                    values[hit] = block[address[hit] & BYTE, lanes[hit]]
                    continue
                for row_address in self.page_rows[page]:
                    at = hit & (address == row_address)
                    if at.any():
                        values[at] = self.rows[row_address][lanes[at]]
        return values

    def write(self, idx, address, value) -> None:
        """Store value (an int or an array aligned with idx) at address for the lanes idx."""
        if isinstance(address, (int, np.integer)):
            self.row(int(address))[idx] = value
            return
        lanes = self.lanes_of(idx)
        array = not isinstance(value, (int, np.integer))
        targets = np.unique(address)
        if len(targets) == 1:
            self.row(int(targets[0]))[lanes] = value
            return
        for page in np.unique(targets >> 8).tolist():
            in_page = targets[(targets >> 8) == page]
            if page not in self.dense and len(in_page) + len(self.page_rows.get(page, ())) > DENSE_AFTER:
                self._densify(page)
            block = self.dense.get(page)
            if block is not None:
                hit = (address >> 8) == page
                block[address[hit] & BYTE, lanes[hit]] = value[hit] if array else value
                continue
            for target in in_page.tolist():
                at = address == target
                self.row(target)[lanes[at]] = value[at] if array else value

    def fill(self, address: int, values) -> None:
        """Per-lane values (an array of one byte per lane) at one address, for every lane."""
        self.row(address)[:] = values


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
    return (p & ~NZ) | (value & FLAG_N) | ((value == 0) * FLAG_Z)


class BatchCpu:
    """N lanes of one 6502 on one memory image (see the module docstring)."""

    def __init__(self, variant: str, image, lanes: int, *, stop_on_brk: bool = True,
                 memory_limit: int = MAX_PRIVATE_BYTES) -> None:
        if variant not in VARIANTS:
            raise InputError(f"unknown CPU variant {variant!r} (known: {', '.join(VARIANTS)})")
        self.variant = variant
        self.decimal = VARIANTS[variant].has_decimal
        self.lanes = lanes
        self.stop_on_brk = stop_on_brk
        self.memory = LaneMemory(image, lanes, memory_limit)
        zeros = np.zeros(lanes, dtype=np.int32)
        self.a, self.x, self.y = zeros.copy(), zeros.copy(), zeros.copy()
        self.sp = np.full(lanes, BYTE, dtype=np.int32)
        self.p = np.full(lanes, FLAG_U | FLAG_I, dtype=np.int32)
        self.pc = zeros.copy()
        self.cycles = np.zeros(lanes, dtype=np.int64)
        self.error = np.zeros(lanes, dtype=np.int8)
        self.error_pc = zeros.copy()
        self.instructions = 0  # group executions (one instruction run by a group of lanes)

    # ---- running -------------------------------------------------------------------------------

    def call(self, entry: int, budget: int, return_pc: int, return_sp: int) -> None:
        """Run every lane from entry until it stands at return_pc with S = return_sp (the caller has
        pushed the return address and set S), or stops with an error. Cycles count from entry."""
        every = slice(None)
        pending: dict[int, list] = {entry: [every]}
        lanes_of = self.memory.lanes_of
        while pending:
            pc = min(pending)
            parts = pending.pop(pc)
            idx = parts[0] if len(parts) == 1 else np.concatenate([lanes_of(part) for part in parts])
            if not isinstance(idx, slice) and len(idx) == self.lanes:
                idx = every  # every lane: slices index without copying
            if pc == return_pc:
                home = self.sp[idx] == return_sp
                if home.any():
                    lanes = lanes_of(idx)
                    done = lanes[home]
                    self.pc[done] = pc
                    self._stop(done[self.cycles[done] > budget], pc, LaneError.BUDGET)
                    idx = lanes[~home]
                    if not len(idx):
                        continue
            spent = self.cycles[idx] >= budget
            if spent.any():
                lanes = lanes_of(idx)
                self._stop(lanes[spent], pc, LaneError.BUDGET)
                idx = lanes[~spent]
                if not len(idx):
                    continue
            for target, lanes in self._run_at(idx, pc):
                if isinstance(target, int):
                    pending.setdefault(target, []).append(lanes)
                else:
                    lanes = lanes_of(lanes)
                    order = np.argsort(target, kind="stable")
                    ordered = target[order]
                    starts = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]])
                    for start, end in zip(starts, np.r_[starts[1:], len(ordered)]):
                        pending.setdefault(int(ordered[start]), []).append(lanes[order[start:end]])

    def step(self) -> None:
        """Run one instruction on every lane from its own PC (for single-step test vectors)."""
        pc = _uniform(self.pc)
        for target, lanes in self._run_at(slice(None), pc):
            self.pc[lanes] = target

    def _stop(self, idx, pc, kind: LaneError) -> None:
        if isinstance(idx, slice) or len(idx):
            self.error[idx] = kind
            self.error_pc[idx] = pc

    def _run_at(self, idx: np.ndarray, pc):
        """Run the instruction at pc (an int, or per-lane) for the lanes idx; yield (next pc, lanes)."""
        memory = self.memory
        if isinstance(pc, int) and not memory.is_private[pc >> 8] and not memory.is_private[((pc + 2) & WORD) >> 8]:
            shared = memory.shared
            yield from self._dispatch(int(shared[pc]), idx, pc, int(shared[(pc + 1) & WORD]),
                                      int(shared[(pc + 2) & WORD]))
            return
        opcodes = _uniform(memory.read(idx, pc))
        lo = _uniform(memory.read(idx, (pc + 1) & WORD))
        hi = _uniform(memory.read(idx, (pc + 2) & WORD))
        if isinstance(opcodes, int):
            yield from self._dispatch(opcodes, idx, pc, lo, hi)
            return
        lanes = memory.lanes_of(idx)
        for opcode in np.unique(opcodes).tolist():
            hit = opcodes == opcode
            yield from self._dispatch(opcode, lanes[hit], _uniform(pc if isinstance(pc, int) else pc[hit]),
                                      _uniform(lo if isinstance(lo, int) else lo[hit]),
                                      _uniform(hi if isinstance(hi, int) else hi[hit]))

    def _dispatch(self, opcode: int, idx: np.ndarray, pc, lo, hi):
        self.instructions += 1
        handler = HANDLERS.get(opcode)
        if handler is None:
            self._stop(idx, pc, LaneError.JAM if opcode in JAM_OPCODES else LaneError.UNSTABLE)
            return
        result = handler(self, idx, pc, lo, hi)
        if isinstance(result, list):
            yield from result
        else:
            yield result, idx

    # ---- lane state helpers --------------------------------------------------------------------

    def read(self, address: int) -> np.ndarray:
        """Every lane's byte at address."""
        value = self.memory.read(slice(None), address)
        return np.full(self.lanes, value, dtype=np.int32) if isinstance(value, int) else value.copy()

    def push(self, idx, value) -> None:
        sp = self.sp[idx]
        self.memory.write(idx, STACK_PAGE | _uniform(sp), value)
        self.sp[idx] = (sp - 1) & BYTE

    def pull(self, idx):
        sp = (self.sp[idx] + 1) & BYTE
        self.sp[idx] = sp
        return self.memory.read(idx, STACK_PAGE | _uniform(sp))


# ---- operand addresses ---------------------------------------------------------------------------------
# Each returns (address, crossed): crossed is whether indexing moved the address into another page.

def _zpg(cpu, idx, lo, hi):
    return lo, False


def _zpx(cpu, idx, lo, hi):
    return (lo + cpu.x[idx]) & BYTE, False


def _zpy(cpu, idx, lo, hi):
    return (lo + cpu.y[idx]) & BYTE, False


def _abs(cpu, idx, lo, hi):
    return lo | hi << 8, False


def _indexed(base, index):
    address = (base + index) & WORD
    return address, (base & PAGE_MASK) != (address & PAGE_MASK)


def _abx(cpu, idx, lo, hi):
    return _indexed(lo | hi << 8, cpu.x[idx])


def _aby(cpu, idx, lo, hi):
    return _indexed(lo | hi << 8, cpu.y[idx])


def _inx(cpu, idx, lo, hi):
    pointer = _uniform((lo + cpu.x[idx]) & BYTE)
    read = cpu.memory.read
    return _uniform(read(idx, pointer) | read(idx, (pointer + 1) & BYTE) << 8), False


def _iny(cpu, idx, lo, hi):
    read = cpu.memory.read
    base = _uniform(read(idx, lo) | read(idx, (lo + 1) & BYTE) << 8)
    return _indexed(base, cpu.y[idx])


ADDRESSING = {"zpg": _zpg, "zpx": _zpx, "zpy": _zpy, "abs": _abs, "abx": _abx, "aby": _aby,
              "inx": _inx, "iny": _iny}


# ---- arithmetic ------------------------------------------------------------------------------------------

def _binary_adc(a, value, p):
    total = a + value + (p & FLAG_C)
    result = total & BYTE
    overflow = (~(a ^ value) & (a ^ result) & 0x80) != 0
    return result, ((p & ~NVZC) | (result & FLAG_N) | (overflow * FLAG_V) | ((result == 0) * FLAG_Z)
                    | (total > BYTE) * FLAG_C)


def _adc(cpu, idx, a, value, p):
    """(A, P) after ADC: binary, or NMOS decimal for lanes with D set on a CPU that has it."""
    carry = p & FLAG_C
    total = a + value + carry
    result, flags = _binary_adc(a, value, p)
    if not cpu.decimal:
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


def _sbc(cpu, idx, a, value, p):
    """(A, P) after SBC: flags from the binary difference in both modes (NMOS); A decimal-adjusted."""
    result, flags = _binary_adc(a, value ^ BYTE, p)
    if not cpu.decimal:
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
    difference = register - value
    return (_nz(p, difference & BYTE) & ~FLAG_C) | (difference >= 0) * FLAG_C


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
# A handler runs one opcode for the lanes idx (pc, lo, hi: ints or per-lane arrays), adds its cycles and
# returns the next PC (an int or per-lane array) or a list of (next pc, lanes).

Handler = Callable[..., object]


def _next(pc, length: int):
    return (pc + length) & WORD


def _add_cycles(cpu, idx, base: int, crossed, penalised: bool) -> None:
    if penalised and not (crossed is False):
        cpu.cycles[idx] += base + np.asarray(crossed, dtype=np.int64) * PAGE_CROSS_CYCLES
    else:
        cpu.cycles[idx] += base


def _make_read(opcode: int, mnemonic: str, mode: str, cycles: int, penalised: bool, length: int) -> Handler:
    """Instructions that read an operand (immediate or memory) and change registers and flags."""
    address_of = ADDRESSING.get(mode)

    def operate(cpu, idx, value):
        a = cpu.a
        p = cpu.p[idx]
        if mnemonic in ("LDA", "LDX", "LDY", "LAX"):
            if mnemonic in ("LDA", "LAX"):
                a[idx] = value
            if mnemonic in ("LDX", "LAX"):
                cpu.x[idx] = value
            if mnemonic == "LDY":
                cpu.y[idx] = value
            cpu.p[idx] = _nz(p, value)
        elif mnemonic in ("ORA", "AND", "EOR"):
            result = {"ORA": a[idx] | value, "AND": a[idx] & value, "EOR": a[idx] ^ value}[mnemonic]
            a[idx] = result
            cpu.p[idx] = _nz(p, result)
        elif mnemonic == "ADC":
            a[idx], cpu.p[idx] = _adc(cpu, idx, a[idx], value, p)
        elif mnemonic in ("SBC", "USBC"):
            a[idx], cpu.p[idx] = _sbc(cpu, idx, a[idx], value, p)
        elif mnemonic in ("CMP", "CPX", "CPY"):
            register = {"CMP": a, "CPX": cpu.x, "CPY": cpu.y}[mnemonic][idx]
            cpu.p[idx] = _compare(register, value, p)
        elif mnemonic == "BIT":
            cpu.p[idx] = ((p & ~(FLAG_N | FLAG_V | FLAG_Z)) | (value & (FLAG_N | FLAG_V))
                          | (((a[idx] & value) == 0) * FLAG_Z))
        elif mnemonic == "ANC":
            result = a[idx] & value
            a[idx] = result
            cpu.p[idx] = (_nz(p, result) & ~FLAG_C) | (result >> 7)
        elif mnemonic == "ALR":
            a[idx], cpu.p[idx] = _lsr(a[idx] & value, p)
        elif mnemonic == "ARR":
            a[idx], cpu.p[idx] = _arr(cpu, a[idx] & value, p)
        elif mnemonic == "SBX":
            both = a[idx] & cpu.x[idx]
            cpu.x[idx] = (both - value) & BYTE
            cpu.p[idx] = _compare(both, value, p)
        elif mnemonic == "NOP":
            pass
        else:  # pragma: no cover - the table below lists only the mnemonics handled here
            raise AssertionError(mnemonic)

    if mode == "imm":
        def handler(cpu, idx, pc, lo, hi):
            operate(cpu, idx, lo)
            cpu.cycles[idx] += cycles
            return _next(pc, length)
    elif mode == "imp":  # the undocumented one-byte NOPs
        def handler(cpu, idx, pc, lo, hi):
            cpu.cycles[idx] += cycles
            return _next(pc, length)
    else:
        def handler(cpu, idx, pc, lo, hi):
            address, crossed = address_of(cpu, idx, lo, hi)
            address = _uniform(address)
            operate(cpu, idx, cpu.memory.read(idx, address))
            _add_cycles(cpu, idx, cycles, crossed, penalised)
            return _next(pc, length)
    return handler


def _arr(cpu, value, p):
    """ARR: AND then ROR A with its own flags (No More Secrets, "ARR"; decimal mode as 64doc)."""
    carry = p & FLAG_C
    result = (value >> 1) | (carry << 7)
    flags = ((p & ~NVZC) | (result & FLAG_N) | ((result == 0) * FLAG_Z) | ((result >> 6) & 1) * FLAG_C
             | (((result >> 6) ^ (result >> 5)) & 1) * FLAG_V)
    if not cpu.decimal:
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


def _make_store(mnemonic: str, mode: str, cycles: int, length: int) -> Handler:
    address_of = ADDRESSING[mode]

    def handler(cpu, idx, pc, lo, hi):
        address, _ = address_of(cpu, idx, lo, hi)
        if mnemonic == "STA":
            value = cpu.a[idx]
        elif mnemonic == "STX":
            value = cpu.x[idx]
        elif mnemonic == "STY":
            value = cpu.y[idx]
        else:  # SAX
            value = cpu.a[idx] & cpu.x[idx]
        cpu.memory.write(idx, _uniform(address), value)
        cpu.cycles[idx] += cycles
        return _next(pc, length)
    return handler


# Read-modify-write opcodes: the shift or step, then (undocumented ones) an ALU operation with A.
COMBINED = {"SLO": ("ASL", "ORA"), "RLA": ("ROL", "AND"), "SRE": ("LSR", "EOR"), "RRA": ("ROR", "ADC"),
            "DCP": ("DEC", "CMP"), "ISC": ("INC", "SBC")}


def _make_rmw(mnemonic: str, mode: str, cycles: int, length: int) -> Handler:
    shift, then = COMBINED.get(mnemonic, (mnemonic, None))
    change = SHIFTS[shift]
    if mode == "acc":
        def handler(cpu, idx, pc, lo, hi):
            cpu.a[idx], cpu.p[idx] = change(cpu.a[idx], cpu.p[idx])
            cpu.cycles[idx] += cycles
            return _next(pc, length)
        return handler
    address_of = ADDRESSING[mode]

    def handler(cpu, idx, pc, lo, hi):
        address, _ = address_of(cpu, idx, lo, hi)
        address = _uniform(address)
        memory = cpu.memory
        value = memory.read(idx, address)
        p = cpu.p[idx]
        result, p = change(value, p)
        memory.write(idx, address, result)
        if then is not None:
            a = cpu.a[idx]
            if then == "ORA":
                a = a | result
                p = _nz(p, a)
            elif then == "AND":
                a = a & result
                p = _nz(p, a)
            elif then == "EOR":
                a = a ^ result
                p = _nz(p, a)
            elif then == "ADC":
                a, p = _adc(cpu, idx, a, result, p)
            elif then == "SBC":
                a, p = _sbc(cpu, idx, a, result, p)
            else:  # CMP
                p = _compare(a, result, p)
            cpu.a[idx] = a
        cpu.p[idx] = p
        cpu.cycles[idx] += cycles
        return _next(pc, length)
    return handler


def _make_branch(opcode: int, cycles: int) -> Handler:
    flag, wanted = BRANCH_CONDITIONS[opcode]
    extra_taken = BRANCH_TAKEN_CYCLES

    def handler(cpu, idx, pc, lo, hi):
        taken = ((cpu.p[idx] & flag) != 0) == bool(wanted)
        following = (pc + 2) & WORD
        target = (following + _signed(lo)) & WORD
        crossed = (following & PAGE_MASK) != (target & PAGE_MASK)
        cpu.cycles[idx] += cycles + taken * (extra_taken + crossed * BRANCH_PAGE_CYCLES)
        if isinstance(target, int) and isinstance(following, int):
            if taken.all():
                return target
            if not taken.any():
                return following
            lanes = cpu.memory.lanes_of(idx)
            return [(target, lanes[taken]), (following, lanes[~taken])]
        return np.where(taken, target, following)
    return handler


def _implied(mnemonic: str, cycles: int) -> Handler:
    def handler(cpu, idx, pc, lo, hi):
        p = cpu.p
        if mnemonic in ("CLC", "SEC", "CLI", "SEI", "CLV", "CLD", "SED"):
            bit = {"C": FLAG_C, "I": FLAG_I, "V": FLAG_V, "D": FLAG_D}[mnemonic[2]]
            p[idx] = (p[idx] | bit) if mnemonic[0] == "S" else (p[idx] & ~bit)
        elif mnemonic in ("TAX", "TAY", "TXA", "TYA", "TSX"):
            source = {"A": cpu.a, "X": cpu.x, "Y": cpu.y, "S": cpu.sp}[mnemonic[1]][idx]
            target = {"A": cpu.a, "X": cpu.x, "Y": cpu.y}[mnemonic[2]]
            target[idx] = source
            p[idx] = _nz(p[idx], source)
        elif mnemonic == "TXS":
            cpu.sp[idx] = cpu.x[idx]
        elif mnemonic in ("INX", "INY", "DEX", "DEY"):
            register = cpu.x if mnemonic[2] == "X" else cpu.y
            value = (register[idx] + (1 if mnemonic[0] == "I" else -1)) & BYTE
            register[idx] = value
            p[idx] = _nz(p[idx], value)
        cpu.cycles[idx] += cycles
        return _next(pc, 1)
    return handler


def _stack(mnemonic: str, cycles: int) -> Handler:
    def handler(cpu, idx, pc, lo, hi):
        if mnemonic == "PHA":
            cpu.push(idx, cpu.a[idx])
        elif mnemonic == "PHP":
            cpu.push(idx, cpu.p[idx] | FLAG_B | FLAG_U)
        elif mnemonic == "PLA":
            value = cpu.pull(idx)
            cpu.a[idx] = value
            cpu.p[idx] = _nz(cpu.p[idx], value)
        else:  # PLP: B and bit 5 exist only in pushed copies
            cpu.p[idx] = (cpu.pull(idx) | FLAG_U) & ~FLAG_B
        cpu.cycles[idx] += cycles
        return _next(pc, 1)
    return handler


def _jump(mnemonic: str, mode: str, cycles: int) -> Handler:
    def handler(cpu, idx, pc, lo, hi):
        cpu.cycles[idx] += cycles
        if mnemonic == "JMP":
            pointer = lo | hi << 8
            if mode == "abs":
                return pointer
            # NMOS: the high byte comes from the start of the pointer's page when the pointer ends one
            high_address = (pointer & PAGE_MASK) | ((pointer + 1) & BYTE)
            read = cpu.memory.read
            return _uniform(read(idx, pointer) | read(idx, _uniform(high_address)) << 8)
        if mnemonic == "JSR":
            back = (pc + 2) & WORD
            cpu.push(idx, back >> 8)
            cpu.push(idx, back & BYTE)
            return lo | hi << 8
        if mnemonic == "RTS":
            low = cpu.pull(idx)
            return _uniform(((cpu.pull(idx) << 8 | low) + 1) & WORD)
        if mnemonic == "RTI":
            cpu.p[idx] = (cpu.pull(idx) | FLAG_U) & ~FLAG_B
            low = cpu.pull(idx)
            return _uniform(cpu.pull(idx) << 8 | low)
        raise AssertionError(mnemonic)  # pragma: no cover
    return handler


def _brk(cycles: int) -> Handler:
    def handler(cpu, idx, pc, lo, hi):
        if cpu.stop_on_brk:
            cpu._stop(idx, pc, LaneError.BRK)
            return []
        back = (pc + 2) & WORD
        cpu.push(idx, back >> 8)
        cpu.push(idx, back & BYTE)
        cpu.push(idx, cpu.p[idx] | FLAG_B | FLAG_U)
        cpu.p[idx] = cpu.p[idx] | FLAG_I
        cpu.cycles[idx] += cycles
        read = cpu.memory.read
        return _uniform(read(idx, IRQ_VECTOR) | read(idx, IRQ_VECTOR + 1) << 8)
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
    for opcode, op in OPCODES.items():
        name, mode = op.mnemonic, op.mode
        if name in READS:
            handlers[opcode] = _make_read(opcode, name, mode, op.cycles, op.page_penalty, op.length)
        elif name in STORES:
            handlers[opcode] = _make_store(name, mode, op.cycles, op.length)
        elif name in RMW:
            handlers[opcode] = _make_rmw(name, mode, op.cycles, op.length)
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
    for opcode in JAM_OPCODES | set(UNSTABLE_OPCODES):
        handlers.pop(opcode, None)
    return handlers


HANDLERS: dict[int, Handler] = _build()
