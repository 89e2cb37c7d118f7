"""SMT proofs of fragment equivalence (z3): a straight-line or forward-branching run of 6502
instructions translated into bit-vector formulas, and two such fragments proven to leave the same
values in everything live after them, from every entry state.

The model (one home: `step`): A, X, Y as 8-bit vectors; N, V, D, I, Z, C as booleans; memory as an
array from 16-bit addresses to bytes (plain RAM: routines with a world are refused before this);
cycles as a 16-bit vector (the opcode table's base cycles, +1 for an indexed read that crosses a
page, a branch's +1 taken and +1 more into another page: retro.cpu.opcodes, retro.cpu.timing).
Decimal mode is the NMOS 6510's (64doc: ADC's Z from the binary sum, N and V from the half-adjusted
result, C from the adjusted high nybble; SBC's flags all from the binary difference, the accumulator
adjusted per nybble), and the 2A03 ignores D, as retro.cpu.mpu has them. The 65C02, the stack
(PHA, PLA, PHP, PLP, TSX, TXS), JSR, RTS, RTI, BRK, JMP other than to a label ahead in the
fragment (`jumps_ahead`: an edge always taken, its 3 cycles counted) and the undocumented opcodes are
not translated: a fragment holding one is `unsupported`, never proven.

Entry state: every register, flag and memory byte is a free variable, except what the caller can
stand behind (`Assumptions`): the code block's bytes (each side its own), the bytes of the program
and of `[memory]` when nothing in the routine can store to them, and D when the spec fixes it and
nothing in the routine changes it.

tests/optimize/test_smt.py checks every translated opcode against the Machine (retro.cpu.machine)
on random states, and proves and refutes fragments whose answer is known."""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field

import z3

from retro.cpu.disassembly import opcode_table
from retro.cpu.timing import BRANCH_PAGE_CYCLES, BRANCH_TAKEN_CYCLES, PAGE_CROSS_CYCLES, PAGE_MASK
from retro.optimize.code import Instruction, Listing, opcode_of
from retro.optimize.effects import ALL_MEMORY

CPUS = ("6510", "2a03")  # the variants translated (the 65C02's decimal flags and opcodes are not)
DECIMAL_CPUS = ("6510",)
FLAG_NAMES = ("N", "V", "D", "I", "Z", "C")
TIMEOUT_MS = 5_000  # one solver call; past it the change stays unproven ("unknown"): proofs come on top of the budget
BRANCH_FLAGS = {"BCC": ("C", False), "BCS": ("C", True), "BEQ": ("Z", True), "BNE": ("Z", False),
                "BMI": ("N", True), "BPL": ("N", False), "BVC": ("V", False), "BVS": ("V", True)}
LOADS = {"LDA": "a", "LDX": "x", "LDY": "y"}
STORES = {"STA": "a", "STX": "x", "STY": "y"}
TRANSFERS = {"TAX": ("a", "x"), "TAY": ("a", "y"), "TXA": ("x", "a"), "TYA": ("y", "a")}
COUNTERS = {"INX": ("x", 1), "INY": ("y", 1), "DEX": ("x", -1), "DEY": ("y", -1)}
FLAG_SETTERS = {"CLC": ("C", False), "SEC": ("C", True), "CLD": ("D", False), "SED": ("D", True),
                "CLI": ("I", False), "SEI": ("I", True), "CLV": ("V", False)}
LOGIC = {"AND": lambda a, v: a & v, "ORA": lambda a, v: a | v, "EOR": lambda a, v: a ^ v}
COMPARES = {"CMP": "a", "CPX": "x", "CPY": "y"}
SHIFTS = ("ASL", "LSR", "ROL", "ROR")
READ_MODIFY_WRITE = SHIFTS + ("INC", "DEC")
MODES = ("imp", "acc", "imm", "zpg", "zpx", "zpy", "abs", "abx", "aby", "inx", "iny", "rel")
TRANSLATED = frozenset(list(LOADS) + list(STORES) + list(TRANSFERS) + list(COUNTERS) + list(FLAG_SETTERS)
                       + list(LOGIC) + list(COMPARES) + list(READ_MODIFY_WRITE) + list(BRANCH_FLAGS)
                       + ["ADC", "SBC", "BIT", "NOP"])


