"""6502 cycle timing kept in the project, independent of py65's tables and of retro.cpu.opcodes.

Sources: the MOS MCS6500 Microcomputer Family Programming Manual (1976), appendix "Instruction
timing", for the documented opcodes, and 64doc (J. Ahola, M. Korpi et al., "6502 instructions and
their cycle counts") for the stable undocumented NMOS opcodes. Rules:
- every opcode has a base cycle count;
- reads in the absolute,X / absolute,Y / (indirect),Y modes take one more cycle when the indexed
  address lies in another page than the base address (stores and read-modify-writes always take
  the longer count, so they have no penalty);
- a relative branch takes one more cycle when taken, and one more again when the target lies in
  another page than the instruction that follows the branch.

The WDC 65C02 has its own table (`OPCODES_65C02`, from WDC's "W65C02S 8-bit Microprocessor" data sheet,
table 5-7, by families of the NMOS documented table and the changes the data sheet lists) and rules:
ADC and SBC take one cycle more with D set; BRA is always taken; BBR/BBS take 5 cycles, +1 when
taken and +1 more when the target lies in another page than the next instruction; shifts and
rotates abs,X have the page penalty (6 or 7 cycles). `timing_table(cpu)` gives a CPU's table.

`model_cycles(trace)` sums these over an executed path, deriving every penalty from addresses
(the operand bytes, the index registers before the instruction, the next PC), never from the
emulator's own cycle bookkeeping. `step_model(cpu)` is the same table and rules as a run loop reads
them (per opcode a base count and a rule, a function, for what it adds): Machine's recording loop
sums the model as it runs (`MPU6510.run_recorded`), with no trace to walk again.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

PAGE_MASK = 0xFF00
BRANCH_TAKEN_CYCLES = 1
BRANCH_PAGE_CYCLES = 1
PAGE_CROSS_CYCLES = 1

# Operand bytes per addressing mode.
MODE_LENGTH = {"imp": 1, "acc": 1, "imm": 2, "zpg": 2, "zpx": 2, "zpy": 2, "inx": 2, "iny": 2, "rel": 2,
               "abs": 3, "abx": 3, "aby": 3, "ind": 3, "zpi": 2, "iax": 3, "zpr": 3}
CMOS_DECIMAL_CYCLES = 1  # 65C02: ADC/SBC with D set
WDC_65C02 = "65c02"


@dataclass(frozen=True)
class OpTiming:
    mnemonic: str
    mode: str
    cycles: int
    page_penalty: bool  # +1 when the indexed address crosses a page (reads only)

    @property
    def length(self) -> int:
        return MODE_LENGTH[self.mode]


def _putter(table: dict[int, OpTiming]):
    def put(mnemonic: str, rows: Iterable[tuple[int, str, int]], penalised: tuple[str, ...] = ()) -> None:
        for opcode, mode, cycles in rows:
            if opcode in table:
                raise AssertionError(f"opcode ${opcode:02X} listed twice")
            table[opcode] = OpTiming(mnemonic, mode, cycles, mode in penalised)
    return put


READ_MODES = ("abx", "aby", "iny")


def _documented() -> dict[int, OpTiming]:
    """The 151 opcodes of the MOS programming manual."""
    table: dict[int, OpTiming] = {}
    put = _putter(table)
    read_modes = READ_MODES
    # The eight-mode ALU/load group: imm, zp, zp,X, abs, abs,X, abs,Y, (zp,X), (zp),Y.
    group = (("imm", 2), ("zpg", 3), ("zpx", 4), ("abs", 4), ("abx", 4), ("aby", 4), ("inx", 6), ("iny", 5))
    low = {"imm": 0x09, "zpg": 0x05, "zpx": 0x15, "abs": 0x0D, "abx": 0x1D, "aby": 0x19, "inx": 0x01, "iny": 0x11}
    for mnemonic, base in (("ORA", 0x00), ("AND", 0x20), ("EOR", 0x40), ("ADC", 0x60),
                           ("LDA", 0xA0), ("CMP", 0xC0), ("SBC", 0xE0)):
        put(mnemonic, [(base + low[m], m, c) for m, c in group], read_modes)
    put("STA", [(0x85, "zpg", 3), (0x95, "zpx", 4), (0x8D, "abs", 4), (0x9D, "abx", 5), (0x99, "aby", 5),
                (0x81, "inx", 6), (0x91, "iny", 6)])
    for mnemonic, base in (("ASL", 0x00), ("ROL", 0x20), ("LSR", 0x40), ("ROR", 0x60)):
        put(mnemonic, [(base + 0x0A, "acc", 2), (base + 0x06, "zpg", 5), (base + 0x16, "zpx", 6),
                       (base + 0x0E, "abs", 6), (base + 0x1E, "abx", 7)])
    for mnemonic, base in (("DEC", 0xC0), ("INC", 0xE0)):
        put(mnemonic, [(base + 0x06, "zpg", 5), (base + 0x16, "zpx", 6), (base + 0x0E, "abs", 6), (base + 0x1E, "abx", 7)])
    put("LDX", [(0xA2, "imm", 2), (0xA6, "zpg", 3), (0xB6, "zpy", 4), (0xAE, "abs", 4), (0xBE, "aby", 4)], read_modes)
    put("LDY", [(0xA0, "imm", 2), (0xA4, "zpg", 3), (0xB4, "zpx", 4), (0xAC, "abs", 4), (0xBC, "abx", 4)], read_modes)
    put("STX", [(0x86, "zpg", 3), (0x96, "zpy", 4), (0x8E, "abs", 4)])
    put("STY", [(0x84, "zpg", 3), (0x94, "zpx", 4), (0x8C, "abs", 4)])
    put("CPX", [(0xE0, "imm", 2), (0xE4, "zpg", 3), (0xEC, "abs", 4)])
    put("CPY", [(0xC0, "imm", 2), (0xC4, "zpg", 3), (0xCC, "abs", 4)])
    put("BIT", [(0x24, "zpg", 3), (0x2C, "abs", 4)])
    for mnemonic, opcode in (("BPL", 0x10), ("BMI", 0x30), ("BVC", 0x50), ("BVS", 0x70),
                             ("BCC", 0x90), ("BCS", 0xB0), ("BNE", 0xD0), ("BEQ", 0xF0)):
        put(mnemonic, [(opcode, "rel", 2)])
    put("JMP", [(0x4C, "abs", 3), (0x6C, "ind", 5)])
    put("JSR", [(0x20, "abs", 6)])
    put("RTS", [(0x60, "imp", 6)])
    put("RTI", [(0x40, "imp", 6)])
    put("BRK", [(0x00, "imp", 7)])
    for mnemonic, opcode in (("CLC", 0x18), ("SEC", 0x38), ("CLI", 0x58), ("SEI", 0x78), ("CLV", 0xB8),
                             ("CLD", 0xD8), ("SED", 0xF8), ("TAX", 0xAA), ("TXA", 0x8A), ("TAY", 0xA8),
                             ("TYA", 0x98), ("TSX", 0xBA), ("TXS", 0x9A), ("INX", 0xE8), ("INY", 0xC8),
                             ("DEX", 0xCA), ("DEY", 0x88), ("NOP", 0xEA)):
        put(mnemonic, [(opcode, "imp", 2)])
    put("PHA", [(0x48, "imp", 3)])
    put("PHP", [(0x08, "imp", 3)])
    put("PLA", [(0x68, "imp", 4)])
    put("PLP", [(0x28, "imp", 4)])
    return table


def _build() -> dict[int, OpTiming]:
    """The NMOS table: documented and stable undocumented opcodes (64doc)."""
    table = _documented()
    put = _putter(table)
    read_modes = READ_MODES
    rmw = (("zpg", 0x07, 5), ("zpx", 0x17, 6), ("inx", 0x03, 8), ("iny", 0x13, 8),
           ("abs", 0x0F, 6), ("abx", 0x1F, 7), ("aby", 0x1B, 7))
    for mnemonic, base in (("SLO", 0x00), ("RLA", 0x20), ("SRE", 0x40), ("RRA", 0x60), ("DCP", 0xC0), ("ISC", 0xE0)):
        put(mnemonic, [(base + low_, mode, cycles) for mode, low_, cycles in rmw])
    put("LAX", [(0xA7, "zpg", 3), (0xB7, "zpy", 4), (0xA3, "inx", 6), (0xB3, "iny", 5), (0xAF, "abs", 4),
                (0xBF, "aby", 4)], read_modes)
    put("SAX", [(0x87, "zpg", 3), (0x97, "zpy", 4), (0x83, "inx", 6), (0x8F, "abs", 4)])
    put("ANC", [(0x0B, "imm", 2), (0x2B, "imm", 2)])
    put("ALR", [(0x4B, "imm", 2)])
    put("ARR", [(0x6B, "imm", 2)])
    put("SBX", [(0xCB, "imm", 2)])
    put("USBC", [(0xEB, "imm", 2)])
    put("NOP", [(op, "imp", 2) for op in (0x1A, 0x3A, 0x5A, 0x7A, 0xDA, 0xFA)]
        + [(op, "imm", 2) for op in (0x80, 0x82, 0x89, 0xC2, 0xE2)]
        + [(op, "zpg", 3) for op in (0x04, 0x44, 0x64)]
        + [(op, "zpx", 4) for op in (0x14, 0x34, 0x54, 0x74, 0xD4, 0xF4)]
        + [(0x0C, "abs", 4)]
        + [(op, "abx", 4) for op in (0x1C, 0x3C, 0x5C, 0x7C, 0xDC, 0xFC)], read_modes)
    return table


def _build_65c02() -> dict[int, OpTiming]:
    """The W65C02S data sheet (table 5-7): the NMOS documented opcodes with their changes, the new
    ones, and every other opcode a NOP of the size and cycles the data sheet gives."""
    table = _documented()
    table[0x6C] = OpTiming("JMP", "ind", 6, False)  # the page-wrap bug fixed, one cycle more
    for opcode in (0x1E, 0x3E, 0x5E, 0x7E):  # ASL ROL LSR ROR abs,X: 6, +1 across a page
        table[opcode] = OpTiming(table[opcode].mnemonic, "abx", 6, True)
    put = _putter(table)
    for mnemonic, opcode in (("ORA", 0x12), ("AND", 0x32), ("EOR", 0x52), ("ADC", 0x72), ("STA", 0x92),
                             ("LDA", 0xB2), ("CMP", 0xD2), ("SBC", 0xF2)):
        put(mnemonic, [(opcode, "zpi", 5)])  # the (zp) mode
    put("BIT", [(0x89, "imm", 2), (0x34, "zpx", 4), (0x3C, "abx", 4)], READ_MODES)
    put("BRA", [(0x80, "rel", 2)])  # always taken: 3, 4 across a page
    put("STZ", [(0x64, "zpg", 3), (0x74, "zpx", 4), (0x9C, "abs", 4), (0x9E, "abx", 5)])
    put("TSB", [(0x04, "zpg", 5), (0x0C, "abs", 6)])
    put("TRB", [(0x14, "zpg", 5), (0x1C, "abs", 6)])
    put("INC", [(0x1A, "acc", 2)])
    put("DEC", [(0x3A, "acc", 2)])
    put("PHX", [(0xDA, "imp", 3)])
    put("PHY", [(0x5A, "imp", 3)])
    put("PLX", [(0xFA, "imp", 4)])
    put("PLY", [(0x7A, "imp", 4)])
    put("JMP", [(0x7C, "iax", 6)])
    put("WAI", [(0xCB, "imp", 3)])
    put("STP", [(0xDB, "imp", 3)])
    for bit in range(8):
        put(f"RMB{bit}", [(bit << 4 | 0x07, "zpg", 5)])
        put(f"SMB{bit}", [((8 + bit) << 4 | 0x07, "zpg", 5)])
        put(f"BBR{bit}", [(bit << 4 | 0x0F, "zpr", 5)])
        put(f"BBS{bit}", [((8 + bit) << 4 | 0x0F, "zpr", 5)])
    # The reserved opcodes, by the data sheet's columns: x2 two bytes and two cycles, x3 and xB one
    # byte and one cycle; $44 (3 cycles), $54 $D4 $F4 (4) two bytes; $DC $FC (4) and $5C (8) three.
    nops = {0x44: ("zpg", 3), 0x54: ("zpx", 4), 0xD4: ("zpx", 4), 0xF4: ("zpx", 4), 0xDC: ("abs", 4),
            0xFC: ("abs", 4), 0x5C: ("abs", 8)}
    for opcode in range(256):
        if opcode in table:
            continue
        mode, cycles = nops.get(opcode) or (("imm", 2) if opcode & 0x0F == 0x02 else ("imp", 1))
        put("NOP", [(opcode, mode, cycles)])
    return table


OPCODES: dict[int, OpTiming] = _build()
OPCODES_65C02: dict[int, OpTiming] = _build_65c02()


def timing_table(cpu: str) -> dict[int, OpTiming]:
    """The timing table of a CPU variant ("6510", "2a03": NMOS; "65c02": WDC)."""
    return OPCODES_65C02 if cpu == WDC_65C02 else OPCODES


class TimingError(ValueError):
    """An opcode the table does not know (an unstable or JAM opcode)."""


def timing_of(opcode: int, cpu: str = "6510") -> OpTiming:
    try:
        return timing_table(cpu)[opcode]
    except KeyError:
        raise TimingError(f"opcode ${opcode:02X} has no entry in the timing table") from None


def branch_target(pc: int, offset: int, length: int = 2) -> int:
    """Where a relative branch at pc goes (length: 2, or 3 for BBR/BBS, whose offset is the last byte)."""
    next_pc = (pc + length) & 0xFFFF
    return (next_pc + (offset - 256 if offset & 0x80 else offset)) & 0xFFFF


def crosses_page(base: int, address: int) -> bool:
    return (base & PAGE_MASK) != (address & PAGE_MASK)


# Branch opcode -> (status flag bit, value that takes the branch).
BRANCH_CONDITIONS = {0x10: (0x80, 0), 0x30: (0x80, 1), 0x50: (0x40, 0), 0x70: (0x40, 1),
                     0x90: (0x01, 0), 0xB0: (0x01, 1), 0xD0: (0x02, 0), 0xF0: (0x02, 1)}


def is_conditional_branch(op: OpTiming) -> bool:
    """A branch that may go either way (not BRA): Bxx and the 65C02's BBR/BBS."""
    return op.mode in ("rel", "zpr") and op.mnemonic != "BRA"


