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
cycles and page-crossing penalties from the opcode table (`retro.cpu.opcodes`), branch penalties, NMOS decimal
mode on the 6510 (Bruce Clark, "Decimal Mode" tutorial, appendix A: the 6502's A, C, N, V and Z in
decimal mode), binary-only ADC/SBC on the 2A03, and the stable undocumented opcodes ("NMOS 6510
Unintended Opcodes - No More Secrets", groepaz, 2024). A lane stops with an error code (`LaneError`)
on BRK (when calls stop on it), JAM, an unstable opcode, or a spent cycle budget; the others go on.
No device is modelled: the engine serves plain-RAM routines (a scene with chips runs on `Machine`).
"""

from __future__ import annotations

import functools
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
)
from retro.cpu.opcodes import DECIMAL_EXTRA_CYCLES, DOCUMENTED, MODE_LENGTH, OPCODE_TABLE, STABLE
from retro.cpu.variants import VARIANTS
from retro.cpu.timing import (
    BRANCH_CONDITIONS,
    is_conditional_branch,
    BRANCH_PAGE_CYCLES,
    BRANCH_TAKEN_CYCLES,
    PAGE_CROSS_CYCLES,
    PAGE_MASK,
)
from retro.cpu.lane_memory import BYTE, MAX_PRIVATE_BYTES, LaneMemory
from retro.errors import InputError

STACK_PAGE = 0x100
WORD = 0xFFFF
# A lane whose cycles reach the budget stops there on Machine. Here the budget is looked at when the
# lowest waiting address is below the last one run (some lanes jumped back: every loop does), every
# BUDGET_CHECK_EVERY group runs, and when a lane returns (then cycles > budget is the same verdict): a
# lane past its budget may run a few more instructions, but it is reported as over the budget unless
# it stops first for another reason (BRK, JAM), which is a run error all the same.
BUDGET_CHECK_EVERY = 64
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


class Lanes:
    """A group of lanes that stand at one address: their registers as contiguous arrays (no gather or
    scatter per instruction) and their lane numbers (`ids`, slice(None) for every lane in order),
    which index the per-lane memory rows."""

    __slots__ = ("cpu", "ids", "a", "x", "y", "p", "sp", "cycles")

    def __init__(self, cpu: "BatchCpu", ids, a, x, y, p, sp, cycles) -> None:
        self.cpu, self.ids = cpu, ids
        self.a, self.x, self.y, self.p, self.sp, self.cycles = a, x, y, p, sp, cycles

    def __len__(self) -> int:
        return len(self.a)

    def take(self, index: np.ndarray) -> "Lanes":
        """The lanes at these positions of the group, as a group of their own."""
        ids = index if isinstance(self.ids, slice) else self.ids[index]
        return Lanes(self.cpu, ids, self.a[index], self.x[index], self.y[index], self.p[index], self.sp[index],
                     self.cycles[index])

    @staticmethod
    def join(groups: list["Lanes"]) -> "Lanes":
        if len(groups) == 1:
            return groups[0]
        cpu = groups[0].cpu
        ids = np.concatenate([cpu.memory.lanes_of(g.ids) for g in groups])
        return Lanes(cpu, ids, *(np.concatenate([getattr(g, name) for g in groups])
                                 for name in ("a", "x", "y", "p", "sp", "cycles")))

    def store(self) -> None:
        """Write the group's registers back to the machine's per-lane arrays."""
        cpu, ids = self.cpu, self.ids
        cpu.a[ids], cpu.x[ids], cpu.y[ids], cpu.p[ids], cpu.sp[ids], cpu.cycles[ids] = (
            self.a, self.x, self.y, self.p, self.sp, self.cycles)

    def stop(self, pc, kind: "LaneError") -> None:
        self.store()
        self.cpu.error[self.ids] = kind
        self.cpu.error_pc[self.ids] = pc

    # memory, for these lanes
    def read(self, address):
        return self.cpu.memory.read(self.ids, address)

    def write(self, address, value) -> None:
        self.cpu.memory.write(self.ids, address, value)

    def push(self, value) -> None:
        sp = self.sp
        self.write(STACK_PAGE | _uniform(sp), value)
        self.sp = (sp - 1) & BYTE

    def pull(self):
        self.sp = (self.sp + 1) & BYTE
        return self.read(STACK_PAGE | _uniform(self.sp))


class LaneCoverage:
    """What the lanes ran, per instruction address: executions, each conditional branch's lanes that
    jumped and that went on, and the fewest and most cycles one execution took (penalties included).
    Counted per group run, so it costs a few Python operations per instruction group, not per lane:
    a fixed-cost instruction's cycles come from its table row; only rows whose cycles vary (page
    penalties, the 65C02's decimal cycle, BRA) compare each lane's cycles before and after, and only
    until the address has cost both its least and its most."""

    def __init__(self, variant: str, first_lanes: bool = False) -> None:
        self.executed: dict[int, int] = {}
        # with first_lanes: per branch direction (pc, taken), the lowest lane that went that way
        self.first_lane: dict[tuple[int, bool], int] | None = {} if first_lanes else None
        self.taken: dict[int, int] = {}
        self.not_taken: dict[int, int] = {}
        self.cycles_min: dict[int, int] = {}
        self.cycles_max: dict[int, int] = {}
        self.base, self.branches, self.varying, self.ceiling = _cost_rows(variant)

    def cycles(self, pc: int, low: int, high: int) -> None:
        known = self.cycles_min.get(pc)
        if known is None or low < known:
            self.cycles_min[pc] = low
        known = self.cycles_max.get(pc)
        if known is None or high > known:
            self.cycles_max[pc] = high

    def branch(self, pc: int, base: int, lanes: int, jumped: int, extra: int) -> None:
        """A branch at pc run by `lanes` lanes, `jumped` of them taking it at `extra` cycles more."""
        self.taken[pc] = self.taken.get(pc, 0) + jumped
        self.not_taken[pc] = self.not_taken.get(pc, 0) + lanes - jumped
        self.cycles(pc, base if jumped < lanes else base + extra, base + extra if jumped else base)

    def note_lanes(self, pc: int, ids, taken: np.ndarray) -> None:
        """The lowest lane of each way a branch went (ids: the group's lane numbers)."""
        first = self.first_lane
        for way, lanes in ((True, taken), (False, ~taken)):
            if lanes.any():
                lane = int(np.flatnonzero(lanes)[0]) if isinstance(ids, slice) else int(ids[lanes].min())
                if lane < first.get((pc, way), lane + 1):
                    first[(pc, way)] = lane

    def merge(self, other: "LaneCoverage", lane_offset: int = 0) -> None:
        """Add another run's counts (its lanes numbered from `lane_offset` in this one)."""
        if self.first_lane is not None:
            for key, lane in other.first_lane.items():
                self.first_lane.setdefault(key, lane + lane_offset)
        for mine, theirs in ((self.executed, other.executed), (self.taken, other.taken),
                             (self.not_taken, other.not_taken)):
            for pc, count in theirs.items():
                mine[pc] = mine.get(pc, 0) + count
        for pc, low in other.cycles_min.items():
            self.cycles(pc, low, other.cycles_max[pc])


@functools.cache
def _cost_rows(variant: str) -> tuple[dict, frozenset, frozenset, dict]:
    """Per opcode of a CPU's table: base cycles; the conditional branches; the rows whose cost varies
    (page penalties, branches, BRA, the 65C02's decimal cycle); the most a varying non-branch row can
    cost (once an address has cost its base and this, its lanes need not be measured again:
    instructions in loops stop costing numpy work)."""
    table = VARIANTS[variant].opcode_table
    decimal_cycle = table is not OPCODE_TABLE  # the 65C02's ADC/SBC: one cycle more with D set
    decimal = {opcode for opcode, row in table.items() if decimal_cycle and row.mnemonic in ("ADC", "SBC")}
    varying = frozenset(opcode for opcode, row in table.items()
                        if row.page_penalty or row.mode in ("rel", "zpr") or opcode in decimal)
    ceiling = {opcode: row.cycles + PAGE_CROSS_CYCLES * row.page_penalty + DECIMAL_EXTRA_CYCLES * (opcode in decimal)
               for opcode, row in table.items() if opcode in varying and row.mode != "rel"}
    return ({opcode: row.cycles for opcode, row in table.items()},
            frozenset(opcode for opcode, row in table.items() if is_conditional_branch(row)), varying, ceiling)


class BatchCpu:
    """N lanes of one 6502 on one memory image (see the module docstring). With `coverage`, what the
    lanes ran is counted in `self.coverage` (a LaneCoverage); with `first_lanes` also which lane first
    went each way at every branch (the coverage-guided search's feedback)."""

    def __init__(self, variant: str, image, lanes: int, *, stop_on_brk: bool = True,
                 memory_limit: int = MAX_PRIVATE_BYTES, coverage: bool = False, first_lanes: bool = False) -> None:
        if variant not in VARIANTS:
            raise InputError(f"unknown CPU variant {variant!r} (known: {', '.join(VARIANTS)})")
        self.variant = variant
        self.decimal = VARIANTS[variant].has_decimal
        self.handlers = HANDLERS
        if VARIANTS[variant].opcode_table is not OPCODE_TABLE:  # the 65C02: its own table of handlers
            from retro.cpu.batch65c02 import HANDLERS_65C02
            self.handlers = HANDLERS_65C02
        self.coverage = LaneCoverage(variant, first_lanes) if coverage or first_lanes else None
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
        # A chip's bus stalls (retro.routines.chip_access.BusStalls), or None: bus_stall(opcode, began,
        # spent) -> cycles each lane waits in that instruction, added to its cycles and to `stolen`
        self.bus_stall = None
        self.stolen = np.zeros(lanes, dtype=np.int64)
        self._began = np.zeros(lanes, dtype=np.int64)
        # address -> (Lanes -> bool per lane): lanes for which it is true stop there with LaneError.FACT
        self.watch: dict = {}

    def _everyone(self) -> Lanes:
        return Lanes(self, slice(None), self.a.copy(), self.x.copy(), self.y.copy(), self.p.copy(), self.sp.copy(),
                     self.cycles.copy())

    # ---- running -------------------------------------------------------------------------------

    def call(self, entry: int, budget: int, return_pc: int, return_sp) -> None:
        """Run every lane from entry until it stands at return_pc with S = return_sp (the caller has
        pushed the return address and set S), or stops with an error. Cycles count from entry."""
        pending: dict[int, list[Lanes]] = {entry: [self._everyone()]}
        runs = 0
        last_pc = -1
        while pending:
            pc = min(pending)
            group = Lanes.join(pending.pop(pc))
            if pc == return_pc:  # return_sp: one S for every lane, or an array of one per lane
                home = group.sp == (return_sp if isinstance(return_sp, int) else return_sp[group.ids])
                if home.any():
                    done = group.take(np.flatnonzero(home))
                    done.store()
                    self.pc[done.ids] = pc
                    late = np.flatnonzero(done.cycles > budget)
                    if len(late):
                        done.take(late).stop(pc, LaneError.BUDGET)
                    if home.all():
                        continue
                    group = group.take(np.flatnonzero(~home))
            runs += 1
            backward, last_pc = pc < last_pc, pc
            if backward or runs % BUDGET_CHECK_EVERY == 0:  # a loop jumps back: runaways are caught here
                spent = group.cycles >= budget
                if spent.any():
                    group.take(np.flatnonzero(spent)).stop(pc, LaneError.BUDGET)
                    if spent.all():
                        continue
                    group = group.take(np.flatnonzero(~spent))
            if pc in self.watch:
                broken = np.asarray(self.watch[pc](group), dtype=bool)
                if broken.any():
                    group.take(np.flatnonzero(broken)).stop(pc, LaneError.FACT)
                    if broken.all():
                        continue
                    group = group.take(np.flatnonzero(~broken))
            for target, lanes in self._run_at(group, pc):
                for where, part in _by_address(target, lanes):
                    pending.setdefault(where, []).append(part)

    def step(self) -> None:
        """Run one instruction on every lane from its own PC (for single-step test vectors)."""
        for target, lanes in self._run_at(self._everyone(), _uniform(self.pc)):
            lanes.store()
            self.pc[lanes.ids] = target

    def _run_at(self, group: Lanes, pc):
        """Run the instruction at pc (an int, or per-lane) for a group; yield (next pc, lanes)."""
        memory = self.memory
        if isinstance(pc, int) and not memory.is_private[pc >> 8] and not memory.is_private[((pc + 2) & WORD) >> 8]:
            shared = memory.shared
            yield from self._dispatch(int(shared[pc]), group, pc, int(shared[(pc + 1) & WORD]),
                                      int(shared[(pc + 2) & WORD]))
            return
        opcodes = _uniform(group.read(pc))
        lo = _uniform(group.read((pc + 1) & WORD))
        hi = _uniform(group.read((pc + 2) & WORD))
        if isinstance(opcodes, int):
            yield from self._dispatch(opcodes, group, pc, lo, hi)
            return
        for opcode in np.unique(opcodes).tolist():
            hit = np.flatnonzero(opcodes == opcode)
            yield from self._dispatch(opcode, group.take(hit), _uniform(pc if isinstance(pc, int) else pc[hit]),
                                      _uniform(lo if isinstance(lo, int) else lo[hit]),
                                      _uniform(hi if isinstance(hi, int) else hi[hit]))

    def _dispatch(self, opcode: int, group: Lanes, pc, lo, hi):
        self.instructions += 1
        handler = self.handlers.get(opcode)
        if handler is None:
            group.stop(pc, LaneError.JAM if opcode in JAM_OPCODES else LaneError.UNSTABLE)
            return
        stall = self.bus_stall
        if stall is not None:
            self._began[group.ids] = group.cycles
        coverage = self.coverage
        before = None  # the lanes' cycles before an instruction whose cost varies (coverage measures it)
        if coverage is not None and isinstance(pc, int):
            executed = coverage.executed
            executed[pc] = executed.get(pc, 0) + len(group)
            if opcode not in coverage.varying:
                base = coverage.base[opcode]
                coverage.cycles(pc, base, base)
            elif opcode not in coverage.branches and (  # _branch_split counts the branches
                    coverage.cycles_min.get(pc) != coverage.base[opcode]
                    or coverage.cycles_max.get(pc) != coverage.ceiling.get(opcode)):
                before = group.cycles.copy()
        result = handler(group, pc, lo, hi)
        if before is not None and not isinstance(result, list):
            spent = group.cycles - before  # (stolen cycles come below: coverage counts the CPU's own)
            coverage.cycles(pc, int(spent.min()), int(spent.max()))
        parts = result if isinstance(result, list) else [(result, group)]
        if stall is not None:
            for _, lanes in parts:
                began = self._began[lanes.ids]
                delay = stall(opcode, began, lanes.cycles - began)
                lanes.cycles += delay
                self.stolen[lanes.ids] += delay
        yield from parts

    def read(self, address: int) -> np.ndarray:
        """Every lane's byte at address."""
        value = self.memory.read(slice(None), address)
        return np.full(self.lanes, value, dtype=np.int32) if isinstance(value, int) else value.copy()


def _by_address(target, lanes: Lanes):
    """(address, lanes) for one next address, or per distinct address of a per-lane array."""
    if isinstance(target, int):
        yield target, lanes
        return
    order = np.argsort(target, kind="stable")
    ordered = target[order]
    starts = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]])
    for start, end in zip(starts.tolist(), np.r_[starts[1:], len(ordered)].tolist()):
        yield int(ordered[start]), lanes.take(order[start:end])


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