class Unsupported(Exception):
    """A fragment the translation does not cover (the reason is the message)."""


@dataclass
class Machine:
    """The symbolic machine state: registers, flags, memory, cycles spent, and every address the
    fragment wrote (for the rule that it never writes into the code)."""

    a: z3.BitVecRef
    x: z3.BitVecRef
    y: z3.BitVecRef
    flags: dict
    memory: z3.ArrayRef
    cycles: z3.BitVecRef
    written: list = field(default_factory=list)
    touched: list = field(default_factory=list)  # every data address read or written

    def copy(self) -> "Machine":
        return Machine(self.a, self.x, self.y, dict(self.flags), self.memory, self.cycles, list(self.written),
                       list(self.touched))


def byte(value: int) -> z3.BitVecRef:
    return z3.BitVecVal(value & 0xFF, 8)


def word(value: int) -> z3.BitVecRef:
    return z3.BitVecVal(value & 0xFFFF, 16)


def free_machine(memory: z3.ArrayRef, prefix: str = "") -> Machine:
    """Every register and flag a free variable, cycles 0."""
    return Machine(z3.BitVec(prefix + "A", 8), z3.BitVec(prefix + "X", 8), z3.BitVec(prefix + "Y", 8),
                   {name: z3.Bool(prefix + name) for name in FLAG_NAMES}, memory, word(0))


def _nz(state: Machine, value: z3.BitVecRef) -> None:
    state.flags["N"] = z3.Extract(7, 7, value) == 1
    state.flags["Z"] = value == 0


def _wide(value: z3.BitVecRef, width: int = 16) -> z3.BitVecRef:
    return z3.ZeroExt(width - value.size(), value)


def _bit(flag: z3.BoolRef, width: int) -> z3.BitVecRef:
    return z3.If(flag, z3.BitVecVal(1, width), z3.BitVecVal(0, width))


def _read(memory: z3.ArrayRef, address: z3.BitVecRef) -> z3.BitVecRef:
    return z3.Select(memory, address)


def effective_address(state: Machine, instruction: Instruction) -> tuple[z3.BitVecRef | None, z3.BoolRef]:
    """(the data address, whether indexing crossed a page) of a memory mode; (None, False) otherwise.
    Zero-page indexing and the pointer's high byte wrap in page zero."""
    mode, operand = instruction.mode, instruction.operand
    no = z3.BoolVal(False)
    if mode in ("zpg", "abs"):
        return word(operand), no
    if mode in ("zpx", "zpy"):
        index = state.x if mode == "zpx" else state.y
        return _wide(byte(operand) + index), no
    if mode in ("abx", "aby"):
        index = state.x if mode == "abx" else state.y
        address = word(operand) + _wide(index)
        return address, (word(operand) & PAGE_MASK) != (address & PAGE_MASK)
    if mode == "inx":
        pointer = byte(operand) + state.x
        low, high = _read(state.memory, _wide(pointer)), _read(state.memory, _wide(pointer + 1))
        state.touched += [_wide(pointer), _wide(pointer + 1)]
        return z3.Concat(high, low), no
    if mode == "iny":
        low, high = _read(state.memory, word(operand & 0xFF)), _read(state.memory, word((operand + 1) & 0xFF))
        state.touched += [word(operand & 0xFF), word((operand + 1) & 0xFF)]
        base = z3.Concat(high, low)
        address = base + _wide(state.y)
        return address, (base & PAGE_MASK) != (address & PAGE_MASK)
    return None, no