# ---- the rules as the run loop reads them: per opcode, its base cycles and what it adds ------------

Rule = Callable[[Callable[[int], int], int, int, int, int, "int | None"], int]  # (read, pc, x, y, p, pointer) -> cycles


def _pointer(read: Callable[[int], int], pc: int, pointer: int | None) -> int:
    """The zero-page word the operand of the instruction at pc names, unless given (None: read now,
    before the instruction runs)."""
    if pointer is not None:
        return pointer
    zp = read((pc + 1) & 0xFFFF)
    return read(zp) | read((zp + 1) & 0xFF) << 8


def _taken_cycles(read: Callable[[int], int], pc: int, length: int) -> int:
    """What a taken branch at pc adds: +1, and +1 more when the target lies in another page than the
    next instruction (the offset is the instruction's last byte; `length` 2, or 3 for BBR/BBS)."""
    after = (pc + length) & 0xFFFF
    target = branch_target(pc, read((pc + length - 1) & 0xFFFF), length)
    return BRANCH_TAKEN_CYCLES + (BRANCH_PAGE_CYCLES if (after ^ target) & PAGE_MASK else 0)


def _flag_branch_rule(opcode: int) -> Rule:
    """Bxx: taken when its flag has the value BRANCH_CONDITIONS says."""
    flag, wanted = BRANCH_CONDITIONS[opcode]
    when = flag if wanted else 0

    def extra(read, pc, x, y, p, pointer):
        return _taken_cycles(read, pc, 2) if (p & flag) == when else 0
    return extra


