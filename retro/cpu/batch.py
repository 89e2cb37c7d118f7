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

The instructions are the handlers of `retro.cpu.batch_handlers` (the 65C02's: `retro.cpu.batch65c02`),
one per opcode. Semantics and cycle counts are those of `retro.cpu.mpu` (the scalar core, the reference): base
cycles and page-crossing penalties from the opcode table (`retro.cpu.opcodes`), branch penalties, NMOS decimal
mode on the 6510 (Bruce Clark, "Decimal Mode" tutorial, appendix A: the 6502's A, C, N, V and Z in
decimal mode), binary-only ADC/SBC on the 2A03, and the stable undocumented opcodes ("NMOS 6510
Unintended Opcodes - No More Secrets", groepaz, 2024). A lane stops with an error code (`LaneError`)
on BRK (when calls stop on it), JAM, an unstable opcode, or a spent cycle budget; the others go on.
No device is modelled: the engine serves plain-RAM routines (a scene with chips runs on `Machine`).
"""

from __future__ import annotations

import functools

import numpy as np

from retro.cpu.batch_handlers import HANDLERS, STACK_PAGE, WORD, LaneError, _uniform
from retro.cpu.lane_memory import BYTE, MAX_PRIVATE_BYTES, LaneMemory
from retro.cpu.mpu import FLAG_I, FLAG_U, JAM_OPCODES
from retro.cpu.opcodes import DECIMAL_EXTRA_CYCLES, OPCODE_TABLE
from retro.cpu.timing import PAGE_CROSS_CYCLES, is_conditional_branch
from retro.cpu.variants import VARIANTS
from retro.errors import InputError

# A lane whose cycles reach the budget stops there on Machine. Here the budget is looked at when the
# lowest waiting address is below the last one run (some lanes jumped back: every loop does), every
# BUDGET_CHECK_EVERY group runs, and when a lane returns (then cycles > budget is the same verdict): a
# lane past its budget may run a few more instructions, but it is reported as over the budget unless
# it stops first for another reason (BRK, JAM), which is a run error all the same.
BUDGET_CHECK_EVERY = 64


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