def _adc(state: Machine, value: z3.BitVecRef, decimal: bool) -> None:
    a, carry = state.a, _bit(state.flags["C"], 16)
    a16, v16 = _wide(a), _wide(value)
    binary = a16 + v16 + carry
    result = z3.Extract(7, 0, binary)
    overflow = z3.Extract(7, 7, ~(a ^ value) & (a ^ result)) == 1
    binary_flags = (z3.Extract(7, 7, result) == 1, overflow, result == 0, z3.UGT(binary, 0xFF))
    if not decimal:
        state.a = result
        state.flags["N"], state.flags["V"], state.flags["Z"], state.flags["C"] = binary_flags
        return
    # NMOS decimal ADC (64doc), as retro.cpu.mpu.MPU6510._adc
    low = (a16 & 0x0F) + (v16 & 0x0F) + carry
    low = z3.If(z3.UGT(low, 9), low + 6, low)
    t = z3.If(z3.ULE(low, 0x0F), (low & 0x0F) + (a16 & 0xF0) + (v16 & 0xF0),
              (low & 0x0F) + (a16 & 0xF0) + (v16 & 0xF0) + 0x10)
    d_overflow = z3.And(((a16 ^ t) & 0x80) != 0, ((a16 ^ v16) & 0x80) == 0)
    d_negative = (t & 0x80) != 0
    adjusted = z3.If(z3.UGT(t & 0x1F0, 0x90), t + 0x60, t)
    d = state.flags["D"]
    state.flags["N"] = z3.If(d, d_negative, binary_flags[0])
    state.flags["V"] = z3.If(d, d_overflow, binary_flags[1])
    state.flags["Z"] = binary_flags[2]
    state.flags["C"] = z3.If(d, z3.UGT(adjusted & 0xFF0, 0xF0), binary_flags[3])
    state.a = z3.If(d, z3.Extract(7, 0, adjusted), result)


def _sbc(state: Machine, value: z3.BitVecRef, decimal: bool) -> None:
    a, borrow = state.a, _bit(z3.Not(state.flags["C"]), 16)
    a16, v16 = _wide(a), _wide(value)
    binary = a16 - v16 - borrow
    result = z3.Extract(7, 0, binary)
    _nz(state, result)
    state.flags["C"] = z3.UGE(a16, v16 + borrow)
    state.flags["V"] = z3.Extract(7, 7, (a ^ value) & (a ^ result)) == 1
    if not decimal:
        state.a = result
        return
    # NMOS decimal SBC (64doc), as retro.cpu.mpu.MPU6510._sbc: flags binary, A adjusted per nybble
    low = (a16 & 0x0F) - (v16 & 0x0F) - borrow
    high = z3.LShR(a16, 4) - z3.LShR(v16, 4)
    low_borrowed = (low & 0x10) != 0
    low, high = z3.If(low_borrowed, low - 6, low), z3.If(low_borrowed, high - 1, high)
    high = z3.If((high & 0x10) != 0, high - 6, high)
    state.a = z3.If(state.flags["D"], z3.Extract(7, 0, (high << 4) | (low & 0x0F)), result)


def _shift(state: Machine, name: str, value: z3.BitVecRef) -> z3.BitVecRef:
    carry_in = _bit(state.flags["C"], 8)
    if name == "ASL":
        out, state.flags["C"] = value << 1, z3.Extract(7, 7, value) == 1
    elif name == "LSR":
        out, state.flags["C"] = z3.LShR(value, 1), z3.Extract(0, 0, value) == 1
    elif name == "ROL":
        out, state.flags["C"] = (value << 1) | carry_in, z3.Extract(7, 7, value) == 1
    else:
        out, state.flags["C"] = z3.LShR(value, 1) | (carry_in << 7), z3.Extract(0, 0, value) == 1
    _nz(state, out)
    return out


@functools.cache
def _op(cpu: str, mnemonic: str, mode: str):
    opcode = opcode_of(cpu).get((mnemonic, mode))
    if opcode is None:
        raise Unsupported(f"{mnemonic} {mode}: no such opcode on the {cpu}")
    return opcode_table(cpu)[opcode]


def supported(instruction: Instruction, cpu: str) -> bool:
    return (cpu in CPUS and instruction.mnemonic in TRANSLATED and instruction.mode in MODES
            and (instruction.mnemonic, instruction.mode) in opcode_of(cpu)
            and (instruction.mode != "rel" or isinstance(instruction.target, str)))


def jumps_ahead(instruction: Instruction) -> bool:
    """A JMP absolute to a label: `run` follows it as an edge when the label is ahead in the
    fragment (a jump back, a loop, stays unsupported)."""
    return instruction.mnemonic == "JMP" and instruction.mode == "abs" and isinstance(instruction.target, str)