def _always_taken(read, pc, x, y, p, pointer):  # the 65C02's BRA
    return _taken_cycles(read, pc, 2)


def _bit_branch_rule(bit: int, when_set: bool) -> Rule:
    """The 65C02's BBR/BBS: taken when the zero-page byte's bit (the pointer's low byte) is as named."""
    def extra(read, pc, x, y, p, pointer):
        return _taken_cycles(read, pc, 3) if bool(_pointer(read, pc, pointer) >> bit & 1) == when_set else 0
    return extra


def _page_rule(mode: str) -> Rule:
    """A read in an indexed mode: +1 when the indexed address lies in another page than its base."""
    if mode == "iny":
        def extra(read, pc, x, y, p, pointer):
            base = _pointer(read, pc, pointer)
            return PAGE_CROSS_CYCLES if (base ^ (base + y)) & PAGE_MASK else 0
        return extra
    use_x = mode == "abx"

    def extra(read, pc, x, y, p, pointer):
        base = read((pc + 1) & 0xFFFF) | read((pc + 2) & 0xFFFF) << 8
        return PAGE_CROSS_CYCLES if (base ^ (base + (x if use_x else y))) & PAGE_MASK else 0
    return extra


def _decimal_rule(rule: Rule | None) -> Rule:
    """The 65C02's ADC and SBC: one cycle more with D set (besides a page penalty `rule`)."""
    def extra(read, pc, x, y, p, pointer):
        return (CMOS_DECIMAL_CYCLES if p & 0x08 else 0) + (rule(read, pc, x, y, p, pointer) if rule else 0)
    return extra


