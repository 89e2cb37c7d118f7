"""A routine's code translated, basic block by basic block, into the Python source of one function that
numba compiles (`retro.cpu.compiled`): the compiled engine's front half, pure (bytes in, text out).

The code is found from the entry as the static analysis finds it (branches both ways, JMP and JSR
targets, the address after every JSR, where its RTS returns). Every instruction becomes a few lines
with its operands, addresses and base cycles folded in; page-crossing penalties, taken branches and
decimal mode are tested at run time. A block starts at every address control can reach other than by
falling through; the function runs the calls one after another, each a loop over block numbers
(`blk`) whose body is a chain of `if blk == k:` (LLVM turns it into one jump table), so the code grows
with the instructions, not with the blocks squared.

Semantics and cycles are those of `retro.cpu.batch` (and so of `Machine`): the cycle table of
`retro.cpu.opcodes`, the branch rules of `retro.cpu.timing`, NMOS decimal mode on the 6510 (Bruce
Clark, "Decimal Mode", appendix A), binary ADC/SBC on the 2A03, the stable undocumented opcodes
("NMOS 6510 Unintended Opcodes - No More Secrets"), the WDC 65C02's table and decimal mode. The helpers
the generated code calls for the rare paths (decimal arithmetic, ARR) are in `retro.cpu.compiled_ops`.

What is not translated stops the call with FALLBACK, and the caller runs that call on the batched
core: BRK, RTI, JAM and unstable opcodes, STP/WAI, a jump (RTS, JMP (ind)) to an address that starts
no block, a write into code bytes the translation fixed (self-modifying code beyond operands).

Self-modifying code that patches only OPERANDS is translated (`live_operands`): an instruction one of
whose operand bytes a store at a fixed address (STA abs, INC zp, ...) writes reads all its operand
bytes from memory when it runs (its address, page crossing, immediate value or JMP target computed
then), so a patch made earlier in the call is seen, as `Machine` sees it; a store to a computed
address into those bytes is allowed too (logged and restored like any other). A fixed store into an
opcode byte, or into an operand the translation decodes (a branch's offset, a JSR's target, a BBR/BBS
operand), or an input placed in the code, is refused as a whole (`Untranslatable`, with the reason
the report gives); a computed store into such bytes leaves the call to the batched core.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from retro.cpu import ifconvert

from retro.cpu.mpu import FLAG_D
from retro.cpu.opcodes import DOCUMENTED, MODE_LENGTH, OPCODE_TABLE, OPCODE_TABLE_65C02, RESERVED, STABLE, Op
from retro.cpu.timing import (
    BRANCH_CONDITIONS,
    BRANCH_PAGE_CYCLES,
    BRANCH_TAKEN_CYCLES,
    PAGE_CROSS_CYCLES,
    PAGE_MASK,
    WDC_65C02,
    branch_target,
)

TRANSLATOR_VERSION = 10  # part of every cache key: a change of the generated code's meaning bumps it
# A call's status (the compiled function's per-call result): 0 returned, else why it stopped.
RETURNED = 0
BUDGET = 4  # the cycle budget was spent (retro.cpu.batch.LaneError.BUDGET)
FALLBACK = 100  # from here up: the call left the translated code and runs again on the batched core
FALLBACK_STOP = 101  # an instruction not translated (BRK, RTI, JAM, unstable, STP, WAI)
FALLBACK_JUMP = 102  # RTS or JMP (ind) to an address no dispatched block starts at
FALLBACK_WRITE = 103  # a write into the routine's own code bytes
FALLBACK_DECIMAL = 104  # D set on entry to code translated for binary mode only (`decimal_free`)
STOPPED = -1  # inside the function only: a loop check stopped the call (the budget, or `bad`: a write into the code)
JUMPED = -2  # inside the function only: a computed jump stopped the call (`_jump_to`: which way, settled after the loop)
NO_BLOCK = -1
WORD = 0xFFFF
BYTE = 0xFF
STACK_PAGE = 0x100


REGISTERS_OUT = tuple((name, name) for name in "axyp")  # `translate`'s `results`: the registers and P
RESULT_ROWS = ("cycles", "status")  # the rows of the function's `out` array after the results
SET_A, SET_X, SET_Y, SET_P, SET_FLAG = range(5)  # what a `sets` row of `translate` does with its column
SET_REGISTERS = "axyp"


class Untranslatable(Exception):
    """A routine the compiled engine does not take (the message says why: it goes in the report)."""


@dataclass(frozen=True)
class Translation:
    """The generated source and what the compiled function needs beside it."""

    source: str
    function_name: str
    blocks: dict[int, int]  # block start address -> block number
    code_bytes: frozenset[int]  # every byte of a translated instruction (writes there fall back, but to live_bytes)
    fixed_writes: tuple[int, ...]  # addresses written at a fixed address (restored after every call)
    instructions: int
    placed: tuple[int, ...] = ()  # addresses the function puts the case columns' bytes at (`places`)
    lanes: tuple[int, ...] | None = None  # the `lane_addr` the function was made for (None: any, looped over)
    outputs: tuple[int, ...] | None = None  # the `out_addr` likewise
    results: tuple[tuple[str, str], ...] = REGISTERS_OUT  # (name, expression) per `out` row before RESULT_ROWS
    live_bytes: frozenset[int] = frozenset()  # operand bytes read from memory at run time (`live_operands`)


def tables_for(cpu: str) -> dict[int, Op]:
    return OPCODE_TABLE_65C02 if cpu == WDC_65C02 else OPCODE_TABLE


# ---- finding the code -------------------------------------------------------------------------------

def _op(table: dict[int, Op], opcode: int) -> Op | None:
    op = table[opcode]
    return op if op.kind in (DOCUMENTED, STABLE, RESERVED) else None


STOPS = {"BRK", "RTI", "STP", "WAI"}  # not translated: the call runs on the batched core from here


def _successors(pc: int, op: Op | None, read: Callable[[int], int]) -> tuple[list[int], bool]:
    """(addresses control may go to next that start a block, whether it may fall through to pc + length)."""
    if op is None or op.mnemonic in STOPS or op.mnemonic == "RTS":
        return [], False
    length = MODE_LENGTH[op.mode]
    if op.mode == "rel":
        target = branch_target(pc, read((pc + 1) & WORD))
        return [target], op.mnemonic != "BRA"
    if op.mode == "zpr":
        return [branch_target(pc, read((pc + 2) & WORD), 3)], True
    if op.mnemonic == "JMP":
        return ([read((pc + 1) & WORD) | read((pc + 2) & WORD) << 8] if op.mode == "abs" else []), False
    if op.mnemonic == "JSR":
        return [read((pc + 1) & WORD) | read((pc + 2) & WORD) << 8, (pc + length) & WORD], False
    return [], True


def find_blocks(read: Callable[[int], int], entry: int, cpu: str, return_pc: int) -> tuple[list[int], dict]:
    """(block starts in address order, {pc: Op or None} of every reachable instruction)."""
    table = tables_for(cpu)
    leaders = {entry}
    instructions: dict[int, Op | None] = {}
    pending = [entry]
    while pending:
        pc = pending.pop()
        while pc not in instructions and pc != return_pc:
            op = _op(table, read(pc))
            instructions[pc] = op
            targets, falls = _successors(pc, op, read)
            for target in targets:
                if target != return_pc:
                    leaders.add(target)
                    pending.append(target)
            if not falls:
                break
            pc = (pc + MODE_LENGTH[op.mode]) & WORD
            if op.mode in ("rel", "zpr") and pc != return_pc:  # a branch ends its block: what follows starts one
                leaders.add(pc)
    return sorted(leaders), instructions


# ---- operands patched by the code itself ---------------------------------------------------------------

WRITERS = {"STA", "STX", "STY", "SAX", "STZ", "ASL", "LSR", "ROL", "ROR", "INC", "DEC", "SLO", "RLA", "SRE", "RRA",
           "DCP", "ISC", "TSB", "TRB", *(f"{kind}MB{bit}" for kind in "RS" for bit in range(8))}
DECODED = "a branch's offset, a JSR's target or a BBR/BBS operand, which the translation decodes"


def _fixed_target(pc: int, op: Op | None, read: Callable[[int], int]) -> int | None:
    """The address an instruction writes when it is a fixed one (zero page or absolute, as the image has it)."""
    if op is None or op.mnemonic not in WRITERS or op.mode not in ("zpg", "abs"):
        return None
    return read((pc + 1) & WORD) | (read((pc + 2) & WORD) << 8 if op.mode == "abs" else 0)


def _can_be_live(op: Op) -> bool:
    """Whether an instruction can read its operand bytes at run time (exactly, as the batched core and
    Machine do): not the control flow the blocks are cut by (branches, BBR/BBS, JSR: its push comes
    between the reads of its target's bytes); JMP abs and JMP (ind) go through the dispatch then."""
    return op.mode not in ("rel", "zpr") and op.mnemonic != "JSR"


def live_operands(instructions: dict, read: Callable[[int], int]) -> set[int]:
    """The instructions (their pc) whose operand bytes some store at a fixed address writes: they read
    their operands from memory when they run. Untranslatable when a fixed store reaches an opcode byte or
    an operand the translation decodes (`_can_be_live`). A store whose own operand is live has its image
    target looked at all the same (conservative: an extra live instruction is exact, only slower)."""
    holder = {(pc + k) & WORD: pc for pc, op in instructions.items() if op is not None
              for k in range(1, MODE_LENGTH[op.mode])}
    live: set[int] = set()
    for pc, op in sorted(instructions.items()):
        address = _fixed_target(pc, op, read)
        if address is None or (address not in instructions and address not in holder):
            continue
        why = f"self-modifying code: the instruction at ${pc:04X} writes ${address:04X}, "
        if address in instructions:
            raise Untranslatable(why + "an opcode byte of the routine's code")
        owner = holder[address]
        if not _can_be_live(instructions[owner]):
            raise Untranslatable(why + f"an operand byte of the instruction at ${owner:04X}: {DECODED}")
        live.add(owner)
    return live


# ---- code generation ------------------------------------------------------------------------------------
# State: a x y sp (ints), cycles; flags as fc fv fd fi (0/1) and N, Z lazily: N is bit 7 of `nv`, Z is
# set when `zv` == 0 (most instructions set both from one value: one assignment each).

def _read(address: str) -> str:
    return f"mem[{address}]"


class _Emitter:
    def __init__(self, cpu: str, code_bytes: frozenset[int], read: Callable[[int], int],
                 live: frozenset[int] = frozenset()) -> None:
        self.cpu = cpu
        self.decimal = cpu == "6510"  # NMOS decimal mode; the 2A03 has none; the 65C02's own below
        self.cmos = cpu == WDC_65C02
        self.binary = False  # D is 0 throughout (`decimal_free`): ADC and SBC inline, binary only
        self.adds = False  # an ADC or SBC was emitted: only then can D on entry make binary-only code wrong
        self.code_bytes = code_bytes  # the bytes the translation fixed (not live operands)
        self.live = live  # instructions that read their operand bytes at run time (`live_operands`)
        self.read = read
        self.lines: list[str] = []
        self.fixed_writes: set[int] = set()
        self.computed_writes = False  # a write to a computed address (or a push) was emitted
        self.pc = 0  # the instruction being emitted
        self.indent = ""
        self.inlined: set[int] = set()
        self.chained: set[int] = set()  # blocks some code reaches through the dispatch
        self.emit_block: Callable[[int], None] = lambda start: None
        self.instructions: dict[int, Op | None] = {}
        self.regions: dict[int, ifconvert.Region] = {}  # branches run without a jump (`_emit_converted`)
        self.converted = 0  # regions emitted so far: their variables' numbers
        self.guard: str | None = None  # inside a converted way: the variable that is 1 when it is the way taken
        self.return_arm: int | None = None  # the block number of the shared return arm, if any (`_emit_return_arm`)

    def put(self, line: str) -> None:
        self.lines.append(self.indent + line)

    # memory
    def write_fixed(self, pc: int, address: int, value: str) -> None:
        if address in self.code_bytes:  # (live_operands refused it first; kept so that no path misses it)
            raise Untranslatable(f"self-modifying code: the instruction at ${pc:04X} writes ${address:04X}, "
                                 f"a byte of the routine's code")
        self.fixed_writes.add(address)
        if self.guard is not None:  # a converted way's store: made only on the way taken (`_emit_converted`)
            value = f"choose({self.guard}, {value}, mem[{address}])"
        self.put(f"mem[{address}] = {value}")

    def write_at(self, address: str, value: str) -> None:
        """A write to a computed address: into the code -> the call falls back; logged for the restore."""
        self.computed_writes = True
        self.put(f"t = {address}")
        self.put("bad |= code_map[t]")  # looked at when the block ends: the call then runs again elsewhere
        self.put("log[nlog & LOG_MASK] = t")
        self.put("nlog += 1")
        self.put(f"mem[t] = {value}")

    def push(self, value: str) -> None:
        self.write_at(f"{STACK_PAGE} + sp", value)
        self.put("sp = (sp - 1) & 255")

    def pull(self, into: str) -> None:
        self.put("sp = (sp + 1) & 255")
        self.put(f"{into} = {_read(f'{STACK_PAGE} + sp')}")

    # operands: (address expression or int, page-crossing expression or None)
    def operand_bytes(self, pc: int, length: int) -> tuple[int | str, int | str]:
        """(low byte, the word when `length` is 3): numbers folded into the code, or, for a live
        instruction (`live_operands`), expressions of the bytes memory holds when it runs (the low
        one in `w`); the page crossing is then computed from that run-time address."""
        if pc in self.live:
            self.put(f"w = {_read((pc + 1) & WORD)}")
            return "w", (f"(w | ({_read((pc + 2) & WORD)} << 8))" if length == 3 else "w")
        lo = self.read((pc + 1) & WORD)
        return lo, (lo | self.read((pc + 2) & WORD) << 8 if length == 3 else lo)

    def address(self, pc: int, op: Op) -> tuple[str | int, str | None]:
        mode = op.mode
        lo, word = self.operand_bytes(pc, MODE_LENGTH[mode])
        following = (lo + 1) & BYTE if isinstance(lo, int) else f"({lo} + 1) & 255"
        if mode == "zpg":
            return lo, None
        if mode == "zpx":
            return f"({lo} + x) & 255", None
        if mode == "zpy":
            return f"({lo} + y) & 255", None
        if mode == "abs":
            if isinstance(word, str):
                self.put(f"ea = {word}")
                return "ea", None
            return word, None
        if mode in ("abx", "aby"):
            index = "x" if mode == "abx" else "y"
            self.put(f"ea = ({word} + {index}) & 65535")
            self.put(f"pg = ({lo} + {index}) >> 8")
            return "ea", "pg"
        if mode == "inx":
            self.put(f"t = ({lo} + x) & 255")
            self.put(f"ea = {_read('t')} | ({_read('(t + 1) & 255')} << 8)")
            return "ea", None
        if mode == "iny":
            self.put(f"t = {_read(lo)} | ({_read(following)} << 8)")
            self.put("ea = (t + y) & 65535")
            self.put("pg = ((t & 255) + y) >> 8")
            return "ea", "pg"
        if mode == "zpi":
            self.put(f"ea = {_read(lo)} | ({_read(following)} << 8)")
            return "ea", None
        raise AssertionError(mode)  # pragma: no cover

    def immediate(self, pc: int) -> str:
        """An immediate operand: the number, or for a live instruction the byte memory holds then."""
        return str(self.operand_bytes(pc, 2)[0])

    def operand(self, pc: int, op: Op) -> tuple[str, str | None]:
        """The value an instruction reads (an expression) and its page-crossing test."""
        if op.mode == "imm":
            return self.immediate(pc), None
        address, crossed = self.address(pc, op)
        self.put(f"v = {_read(address)}")
        return "v", crossed

    def cycles(self, base: int, crossed: str | None, penalised: bool) -> None:
        if penalised and crossed is not None:
            self.put(f"cycles += {base} + {crossed} * {PAGE_CROSS_CYCLES}")
        else:
            self.put(f"cycles += {base}")

    # ALU
    def nz(self, value: str) -> None:
        self.put(f"nv = {value}")
        self.put(f"zv = {value}")

    def add(self, name: str, value: str) -> None:
        """ADC (or SBC: `name` "sbc") of value: one call of the helper for this CPU's decimal mode
        (retro.cpu.compiled_ops); the 2A03 has none, the 65C02 takes a cycle more with D set."""
        self.adds = True
        if self.binary or not (self.decimal or self.cmos):
            operand = f"({value} ^ 255)" if name == "sbc" else value
            self.put(f"t = a + {operand} + fc")
            self.put(f"fv = (((a ^ t) & ({operand} ^ t)) >> 7) & 1")
            self.put("fc = t >> 8")
            self.put("a = t & 255")
            self.nz("a")
        else:
            family = "cmos" if self.cmos else "nmos"
            self.put(f"a, nv, zv, fv, fc = {name}_{family}(a, {value}, fc, fd)")
            if self.cmos:
                self.put("cycles += fd")

    def compare(self, register: str, value: str) -> None:
        self.put(f"t = {register} - {value}")
        self.put("fc = ((t >> 8) & 1) ^ 1")  # both are bytes: a negative difference has bit 8 set
        self.put("t = t & 255")
        self.nz("t")

    def shift(self, name: str, value: str, into: str) -> None:
        """into = the shift or step of value (an expression of other variables), flags set."""
        if name == "ASL":
            self.put(f"fc = {value} >> 7")
            self.put(f"{into} = ({value} << 1) & 255")
        elif name == "LSR":
            self.put(f"fc = {value} & 1")
            self.put(f"{into} = {value} >> 1")
        elif name == "ROL":
            self.put(f"t = ({value} << 1) | fc")
            self.put(f"fc = {value} >> 7")
            self.put(f"{into} = t & 255")
        elif name == "ROR":
            self.put(f"t = ({value} >> 1) | (fc << 7)")
            self.put(f"fc = {value} & 1")
            self.put(f"{into} = t")
        elif name == "INC":
            self.put(f"{into} = ({value} + 1) & 255")
        elif name == "DEC":
            self.put(f"{into} = ({value} - 1) & 255")
        else:  # pragma: no cover
            raise AssertionError(name)
        self.nz(into)

    def operate(self, name: str, value: str) -> None:
        """What a reading instruction does with its operand value."""
        if name in ("LDA", "LDX", "LDY", "LAX"):
            targets = {"LDA": "a", "LDX": "x", "LDY": "y", "LAX": "a"}[name]
            self.put(f"{targets} = {value}")
            if name == "LAX":
                self.put("x = a")
            self.nz(targets)
        elif name in ("ORA", "AND", "EOR"):
            symbol = {"ORA": "|", "AND": "&", "EOR": "^"}[name]
            self.put(f"a = a {symbol} {value}")
            self.nz("a")
        elif name == "ADC":
            self.add("adc", value)
        elif name in ("SBC", "USBC"):
            self.add("sbc", value)
        elif name in ("CMP", "CPX", "CPY"):
            self.compare({"CMP": "a", "CPX": "x", "CPY": "y"}[name], value)
        elif name == "BIT":
            self.put(f"nv = {value}")
            self.put(f"fv = ({value} >> 6) & 1")
            self.put(f"zv = a & {value}")
        elif name == "ANC":
            self.put(f"a = a & {value}")
            self.nz("a")
            self.put("fc = a >> 7")
        elif name == "ALR":
            self.put(f"t = a & {value}")
            self.shift("LSR", "t", "a")
        elif name == "ARR":
            if self.decimal:
                self.put(f"a, nv, zv, fv, fc = arr(a & {value}, fc, fd)")
            else:
                self.put(f"a, nv, zv, fv, fc = arr(a & {value}, fc, 0)")
        elif name == "SBX":
            self.put("w = a & x")
            self.compare("w", value)
            self.put("x = t")
        elif name == "NOP":
            pass
        else:  # pragma: no cover
            raise AssertionError(name)

    def pack_p(self) -> str:
        return f"((nv & 128) | (fv << 6) | 48 | (fd << 3) | (fi << 2) | {_Z_BIT} | fc)"

    def unpack_p(self, value: str) -> None:
        self.put(f"nv = {value} & 128")
        self.put(f"fv = ({value} >> 6) & 1")
        self.put(f"fd = ({value} >> 3) & 1")
        self.put(f"fi = ({value} >> 2) & 1")
        self.put(f"zv = ({value} & 2) ^ 2")
        self.put(f"fc = {value} & 1")


READS = {"LDA", "LDX", "LDY", "LAX", "ORA", "AND", "EOR", "ADC", "SBC", "USBC", "CMP", "CPX", "CPY", "BIT",
         "ANC", "ALR", "ARR", "SBX", "NOP"}
STORES = {"STA": "a", "STX": "x", "STY": "y", "SAX": "(a & x)", "STZ": "0"}
SHIFTS = ("ASL", "LSR", "ROL", "ROR", "INC", "DEC")
COMBINED = {"SLO": ("ASL", "ORA"), "RLA": ("ROL", "AND"), "SRE": ("LSR", "EOR"), "RRA": ("ROR", "ADC"),
            "DCP": ("DEC", "CMP"), "ISC": ("INC", "SBC")}
FLAG_SETTERS = {"CLC": ("fc", 0), "SEC": ("fc", 1), "CLI": ("fi", 0), "SEI": ("fi", 1), "CLV": ("fv", 0),
                "CLD": ("fd", 0), "SED": ("fd", 1)}
TRANSFERS = {"TAX": ("x", "a"), "TAY": ("y", "a"), "TXA": ("a", "x"), "TYA": ("a", "y"), "TSX": ("x", "sp")}
STEPS = {"INX": ("x", 1), "INY": ("y", 1), "DEX": ("x", -1), "DEY": ("y", -1)}
SHIFTS_ABX_65C02 = {"ASL", "LSR", "ROL", "ROR"}
TEST_BITS = {"TSB", "TRB", *(f"{kind}MB{bit}" for kind in "RS" for bit in range(8))}


def _jump_to(e: _Emitter) -> None:
    """Control goes to the computed address in `t`: a known block, or the call stops there (the
    caller's return, an address no dispatched block starts at, the loop check's budget or write into
    the code), in one test: which of them, and so the status, is settled once after the loop
    (`_FUNCTION`'s JUMPED, in that order). Four tests at each of aabb_sprite's 27 RTSs were most of
    its compile time. (A shared arm of the dispatch serves the RTSs only in code of RETURN_ARM_FROM or
    more, `_emit_rts`: an arm made every call of mul8 20% slower.)"""
    e.put("blk = addr_block[t]")
    e.put("if (blk < 0) | ((t == return_pc) & (sp == return_sp)) | (cycles >= budget) | (bad != 0):")
    e.put(f"    status = {JUMPED}")
    e.put("    break")
    e.put("continue")


def _loop_check(e: _Emitter) -> None:
    """Before control goes back through the dispatch to a block not after the jump (a loop, a return,
    a computed jump): the call stops when the budget is spent or a write went into the code. Forward
    jumps go unchecked: their blocks start at ever higher addresses, so code without a backward jump
    ends by itself, and its cycles and writes are looked at once, when it does."""
    e.put("if (cycles >= budget) | (bad != 0):")
    e.put(f"    status = {STOPPED}")  # which of the two: once, after the loop (fewer branches to compile)
    e.put("    break")


def _go(e: _Emitter, address: int, blocks: dict[int, int], return_pc: int) -> None:
    if address == return_pc:
        e.put(f"t = {address}")
        _jump_to(e)
        return
    if address in e.inlined and len(e.indent) < MAX_INDENT:  # its only way in is from here: its code
        e.emit_block(address)  # follows, no trip through the dispatch
        return
    e.chained.add(address)
    if address <= e.pc:
        _loop_check(e)
    e.put(f"blk = {blocks[address]}")
    e.put("continue")


def _taken_cycles(pc: int, length: int, offset: int) -> int:
    """What a taken branch adds: +1, and +1 more into another page than the next instruction's."""
    following = (pc + length) & WORD
    target = branch_target(pc, offset, length)
    return BRANCH_TAKEN_CYCLES + (BRANCH_PAGE_CYCLES if (following & PAGE_MASK) != (target & PAGE_MASK) else 0)


def _branch(e: _Emitter, condition: str, pc: int, length: int, offset: int, blocks, return_pc: int) -> None:
    following = (pc + length) & WORD
    target = branch_target(pc, offset, length)
    extra = _taken_cycles(pc, length, offset)
    e.put(f"if {condition}:")
    e.indent += "    "
    e.put(f"cycles += {extra}")
    _go(e, target, blocks, return_pc)
    e.indent = e.indent[:-4]
    e.pc = pc  # (the taken side's inlined code moved it on)
    _go(e, following, blocks, return_pc)


MAX_INDENT = 160  # spaces: nested inlined blocks stop here (Python's tokenizer allows 100 levels)
_Z_BIT = "(((zv - 1) >> 8) & 2)"  # P's Z bit from zv (0..255): 2 when zv == 0, without a branch
BRANCH_TESTS = {0x80: ("nv >= 128", "nv < 128"), 0x40: ("fv", "fv == 0"), 0x01: ("fc", "fc == 0"),
                0x02: ("zv == 0", "zv != 0")}
BRANCH_VALUES = {0x80: "nv >> 7", 0x40: "fv", 0x01: "fc", 0x02: "((zv - 1) >> 8) & 1"}  # the flag as 0 or 1 (nv, zv 0..255)


# One function per kind of instruction, each emitting it and returning True when it ends the block
# (control went elsewhere); `_instruction` picks it by mnemonic (HANDLERS, built below from the tables).

def _emit_stop(e: _Emitter, pc: int, op: Op | None, blocks: dict[int, int], return_pc: int) -> bool:
    e.put(f"status = {FALLBACK_STOP}")
    e.put("break")
    return True


def _condition(e: _Emitter, pc: int, op: Op, value: bool = False) -> str:
    """When the branch at pc is taken (BBRn / BBSn zp, offset: the 65C02's bit branches): a test for an
    `if`, or with `value` an expression that is 1 when taken, else 0, computed without a branch (an
    if-converted branch's choice: `x = 1 if test else 0` is two more basic blocks for numba to compile)."""
    if op.mnemonic == "BRA":
        return "1" if value else "True"
    if op.mode == "zpr":
        test = f"({_read(e.read((pc + 1) & WORD))} >> {int(op.mnemonic[3])}) & 1"
        if value:
            return test if op.mnemonic[2] == "S" else f"{test} ^ 1"
        return f"{test} == {1 if op.mnemonic[2] == 'S' else 0}"
    flag, wanted = BRANCH_CONDITIONS[e.read(pc)]
    if value:
        return BRANCH_VALUES[flag] if wanted else f"({BRANCH_VALUES[flag]}) ^ 1"
    return BRANCH_TESTS[flag][0 if wanted else 1]


def _emit_branch(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    """A branch (BXX offset, BBRn / BBSn zp, offset): a jump, or both ways run when it converts."""
    e.put(f"cycles += {op.cycles}")
    region = e.regions.get(pc)
    if region is not None:
        _emit_converted(e, region)
        if region.join == ifconvert.RTS_JOIN:
            return _emit_rts(e, pc, tables_for(e.cpu)[RTS_OPCODE], blocks, return_pc)
        e.pc = pc
        _go(e, region.join, blocks, return_pc)
        return True
    length = MODE_LENGTH[op.mode]
    _branch(e, _condition(e, pc, op), pc, length, e.read((pc + length - 1) & WORD), blocks, return_pc)
    return True


# ---- if-conversion (retro.cpu.ifconvert finds the regions) -----------------------------------------------
# Both ways of a converted branch run, one after the other: the way not taken first, then, from the state
# saved before it, the way taken; then each variable either way changed takes the taken way's value or
# the other's by selection (no jump: LLVM's select). Inside a way nothing is seen outside but its
# variables and its stores, which are conditional on the way being the one taken (`_Emitter.guard`),
# so the way run in vain leaves memory as it was. Temporaries (t, u, v, ea, w, pg) are dead between
# instructions; S, the write log and `bad` no way changes (the classifier keeps their writers out).

RTS_OPCODE = 0x60
CONVERTED_NOTE = "if-converted: both ways run, the taken one's state kept"  # (the generated code's comment)
CONVERTED_STATE = ("a", "x", "y", "nv", "zv", "fv", "fc", "fd", "fi", "cycles")
TEMPORARIES = {"t", "u", "v", "ea", "w", "pg"}
_ASSIGNED = re.compile(r"^\s*([a-z]\w*(?:\s*,\s*[a-z]\w*)*)\s*[-+|&^]?=(?!=)")
_REGION_NAME = re.compile(r"^[csfge]\d+")  # the converted code's own variables: c7, s7_a, f7_a, g7t, e7t


def _assigned(lines: list[str]) -> set[str]:
    """The state variables these generated lines assign (an unknown name is a translator bug)."""
    names = set()
    for line in lines:
        match = _ASSIGNED.match(line)
        if match:
            names.update(name.strip() for name in match.group(1).split(","))
    unknown = names - set(CONVERTED_STATE) - TEMPORARIES - {n for n in names if _REGION_NAME.match(n)}
    if unknown:  # pragma: no cover - a way holding an instruction the classifier should have kept out
        raise AssertionError(f"a converted way assigns {sorted(unknown)}")
    return names & set(CONVERTED_STATE)


def _way_kind(e: _Emitter, pc: int, op: Op) -> tuple[int, bool] | None:
    """ifconvert's classifier: (cost, stores) of an instruction a converted way may hold, else None
    (control flow, the stack, a store to a computed address: logged, checked against the code)."""
    name = op.mnemonic
    if name in STOPS or name in STACK_MNEMONICS or name in ("JMP", "JSR", "RTS") or op.mode in ("rel", "zpr"):
        return None
    stores = (name in STORES or name in TEST_BITS
              or (name in (*SHIFTS, *COMBINED) and op.mode != "acc")) and not (e.cmos and op.kind == RESERVED)
    if stores and op.mode not in ("zpg", "abs"):
        return None
    helper = name in HELPER_MNEMONICS and (name == "ARR" or (not e.binary and (e.decimal or e.cmos)))
    return (HELPER_COST if helper else 1), stores


HELPER_MNEMONICS = {"ADC", "SBC", "USBC", "RRA", "ISC", "ARR"}  # a call of a compiled_ops helper unless binary
HELPER_COST = 3


def _emit_way(e: _Emitter, way: ifconvert.Way, guard: str | None) -> None:
    outer, e.guard = e.guard, guard
    for pc, region, _, _ in way.items:
        op = e.instructions[pc]
        e.pc = pc
        e.put(f"# ${pc:04X} {op.mnemonic}")
        if region is not None:
            e.put(f"cycles += {op.cycles}")
            _emit_converted(e, region)
        elif op.mnemonic == "BRA":
            e.put(f"cycles += {op.cycles + _taken_cycles(pc, 2, e.read((pc + 1) & WORD))}")
        elif op.mnemonic == "JMP":
            e.put(f"cycles += {op.cycles}")
        else:
            _instruction(e, pc, op, {}, -1)
    e.guard = outer


def _emit_converted(e: _Emitter, region: ifconvert.Region) -> None:
    """The branch at region.pc without a jump (its base cycles counted already): the state after it is
    the taken way's or the other's, as the branch goes, at region.join."""
    k = e.converted
    op = e.instructions[region.pc]
    length = MODE_LENGTH[op.mode]
    e.put(f"# ${region.pc:04X} {op.mnemonic} {CONVERTED_NOTE}")
    e.put(f"c{k} = {_condition(e, region.pc, op, value=True)}")
    _emit_ways(e, region, _taken_cycles(region.pc, length, e.read((region.pc + length - 1) & WORD)))
    if region.then is not None:  # the ways' own branches, one chosen above (e{k}): their two addresses
        e.put(f"# ${region.then.pc:04X} and ${region.exits[1]:04X}: the way taken's branch, {CONVERTED_NOTE}")
        _emit_ways(e, region.then, 0, f"e{k}")


def _exit_branch(e: _Emitter, pc: int, towards: int, into: str) -> None:
    """A way's own last branch (a merged region's exit): its cycles, and `into` = 1 when it goes to `towards`."""
    op = e.instructions[pc]
    length = MODE_LENGTH[op.mode]
    offset = e.read((pc + length - 1) & WORD)
    e.put(f"# ${pc:04X} {op.mnemonic}")
    e.put(f"cycles += {op.cycles}")
    e.put(f"u = {_condition(e, pc, op, value=True)}")
    e.put(f"cycles += {_taken_cycles(pc, length, offset)} * u")
    e.put(f"{into} = u" if branch_target(pc, offset, length) == towards else f"{into} = u ^ 1")


def _emit_ways(e: _Emitter, region: ifconvert.Region, extra: int, taken: str | None = None) -> None:
    """Both ways of a region, then the selection by `taken` (the branch's own test, c{k}, when None;
    `extra`: what the taken way adds for the branch)."""
    k = e.converted
    e.converted += 1
    taken = taken or f"c{k}"
    towards = 0
    if region.exits:  # where the taken way's own branch goes when taken: where e{k} = 1 leads
        length = MODE_LENGTH[e.instructions[region.exits[0]].mode]
        towards = branch_target(region.exits[0], e.read((region.exits[0] + length - 1) & WORD), length)
    guard_taken = guard_fall = None
    if region.stores:
        guard_taken, guard_fall = f"g{k}t", f"g{k}f"
        within = "" if e.guard is None else f"{e.guard} & "
        e.put(f"{guard_taken} = {within}{taken}")
        e.put(f"{guard_fall} = {within}({taken} ^ 1)")
    start = len(e.lines)
    _emit_way(e, region.fall, guard_fall)
    if region.exits:
        _exit_branch(e, region.exits[1], towards, f"e{k}f")
    fall_writes = [name for name in CONVERTED_STATE if name in _assigned(e.lines[start:])]
    e.lines[start:start] = [f"{e.indent}s{k}_{name} = {name}" for name in fall_writes]
    middle = len(e.lines)
    if extra:
        e.put(f"cycles += {extra}")
    _emit_way(e, region.taken, guard_taken)
    if region.exits:
        _exit_branch(e, region.exits[0], towards, f"e{k}t")
    changed = [name for name in CONVERTED_STATE if name in fall_writes or name in _assigned(e.lines[middle:])]
    e.lines[middle:middle] = ([f"{e.indent}f{k}_{name} = {name}" for name in changed]
                              + [f"{e.indent}{name} = s{k}_{name}" for name in fall_writes])
    for name in changed:
        e.put(f"{name} = choose({taken}, {name}, f{k}_{name})")
    if region.exits:
        e.put(f"e{k} = choose({taken}, e{k}t, e{k}f)")


def _emit_jmp(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    e.put(f"cycles += {op.cycles}")
    _, pointer = e.operand_bytes(pc, 3)
    if op.mode == "abs":
        if isinstance(pointer, int):
            _go(e, pointer, blocks, return_pc)
        else:  # a patched target: through the dispatch (a target no block starts at falls back)
            e.put(f"t = {pointer}")
            _jump_to(e)
        return True
    if isinstance(pointer, str):
        e.put(f"w = {pointer}")
        pointer = "w"
    if op.mode == "iax":
        e.put(f"t = ({pointer} + x) & 65535")
        e.put(f"t = {_read('t')} | ({_read('(t + 1) & 65535')} << 8)")
    elif e.cmos:
        following = (pointer + 1) & WORD if isinstance(pointer, int) else f"({pointer} + 1) & 65535"
        e.put(f"t = {_read(pointer)} | ({_read(following)} << 8)")
    else:  # NMOS: the high byte from the start of the pointer's page when the pointer ends one
        following = ((pointer & PAGE_MASK) | ((pointer + 1) & BYTE) if isinstance(pointer, int)
                     else f"({pointer} & {PAGE_MASK}) | (({pointer} + 1) & 255)")
        e.put(f"t = {_read(pointer)} | ({_read(following)} << 8)")
    _jump_to(e)
    return True


def _emit_jsr(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    back = (pc + 2) & WORD
    e.push(str(back >> 8))
    e.push(str(back & BYTE))
    e.put(f"cycles += {op.cycles}")
    _go(e, e.read((pc + 1) & WORD) | e.read((pc + 2) & WORD) << 8, blocks, return_pc)
    return True


def _emit_rts(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    """An RTS: the call's return when `direct`, else its return address pulled and gone to, here or,
    in code of RETURN_ARM_FROM RTSs or more, in the dispatch's one return arm (`_emit_return_arm`)."""
    e.put(f"cycles += {op.cycles}")
    e.put("if direct:  # the caller's own return address, unchanged on the stack: the call has returned")
    e.put("    break")
    if e.return_arm is not None:
        e.put(f"blk = {e.return_arm}  # the return arm")
        e.put("continue")
        return True
    _emit_return(e)
    return True


def _emit_return(e: _Emitter) -> None:
    e.pull("t")
    e.pull("u")
    e.put("t = ((u << 8 | t) + 1) & 65535")
    _jump_to(e)


RETURN_ARM_FROM = 6  # RTSs from which they share the dispatch's return arm (aabb_sprite has 27)


def _emit_return_arm(e: _Emitter) -> None:
    """The dispatch's arm after every block's: an RTS's return address pulled and gone to. Shared by all
    of a routine's RTSs when it has many: written out at each of aabb_sprite's 27 it was most of its
    compile time (9.5 -> 3.7 CPU-s, side by side); an arm of the dispatch costs a call about 1 ns more
    even when never taken (mul8: 5.2 -> 6.4 ns; aabb_sprite, 14-32 ns a call: within the noise), so
    code with few RTSs keeps them written out."""
    e.indent = " " * 12
    e.put(f"elif blk == {e.return_arm}:  # RTS: the return address from the stack")
    e.indent = " " * 16
    _emit_return(e)


def _store_to(e: _Emitter, pc: int, address: str | int, value: str) -> None:
    if isinstance(address, int):
        e.write_fixed(pc, address, value)
    else:
        e.write_at(address, value)


def _emit_store(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    address, _ = e.address(pc, op)
    _store_to(e, pc, address, STORES[op.mnemonic])
    e.put(f"cycles += {op.cycles}")
    return False


def _emit_read(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    if op.mode == "imp":  # the undocumented one-byte NOPs
        e.put(f"cycles += {op.cycles}")
    elif e.cmos and op.mnemonic == "BIT" and op.mode == "imm":  # 65C02 BIT #imm: Z only
        e.put(f"zv = a & {e.immediate(pc)}")
        e.put(f"cycles += {op.cycles}")
    else:
        value, crossed = e.operand(pc, op)
        e.operate(op.mnemonic, value)
        e.cycles(op.cycles, crossed, op.page_penalty)
    return False


def _emit_modify(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    """A shift or step of A or memory, and the undocumented ones that then read the result (SLO...)."""
    shift, then = COMBINED.get(op.mnemonic, (op.mnemonic, None))
    if op.mode == "acc":
        e.shift(shift, "a", "a")
        e.put(f"cycles += {op.cycles}")
        return False
    address, crossed = e.address(pc, op)
    if not isinstance(address, int) and address != "ea":
        e.put(f"ea = {address}")
        address = "ea"
    e.put(f"v = {_read(address)}")
    e.shift(shift, "v", "v")
    _store_to(e, pc, address, "v")
    if then is not None:
        e.operate(then, "v")
    e.cycles(op.cycles, crossed, op.page_penalty)  # the 65C02's shifts abs,X: +1 across a page
    return False


def _emit_test_bits(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
    """TSB, TRB, RMBn, SMBn (65C02)."""
    name = op.mnemonic
    address, _ = e.address(pc, op)
    e.put(f"v = {_read(address)}")
    if name in ("TSB", "TRB"):
        e.put("zv = a & v")
        result = "(v | a)" if name == "TSB" else "(v & (a ^ 255))"
    else:
        mask = 1 << int(name[3])
        result = f"(v | {mask})" if name[0] == "S" else f"(v & {BYTE ^ mask})"
    _store_to(e, pc, address, result)
    e.put(f"cycles += {op.cycles}")
    return False


def _implied(emit: Callable[[_Emitter, str], None]):
    """A one-byte instruction's handler: its effect (`emit(e, mnemonic)`), then its cycles."""
    def handler(e: _Emitter, pc: int, op: Op, blocks: dict[int, int], return_pc: int) -> bool:
        emit(e, op.mnemonic)
        e.put(f"cycles += {op.cycles}")
        return False
    return handler


def _set_flag(e: _Emitter, name: str) -> None:
    flag, value = FLAG_SETTERS[name]
    e.put(f"{flag} = {value}")


def _transfer(e: _Emitter, name: str) -> None:
    target, source = TRANSFERS[name]
    e.put(f"{target} = {source}")
    e.nz(target)


def _step(e: _Emitter, name: str) -> None:
    register, step = STEPS[name]
    e.put(f"{register} = ({register} + {step}) & 255")
    e.nz(register)


def _pull_register(e: _Emitter, name: str) -> None:
    register = name[2].lower()
    e.pull(register)
    e.nz(register)


def _pull_p(e: _Emitter, name: str) -> None:
    e.pull("t")
    e.unpack_p("t")


def _mnemonics(mode: str) -> set[str]:
    return {op.mnemonic for table in (OPCODE_TABLE, OPCODE_TABLE_65C02) for op in table.values() if op.mode == mode}


HANDLERS: dict[str, Callable[..., bool]] = {
    **{name: _emit_stop for name in STOPS},
    **{name: _emit_branch for name in _mnemonics("rel")},
    **{name: _emit_branch for name in _mnemonics("zpr")},
    "JMP": _emit_jmp, "JSR": _emit_jsr, "RTS": _emit_rts,
    **{name: _emit_store for name in STORES},
    **{name: _emit_read for name in READS},
    **{name: _emit_modify for name in (*SHIFTS, *COMBINED)},
    **{name: _emit_test_bits for name in TEST_BITS},
    **{name: _implied(_set_flag) for name in FLAG_SETTERS},
    **{name: _implied(_transfer) for name in TRANSFERS},
    **{name: _implied(_step) for name in STEPS},
    "TXS": _implied(lambda e, name: e.put("sp = x")),
    **{name: _implied(lambda e, name: e.push(name[2].lower())) for name in ("PHA", "PHX", "PHY")},
    "PHP": _implied(lambda e, name: e.push(e.pack_p())),
    **{name: _implied(_pull_register) for name in ("PLA", "PLX", "PLY")},
    "PLP": _implied(_pull_p),
}


def _instruction(e: _Emitter, pc: int, op: Op | None, blocks: dict[int, int], return_pc: int) -> bool:
    """Emit one instruction; True when it ends the block (control went elsewhere)."""
    if op is None:
        return _emit_stop(e, pc, op, blocks, return_pc)
    if e.cmos and op.kind == RESERVED:  # the 65C02's NOPs of every length
        e.put(f"cycles += {op.cycles}")
        return False
    handler = HANDLERS.get(op.mnemonic)
    if handler is None:  # pragma: no cover - a new table row needs its translation here
        raise AssertionError(f"no translation for {op.mnemonic} ({op.mode})")
    return handler(e, pc, op, blocks, return_pc)


def _exits(start: int, instructions: dict, leaders: set[int], return_pc: int, read,
           regions: dict | None = None) -> tuple[list[int], list[int]]:
    """(blocks a block goes to by its code, blocks reached later by an RTS: the addresses after its JSRs);
    a converted branch (`regions`) goes only to its join."""
    pc = start
    while True:
        op = instructions[pc]
        if regions and pc in regions:
            join = regions[pc].join
            return ([join] if join not in (ifconvert.RTS_JOIN, return_pc) else []), []
        targets, falls = _successors(pc, op, read)
        if op is not None and op.mnemonic == "JSR":
            return [t for t in targets[:1] if t != return_pc], targets[1:]  # a JSR to the return address starts no block
        following = (pc + MODE_LENGTH[op.mode]) & WORD if op is not None else pc
        if op is None or not falls or op.mode in ("rel", "zpr") or following in leaders or following == return_pc:
            return [t for t in targets + ([following] if falls else []) if t != return_pc], []
        pc = following


def _inlined(starts: list[int], instructions: dict, entry: int, return_pc: int, read,
             live: frozenset[int] = frozenset(), regions: dict | None = None) -> tuple[set[int], set[int]]:
    """(blocks whose code goes inside their one predecessor's: a block reached by one jump (or fall) from
    a block before it, never by a return, a patched JMP (`live`: through the dispatch) or as the entry;
    forward only, so no loop is unrolled, blocks control reaches from the entry: not those only inside
    converted branches' ways, `regions`)."""
    leaders = set(starts)
    into: dict[int, list[int]] = {start: [] for start in starts}
    returned_to = {_successors(pc, instructions[pc], read)[0][0] for pc in live
                   if instructions[pc].mnemonic == "JMP" and instructions[pc].mode == "abs"}
    reached, pending = {entry}, [entry]
    while pending:
        start = pending.pop()
        goes, comes_back = _exits(start, instructions, leaders, return_pc, read, regions)
        for target in goes:
            into[target].append(start)
        returned_to.update(comes_back)
        for target in (*goes, *comes_back):
            if target in into and target not in reached:
                reached.add(target)
                pending.append(target)
    inlined = {start for start, sources in into.items()
               if start != entry and start not in returned_to and len(sources) == 1 and sources[0] < start}
    return inlined, reached


def decimal_free(instructions: Iterable[Op | None], sets: tuple) -> bool:
    """Whether D stays as it was on entry through the code (no SED, no PLP) and no case column sets
    P: then a call entered with D clear runs in binary mode throughout, and ADC and SBC are translated
    for binary mode only (a call entered with D set falls back: FALLBACK_DECIMAL)."""
    return (not any(op is not None and op.mnemonic in ("SED", "PLP") for op in instructions)
            and not any(what == SET_P or (what == SET_FLAG and shift == FLAG_D) for _, shift, what in sets))


def _placing(places: tuple, sets: tuple) -> str:
    """The lines that put a lane's inputs in place: `places` rows (column, shift, address) put the byte
    (column >> shift) & 255 at address; `sets` rows (column, shift, what) OR that byte into A, X, Y or P
    (SET_A..SET_P), or set P's bit `shift` when the column is not 0 (SET_FLAG)."""
    lines = [f"mem[{address}] = (cols[{column}][lane] >> {shift}) & 255" for column, shift, address in places]
    for column, shift, what in sets:
        if what == SET_FLAG:
            lines.append(f"p |= {shift} if cols[{column}][lane] != 0 else 0")
        else:
            lines.append(f"{SET_REGISTERS[what]} |= (cols[{column}][lane] >> {shift}) & 255")
    return "\n".join(" " * 8 + line for line in lines)


STACK_MNEMONICS = {"PHA", "PHP", "PHX", "PHY", "PLA", "PLP", "PLX", "PLY", "JSR", "TXS", "BRK", "RTI"}


def returns_directly(instructions: Iterable[Op | None], computed_writes: bool, fixed_writes: Iterable[int],
                     placed: Iterable[int], lanes: tuple[int, ...] | None) -> bool:
    """Whether every RTS the code runs is the call's own return: no instruction moves S but RTS, and
    nothing writes page 1 (no push, no store to a computed address, no fixed store or placed input
    there): S at an RTS is S at entry and the return address is the image's, read once per run (the
    generated `direct`) instead of from memory on every call."""
    page = range(STACK_PAGE, 2 * STACK_PAGE)
    return (lanes is not None and not computed_writes
            and not any(op is not None and op.mnemonic in STACK_MNEMONICS for op in instructions)
            and not any(address in page for address in (*fixed_writes, *placed, *lanes)))


def _out_lines(results: tuple[tuple[str, str], ...]) -> str:
    """The lines that write a call's results into `out`: one row per (name, expression) of `results`
    (an expression of a, x, y, p: P as pushed, and mem[address]), then cycles and status."""
    lines = [f"p = (nv & 128) | (fv << 6) | 32 | (fd << 3) | (fi << 2) | {_Z_BIT} | fc"]
    lines += [f"out[{k}, lane] = {expression}" for k, (_, expression) in enumerate(results)]
    lines += [f"out[{len(results)}, lane] = cycles", f"out[{len(results) + 1}, lane] = status"]
    return "\n".join(" " * 8 + line for line in lines)


_CONSTANT_CYCLES = re.compile(r"^(\s*)cycles \+= (\d+)$")
_CONTROL = re.compile(r"^\s*(if|elif|else|while|for|break|continue)\b")


def merge_cycles(lines: list[str]) -> list[str]:
    """The generated lines with each straight run's constant `cycles += n` summed into one line at its
    end: a run is lines of one indentation without control flow, ended by an `if`, `break`, `continue`
    ..., another indentation, or a line that reads or sets `cycles` any other way (a page penalty, an
    if-converted way's saved or chosen count). Nothing in between reads the count, so every exit sees
    the same total; numba compiles a third fewer lines (aabb_sprite: 290 such lines), LLVM folded them
    anyway."""
    merged: list[str] = []
    pending, indent = 0, ""
    for line in lines:
        if line.lstrip().startswith("#"):
            merged.append(line)
            continue
        constant = _CONSTANT_CYCLES.match(line)
        here = line[:len(line) - len(line.lstrip())]
        if pending and (here != indent or _CONTROL.match(line) or ("cycles" in line and not constant)):
            merged.append(f"{indent}cycles += {pending}")
            pending = 0
        if constant:
            pending, indent = pending + int(constant.group(2)), here
        else:
            merged.append(line)
    if pending:
        merged.append(f"{indent}cycles += {pending}")
    return merged


LINES_LIMIT = 64  # known lane or output addresses from which they are looped over, not written one line each


def _lane_lines(lanes: tuple[int, ...] | None, outputs: tuple[int, ...] | None) -> tuple[str, str]:
    """The lines that put the per-lane bytes in place and copy the output bytes out: one line per
    address when the addresses are known (an empty loop costs more than aabb8's whole call), else loops
    over the `lane_addr` and `out_addr` a run passes (`run` holds them to the known ones); loops too
    above LINES_LIMIT addresses: numba's and LLVM's passes took over 200 s on hundreds of such lines."""
    if lanes is None or len(lanes) > LINES_LIMIT:
        placing = "        for k in range(lane_addr.shape[0]):\n            mem[lane_addr[k]] = lane_bytes[k, lane]"
    else:
        placing = "\n".join(f"        mem[{address}] = lane_bytes[{k}, lane]" for k, address in enumerate(lanes))
    if outputs is None or len(outputs) > LINES_LIMIT:
        copying = "        for k in range(out_addr.shape[0]):\n            out_bytes[k, lane] = mem[out_addr[k]]"
    else:
        copying = "\n".join(f"        out_bytes[{k}, lane] = mem[{address}]" for k, address in enumerate(outputs))
    return placing, copying


def translate(read: Callable[[int], int], entry: int, cpu: str, return_pc: int,
              inputs_at: Iterable[int] = (), places: tuple = (), sets: tuple = (),
              lanes: tuple[int, ...] | None = None, outputs: tuple[int, ...] | None = None,
              decimal_entry: bool = False, results: tuple[tuple[str, str], ...] = REGISTERS_OUT) -> Translation:
    """The routine at entry (its bytes as `read` gives them: the memory every call starts from) as
    the source of one function (see the module docstring; `places` and `sets`: where the case
    columns go, `_placing`; `lanes` and `outputs`: the `lane_addr` and `out_addr` every run will
    pass, when known, `_lane_lines`; `decimal_entry`: calls may start with D set, so ADC and SBC
    keep their decimal mode; `results`: what the function writes per call, `_out_lines`);
    Untranslatable when it certainly modifies its own code."""
    starts, instructions = find_blocks(read, entry, cpu, return_pc)
    code_bytes = frozenset((pc + k) & WORD for pc, op in instructions.items()
                           for k in range(MODE_LENGTH[op.mode] if op is not None else 1))
    for address in inputs_at:
        if address in code_bytes:
            raise Untranslatable(f"self-modifying code: an input is placed at ${address:04X}, a byte of the "
                                 f"routine's code")
    live = frozenset(live_operands(instructions, read))
    live_bytes = frozenset((pc + k) & WORD for pc in live for k in range(1, MODE_LENGTH[instructions[pc].mode]))

    def fixed_read(address: int) -> int:  # the code generation never folds a byte that may be patched
        if address in live_bytes:
            raise AssertionError(f"${address:04X} is a live operand byte")  # pragma: no cover
        return read(address)

    e = _Emitter(cpu, code_bytes - live_bytes, fixed_read, live)
    e.binary = (e.decimal or e.cmos) and not decimal_entry and decimal_free(instructions.values(), sets)
    e.instructions = instructions
    # a converted way never holds a live instruction (its patched store or JMP target is not the image's)
    fixed = {pc: (None if pc in live else op) for pc, op in instructions.items()}
    e.regions = ifconvert.plan(fixed, set(starts), fixed_read, return_pc, lambda pc, op: _way_kind(e, pc, op))
    inlined, reached = _inlined(starts, instructions, entry, return_pc, read, live, e.regions)
    dispatched = [start for start in starts if start in reached and start not in inlined]
    blocks = {start: number for number, start in enumerate(dispatched + [s for s in starts if s not in dispatched])}
    leaders = set(starts)
    e.inlined = inlined
    if sum(op is not None and op.mnemonic == "RTS" for op in instructions.values()) >= RETURN_ARM_FROM:
        e.return_arm = len(blocks)

    def emit_block(start: int) -> None:
        pc = start
        e.put(f"# block ${start:04X}")
        while True:
            op = instructions[pc]
            e.put(f"# ${pc:04X} {op.mnemonic if op is not None else 'not translated'}")
            e.pc = pc
            if _instruction(e, pc, op, blocks, return_pc):
                break
            pc = (pc + MODE_LENGTH[op.mode]) & WORD
            if pc in leaders or pc == return_pc:  # falls into the next block
                _go(e, pc, blocks, return_pc)
                break
    e.emit_block = emit_block
    pending, done = list(dispatched), set()
    while pending:  # the dispatched blocks, then any block nested too deep to be inlined where it was met
        start = pending.pop(0)
        done.add(start)
        e.indent = " " * 12
        e.put(f"{'if' if not e.lines else 'elif'} blk == {blocks[start]}:  # ${start:04X}")
        e.indent = " " * 16
        emit_block(start)
        pending += sorted(e.chained - done - set(pending))
    if e.return_arm is not None:
        _emit_return_arm(e)
    e.indent = " " * 12
    e.put("else:  # a block number the dispatch does not run (inlined code): never spin, leave the call")
    e.put(f"    status = {FALLBACK_JUMP}")
    e.put("    break")
    name = "run_calls"
    restore = "\n".join(f"        mem[{address}] = image[{address}]" for address in sorted(e.fixed_writes))
    placing_lanes, copying = _lane_lines(lanes, outputs)
    source = _FUNCTION.format(name=name, entry_block=blocks[entry], body="\n".join(merge_cycles(e.lines)),
                              budget_status=BUDGET, bad="fd * 2" if e.binary and e.adds else "0",
                              fallback_decimal=FALLBACK_DECIMAL, stopped=STOPPED, jumped=JUMPED, returned=RETURNED,
                              fallback_jump=FALLBACK_JUMP,
                              lane_placing=placing_lanes, out_copying=copying,
                              fallback_write=FALLBACK_WRITE, restore=restore, placing=_placing(places, sets),
                              out_rows=_out_lines(results),
                              direct=returns_directly(instructions.values(), e.computed_writes, e.fixed_writes,
                                                      (address for _, _, address in places), lanes))
    return Translation(source, name, blocks, code_bytes, tuple(sorted(e.fixed_writes)), len(instructions),
                       tuple(address for _, _, address in places), lanes, outputs, tuple(results), live_bytes)


# The function around the blocks: one call per lane, inputs placed from the case columns (`cols`, a
# tuple: `placing`, the lines `_placing` makes), results written straight into the caller's arrays,
# memory restored. `lane_bytes`: bytes per lane made beforehand (table inputs), one row per `lane_addr`.
# `base`: A, X, Y, P before the inputs. `out` rows: A, X, Y, P, cycles, status.
_FUNCTION = '''
LOG_MASK = 65535


def {name}(mem, image, log, code_map, addr_block, cols, lane_addr, lane_bytes, base, start_sp, budget, return_pc,
           return_sp, out_addr, out, out_bytes):
    a0 = base[0]  # read once: in the loop the compiler cannot tell that `out` does not overwrite them
    x0 = base[1]
    y0 = base[2]
    p0 = base[3]
    low = image[256 + ((start_sp + 1) & 255)]  # the return address every call finds on the stack
    high = image[256 + ((start_sp + 2) & 255)]
    direct = {direct} and ((high << 8 | low) + 1) & 65535 == return_pc and (start_sp + 2) & 255 == return_sp
    for lane in range(out.shape[1]):
{lane_placing}
        a = a0
        x = x0
        y = y0
        p = p0
{placing}
        p = (p | 32) & 239
        nv = p & 128
        fv = (p >> 6) & 1
        fd = (p >> 3) & 1
        fi = (p >> 2) & 1
        zv = (p & 2) ^ 2
        fc = p & 1
        bad = {bad}  # 1: a write into the code; 2: D set on entry to binary-only code
        sp = np.int64(start_sp)
        cycles = np.int64(0)
        status = 0
        nlog = 0
        blk = {entry_block}
        t = np.int64(0)
        u = np.int64(0)
        v = np.int64(0)
        ea = np.int64(0)
        w = np.int64(0)
        pg = np.int64(0)
        if cycles >= budget or bad:
            status = {fallback_decimal} if bad else {budget_status}
        while status == 0:
{body}
        if status == {jumped}:  # the caller's return, else no block there, else the loop check (`_jump_to`)
            if t == return_pc and sp == return_sp:
                status = {returned}
            elif blk < 0:
                status = {fallback_jump}
            else:
                status = {stopped}
        if status == {stopped}:
            status = {fallback_write} if bad else {budget_status}
        if status == 0 and bad:
            status = {fallback_write}
        if status == 0 and cycles > budget:
            status = {budget_status}
{out_rows}
{out_copying}
        if nlog > LOG_MASK + 1:  # more writes than the log holds: the whole memory (a loop: `mem[:] = image`
            for k in range(mem.shape[0]):  # makes numba compile its shape-mismatch message, 1.6 CPU-s a process)
                mem[k] = image[k]
        else:
            for k in range(nlog):
                t = log[k]
                mem[t] = image[t]
{restore}
'''