def step(state: Machine, instruction: Instruction, cpu: str) -> Machine:
    """The state after one non-branch instruction (branches: `run`)."""
    name, mode = instruction.mnemonic, instruction.mode
    if not supported(instruction, cpu) or mode == "rel":
        raise Unsupported(f"{name} {mode}: not translated")
    op = _op(cpu, name, mode)
    state = state.copy()
    address, crossed = effective_address(state, instruction)
    if address is not None:
        state.touched.append(address)
    penalty = z3.If(crossed, word(PAGE_CROSS_CYCLES), word(0)) if op.page_penalty else word(0)
    state.cycles = state.cycles + op.cycles + penalty

    def operand() -> z3.BitVecRef:
        return byte(instruction.operand) if mode == "imm" else _read(state.memory, address)

    def write(value: z3.BitVecRef) -> None:
        state.memory = z3.Store(state.memory, address, value)
        state.written.append(address)

    decimal = cpu in DECIMAL_CPUS
    if name in LOADS:
        value = operand()
        setattr(state, LOADS[name], value)
        _nz(state, value)
    elif name in STORES:
        write(getattr(state, STORES[name]))
    elif name in TRANSFERS:
        source, target = TRANSFERS[name]
        setattr(state, target, getattr(state, source))
        _nz(state, getattr(state, target))
    elif name in COUNTERS:
        register, delta = COUNTERS[name]
        setattr(state, register, getattr(state, register) + delta)
        _nz(state, getattr(state, register))
    elif name in FLAG_SETTERS:
        flag, value = FLAG_SETTERS[name]
        state.flags[flag] = z3.BoolVal(value)
    elif name in LOGIC:
        state.a = LOGIC[name](state.a, operand())
        _nz(state, state.a)
    elif name in COMPARES:
        register, value = getattr(state, COMPARES[name]), operand()
        state.flags["C"] = z3.UGE(register, value)
        _nz(state, register - value)
    elif name == "ADC":
        _adc(state, operand(), decimal)
    elif name == "SBC":
        _sbc(state, operand(), decimal)
    elif name == "BIT":
        value = operand()
        state.flags["Z"] = (state.a & value) == 0
        state.flags["N"] = z3.Extract(7, 7, value) == 1
        state.flags["V"] = z3.Extract(6, 6, value) == 1
    elif name in SHIFTS:
        if mode == "acc":
            state.a = _shift(state, name, state.a)
        else:
            write(_shift(state, name, operand()))
    elif name in ("INC", "DEC"):
        value = operand() + (1 if name == "INC" else -1)
        _nz(state, value)
        write(value)
    elif name != "NOP":
        raise Unsupported(f"{name}: not translated")
    return state


def _merge(arrivals: list) -> tuple[z3.BoolRef, Machine]:
    """One state from the paths reaching a point (guards exclusive): if-then-else on the guards."""
    guard, state = arrivals[-1]
    state = state.copy()
    for other_guard, other in reversed(arrivals[:-1]):
        state = Machine(z3.If(other_guard, other.a, state.a), z3.If(other_guard, other.x, state.x),
                        z3.If(other_guard, other.y, state.y),
                        {n: z3.If(other_guard, other.flags[n], state.flags[n]) for n in FLAG_NAMES},
                        z3.If(other_guard, other.memory, state.memory),
                        z3.If(other_guard, other.cycles, state.cycles),
                        [z3.If(other_guard, a, w) for a, w in _paired(other.written, state.written)],
                        [z3.If(other_guard, a, w) for a, w in _paired(other.touched, state.touched)])
        guard = z3.Or(other_guard, guard)
    return guard, state


def _paired(first: list, second: list) -> list:
    """Address lists of two paths made one length (a path's missing entries repeat its last, or the
    other path's: an address it did touch), for a merge per position."""
    if not first and not second:
        return []
    first = first or [second[0]]
    second = second or [first[0]]
    n = max(len(first), len(second))
    return list(zip(first + [first[-1]] * (n - len(first)), second + [second[-1]] * (n - len(second))))


@dataclass(frozen=True)
class Fragment:
    """Instructions run from `address`, their labels (name -> index in the fragment, up to its
    length: the point just after it) and the CPU."""

    instructions: tuple[Instruction, ...]
    address: int
    labels: dict
    cpu: str
    returns: bool = False  # a whole routine: an RTS goes to the end (the stack is not modelled)