def _rule(opcode: int, op: OpTiming, cpu: str) -> Rule | None:
    rule: Rule | None = None
    if op.mnemonic == "BRA":
        rule = _always_taken
    elif op.mode == "rel":
        rule = _flag_branch_rule(opcode)
    elif op.mode == "zpr":
        rule = _bit_branch_rule(int(op.mnemonic[3]), op.mnemonic[2] == "S")
    elif op.page_penalty:
        rule = _page_rule(op.mode)
    if cpu == WDC_65C02 and op.mnemonic in ("ADC", "SBC"):
        rule = _decimal_rule(rule)
    return rule


@dataclass(frozen=True)
class StepModel:
    """A CPU's timing table as a run loop reads it, per opcode: `bases`, its base cycles (0 for an opcode
    the table does not know: `known` says which it knows), and `rules`, None when it adds nothing to
    them, else a function (read, pc, x, y, p, pointer) -> the cycles it adds, from the registers before
    the instruction; `pointer` is the zero-page word an (indirect),Y operand (or the 65C02's BBR/BBS)
    names as it was then, or None to read it from memory as it is now (before the instruction)."""

    bases: tuple[int, ...]
    rules: tuple[Rule | None, ...]
    known: frozenset[int]


def _step_model(cpu: str) -> StepModel:
    table = timing_table(cpu)
    return StepModel(tuple(table[op].cycles if op in table else 0 for op in range(256)),
                     tuple(_rule(op, table[op], cpu) if op in table else None for op in range(256)),
                     frozenset(table))