def run(fragment: Fragment, state: Machine) -> Machine:
    """The state after the fragment: forward branches and JMPs to a label inside it or just after it
    are followed as paths and joined where they meet; anything else is Unsupported."""
    instructions = fragment.instructions
    n = len(instructions)
    rts = _op(fragment.cpu, "RTS", "imp") if fragment.returns else None
    addresses = [fragment.address]
    for instruction in instructions:
        addresses.append(addresses[-1] + instruction.length)
    arrivals: dict[int, list] = {0: [(z3.BoolVal(True), state)]}
    for k, instruction in enumerate(instructions):
        if k not in arrivals:
            continue  # unreachable inside the fragment (after a branch that is always taken)
        guard, here = _merge(arrivals.pop(k))
        if rts is not None and instruction.mnemonic == "RTS":  # the whole routine: an RTS ends a path
            here = here.copy()
            here.cycles = here.cycles + rts.cycles
            arrivals.setdefault(n, []).append((guard, here))
            continue
        if jumps_ahead(instruction):
            target = fragment.labels.get(instruction.target)
            if target is None or target <= k:
                raise Unsupported(f"JMP {instruction.target}: a jump out of the fragment or back")
            went = here.copy()
            went.cycles = here.cycles + _op(fragment.cpu, "JMP", "abs").cycles
            arrivals.setdefault(target, []).append((guard, went))
            continue
        if instruction.mode != "rel":
            arrivals.setdefault(k + 1, []).append((guard, step(here, instruction, fragment.cpu)))
            continue
        if not supported(instruction, fragment.cpu):
            raise Unsupported(f"{instruction.mnemonic}: not translated")
        target = fragment.labels.get(instruction.target)
        if target is None or target <= k:
            raise Unsupported(f"{instruction.mnemonic} {instruction.target}: a branch out of the fragment or back")
        flag, wanted = BRANCH_FLAGS[instruction.mnemonic]
        taken = here.flags[flag] if wanted else z3.Not(here.flags[flag])
        op = _op(fragment.cpu, instruction.mnemonic, "rel")
        crossed = ((addresses[k] + 2) & PAGE_MASK) != (addresses[target] & PAGE_MASK)
        went = here.copy()
        went.cycles = here.cycles + op.cycles + BRANCH_TAKEN_CYCLES + (BRANCH_PAGE_CYCLES if crossed else 0)
        stayed = here.copy()
        stayed.cycles = here.cycles + op.cycles
        arrivals.setdefault(target, []).append((z3.And(guard, taken), went))
        arrivals.setdefault(k + 1, []).append((z3.And(guard, z3.Not(taken)), stayed))
    if n not in arrivals:
        raise Unsupported("no path reaches the fragment's end")
    return _merge(arrivals[n])[1]


# ---- two fragments of two listings ---------------------------------------------------------------

@dataclass(frozen=True)
class Assumptions:
    """What the entry state of the fragment is known to hold: `fixed` bytes (address -> byte),
    registers and flags (D when the spec fixes it and nothing before the fragment changes it);
    everything else is free. The code block (`code_range`) is never read or written by either
    fragment (a proof obligation), so the two sides' different code bytes need no model."""

    fixed: dict = field(default_factory=dict)
    registers: dict = field(default_factory=dict)  # "a"/"x"/"y" -> its byte on entry (the rest free)
    flags: dict = field(default_factory=dict)  # flag name -> its value on entry (the rest free)
    # the inputs' values: (places, lo, hi, listed values or None); a place is ("register", "a"),
    # ("flag", "C") or ("memory", address), low byte first (the spec's domain, as far as it is ranges)
    inputs: tuple = ()
    code_range: tuple[int, int] = (0, 0)  # [start, end): the code block, which no fragment may read or write


@dataclass
class Result:
    """`status`: "proven", "refuted" (a counterexample entry state in `model`), "unknown" (the
    solver gave up) or "unsupported" (`reason`)."""

    status: str
    reason: str = ""
    model: dict | None = None  # "a", "x", "y", flag names, "memory": {address: byte}
    seconds: float = 0.0
    cycles: tuple | None = None  # (before max, after max) over all entry states, when proven
    no_slower: bool | None = None  # the new fragment never takes more cycles than the old

    def record(self) -> dict:
        return {"status": self.status, "reason": self.reason, "seconds": round(self.seconds, 3),
                "worst_cycles": list(self.cycles) if self.cycles else None, "no_slower": self.no_slower}


def _differs(before: Machine, after: Machine, live: frozenset, code_range: tuple[int, int]) -> z3.BoolRef:
    """Some live register, flag or byte differs (ALL_MEMORY: any byte outside the code block)."""
    parts = []
    for register in ("A", "X", "Y"):
        if register in live:
            parts.append(getattr(before, register.lower()) != getattr(after, register.lower()))
    parts += [before.flags[n] != after.flags[n] for n in FLAG_NAMES if n in live]
    for address in sorted(a for a in live if isinstance(a, int) and a != ALL_MEMORY):
        parts.append(_read(before.memory, word(address)) != _read(after.memory, word(address)))
    if ALL_MEMORY in live:
        anywhere = z3.BitVec("any_address", 16)
        start, end = code_range
        parts.append(z3.And(z3.Or(z3.ULT(anywhere, start), z3.UGE(anywhere, end)) if end > start else z3.BoolVal(True),
                            _read(before.memory, anywhere) != _read(after.memory, anywhere)))
    return z3.Or(parts) if parts else z3.BoolVal(False)


def _in_code(addresses: list, code_range: tuple[int, int]) -> z3.BoolRef:
    start, end = code_range
    if end <= start or not addresses:
        return z3.BoolVal(False)
    return z3.Or([z3.And(z3.UGE(a, start), z3.ULT(a, end)) for a in addresses])


def _model_of(model: z3.ModelRef, entry: Machine, addresses: list) -> dict:
    value = {"a": model.eval(entry.a, model_completion=True).as_long(),
             "x": model.eval(entry.x, model_completion=True).as_long(),
             "y": model.eval(entry.y, model_completion=True).as_long()}
    for name in FLAG_NAMES:
        value[name] = z3.is_true(model.eval(entry.flags[name], model_completion=True))
    memory = {}
    for address in addresses:
        at = model.eval(address, model_completion=True).as_long()
        memory[at] = model.eval(z3.Select(entry.memory, word(at)), model_completion=True).as_long()
    value["memory"] = memory
    return value


def prove_equivalent(before: Fragment, after: Fragment, live: frozenset, assumptions: Assumptions = Assumptions(),
                     timeout_ms: int = TIMEOUT_MS, shown: tuple = ()) -> Result:
    """Whether `after` leaves everything in `live` (registers and flags by letter, addresses,
    ALL_MEMORY) as `before` does from every entry state the assumptions allow, neither reading nor
    writing the code block through a computed address."""
    began = time.process_time()
    try:
        entry = free_machine(z3.Array("memory", z3.BitVecSort(16), z3.BitVecSort(8)))
        end_before, end_after = run(before, entry), run(after, entry)
    except Unsupported as exc:
        return Result("unsupported", str(exc), seconds=time.process_time() - began)
    solver = z3.Solver()
    solver.set("timeout", timeout_ms)
    solver.add(_entry_facts(entry, assumptions))
    code_range = assumptions.code_range
    # an access into the code: the two sides' code differs there, and the suffix runs it
    solver.push()
    solver.add(z3.Or(_in_code(end_before.touched + end_after.touched, code_range)))
    hits_code = solver.check()
    solver.pop()
    if hits_code != z3.unsat:
        return Result("unsupported" if hits_code == z3.sat else "unknown",
                      "a fragment may read or write the routine's own code", seconds=time.process_time() - began)
    solver.add(_differs(end_before, end_after, live, code_range))
    verdict = solver.check()
    seconds = time.process_time() - began
    if verdict == z3.sat:
        touched = end_before.touched + end_after.touched
        shown_addresses = touched + [word(a) for a in shown]
        return Result("refuted", "the fragments differ", _model_of(solver.model(), entry, shown_addresses), seconds)
    if verdict != z3.sat and verdict != z3.unsat:
        return Result("unknown", f"z3: {solver.reason_unknown()}", seconds=seconds)
    result = Result("proven", seconds=seconds)
    result.cycles, result.no_slower = _cycles(end_before, end_after, entry, assumptions, timeout_ms)
    result.seconds = time.process_time() - began
    return result