STEP_MODELS = {cpu: _step_model(cpu) for cpu in ("6510", WDC_65C02)}


def step_model(cpu: str = "6510") -> StepModel:
    """The run loop's form of a CPU variant's timing table ("6510", "2a03": NMOS; "65c02": WDC)."""
    return STEP_MODELS[WDC_65C02 if cpu == WDC_65C02 else "6510"]


def instruction_cycles(read: Callable[[int], int], pc: int, x: int, y: int, p: int, pointer: int,
                       cpu: str = "6510") -> int:
    """Cycles of the instruction at pc, given the registers before it.

    `pointer` is the 16-bit pointer an (indirect),Y instruction reads from zero page (else unused); for
    the 65C02's BBR/BBS its low byte is the zero-page byte they test.
    """
    opcode = read(pc)
    model = step_model(cpu)
    if opcode not in model.known:
        timing_of(opcode, cpu)  # (its TimingError)
    rule = model.rules[opcode]
    return model.bases[opcode] + (rule(read, pc, x, y, p, pointer) if rule is not None else 0)


def model_cycles(read: Callable[[int], int], steps: Iterable[tuple[int, int, int, int, int]],
                 cpu: str = "6510") -> int:
    """Total cycles of an executed path; steps are (pc, x, y, p, pointer, ...) before each instruction."""
    model = step_model(cpu)
    bases, rules, known = model.bases, model.rules, model.known
    total = 0
    for step in steps:
        pc = step[0]
        opcode = read(pc)
        if opcode not in known:
            timing_of(opcode, cpu)  # (its TimingError)
        total += bases[opcode]
        rule = rules[opcode]
        if rule is not None:
            total += rule(read, pc, step[1], step[2], step[3], step[4])
    return total