def _entry_facts(entry: Machine, assumptions: Assumptions) -> z3.BoolRef:
    """The assumptions as constraints (the fixed bytes as equalities: z3 solves these far faster
    than reads through a chain of stores)."""
    facts = [getattr(entry, name) == byte(value) for name, value in assumptions.registers.items()]
    facts += [z3.Select(entry.memory, word(address)) == byte(value) for address, value in assumptions.fixed.items()]
    facts += [entry.flags[name] == z3.BoolVal(value) for name, value in assumptions.flags.items()]
    for places, lo, hi, listed in assumptions.inputs:
        value = _input_value(entry, places)
        if listed is not None:
            facts.append(z3.Or([value == v for v in listed]))
        else:
            facts += [z3.UGE(value, lo), z3.ULE(value, hi)]
    return z3.And(facts)


def _input_value(entry: Machine, places: tuple) -> z3.BitVecRef:
    """An input's value on entry from its places, low byte first (a flag is one bit, widened)."""
    parts = []
    for kind, key in places:
        if kind == "register":
            parts.append(getattr(entry, key))
        elif kind == "flag":
            parts.append(_bit(entry.flags[key], 8))
        else:
            parts.append(z3.Select(entry.memory, word(key)))
    value = parts[0] if len(parts) == 1 else z3.Concat(*reversed(parts))
    return z3.ZeroExt(64 - value.size(), value) if value.size() < 64 else value


def _cycles(end_before: Machine, end_after: Machine, entry: Machine, assumptions: Assumptions, timeout_ms: int):
    """(each side's most cycles over every entry state, whether the new one is never slower)."""
    worst = []
    for end in (end_before, end_after):
        optimizer = z3.Optimize()
        optimizer.set("timeout", timeout_ms)
        optimizer.add(_entry_facts(entry, assumptions))
        handle = optimizer.maximize(end.cycles)
        worst.append(handle.value().as_long() if optimizer.check() == z3.sat else None)
    solver = z3.Solver()
    solver.set("timeout", timeout_ms)
    solver.add(_entry_facts(entry, assumptions))
    solver.add(z3.UGT(end_after.cycles, end_before.cycles))
    verdict = solver.check()
    return tuple(worst), (True if verdict == z3.unsat else False if verdict == z3.sat else None)


# ---- the fragment two listings differ in ---------------------------------------------------------

def changed_fragments(old: Listing, new: Listing) -> tuple[int, int, int] | None:
    """(start, old stop, new stop): the instructions two listings differ in (a common prefix and
    suffix around them, at least one instruction on each side), or None when they are the same."""
    a, b = old.instructions, new.instructions
    if a == b:
        return None
    start = 0
    while start < min(len(a), len(b)) and a[start] == b[start]:
        start += 1
    suffix = 0
    while suffix < min(len(a), len(b)) - start and a[len(a) - 1 - suffix] == b[len(b) - 1 - suffix]:
        suffix += 1
    stop_a, stop_b = len(a) - suffix, len(b) - suffix
    if stop_a == start or stop_b == start:  # an empty side: take one common neighbour into both
        if suffix:
            stop_a, stop_b = stop_a + 1, stop_b + 1
        else:
            start -= 1
    return start, stop_a, stop_b


def fragment_of(listing: Listing, start: int, stop: int, cpu: str) -> Fragment:
    """The instructions [start, stop) of a listing with the labels inside or just after them; a
    branch from outside into its inside makes it Unsupported (it would not be one entry)."""
    where = dict(listing.labels)
    for k, instruction in enumerate(listing.instructions):
        if start <= k < stop or not isinstance(instruction.target, str):
            continue
        if start < where[instruction.target] < stop:
            raise Unsupported(f"a branch at instruction {k} enters the fragment at {where[instruction.target]}")
    address = listing.origin + sum(i.length for i in listing.instructions[:start])
    labels = {name: at - start for name, at in listing.labels if start < at <= stop}
    return Fragment(tuple(listing.instructions[start:stop]), address, labels, cpu)
