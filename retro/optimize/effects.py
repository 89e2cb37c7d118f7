"""What each instruction reads and writes (registers, flags, memory by address), and which of them
are live after each instruction of a routine: a window may change what is dead after it."""

from __future__ import annotations

from retro.optimize.code import Listing

NZ = frozenset("NZ")
EVERYTHING = frozenset("AXYCZNVDI")
ALL_MEMORY = -1  # a read at an unknown address: every byte may be read
DIRECT_MODES = ("imm", "zpg", "abs", "imp", "acc")

# mnemonic -> (registers and flags read, registers and flags written); memory comes from the mode
REGISTER_EFFECTS: dict[str, tuple[frozenset, frozenset]] = {
    "LDA": (frozenset(), frozenset("ANZ")), "LDX": (frozenset(), frozenset("XNZ")),
    "LDY": (frozenset(), frozenset("YNZ")), "STA": (frozenset("A"), frozenset()),
    "STX": (frozenset("X"), frozenset()), "STY": (frozenset("Y"), frozenset()),
    "TAX": (frozenset("A"), frozenset("XNZ")), "TAY": (frozenset("A"), frozenset("YNZ")),
    "TXA": (frozenset("X"), frozenset("ANZ")), "TYA": (frozenset("Y"), frozenset("ANZ")),
    "ADC": (frozenset("ACD"), frozenset("ANVZC")), "SBC": (frozenset("ACD"), frozenset("ANVZC")),
    "AND": (frozenset("A"), frozenset("ANZ")), "ORA": (frozenset("A"), frozenset("ANZ")),
    "EOR": (frozenset("A"), frozenset("ANZ")), "CMP": (frozenset("A"), frozenset("NZC")),
    "CPX": (frozenset("X"), frozenset("NZC")), "CPY": (frozenset("Y"), frozenset("NZC")),
    "BIT": (frozenset("A"), frozenset("NVZ")), "INC": (frozenset(), NZ), "DEC": (frozenset(), NZ),
    "INX": (frozenset("X"), frozenset("XNZ")), "DEX": (frozenset("X"), frozenset("XNZ")),
    "INY": (frozenset("Y"), frozenset("YNZ")), "DEY": (frozenset("Y"), frozenset("YNZ")),
    "ASL": (frozenset(), frozenset("NZC")), "LSR": (frozenset(), frozenset("NZC")),
    "ROL": (frozenset("C"), frozenset("NZC")), "ROR": (frozenset("C"), frozenset("NZC")),
    "CLC": (frozenset(), frozenset("C")), "SEC": (frozenset(), frozenset("C")),
    "CLD": (frozenset(), frozenset("D")), "SED": (frozenset(), frozenset("D")),
    "CLV": (frozenset(), frozenset("V")), "NOP": (frozenset(), frozenset()),
    "BCC": (frozenset("C"), frozenset()), "BCS": (frozenset("C"), frozenset()),
    "BEQ": (frozenset("Z"), frozenset()), "BNE": (frozenset("Z"), frozenset()),
    "BMI": (frozenset("N"), frozenset()), "BPL": (frozenset("N"), frozenset()),
    "BVC": (frozenset("V"), frozenset()), "BVS": (frozenset("V"), frozenset()),
}
STORES = frozenset({"STA", "STX", "STY"})
READ_MODIFY_WRITE = frozenset({"INC", "DEC", "ASL", "LSR", "ROL", "ROR"})
INDEXED_READ_MODES = ("zpx", "zpy", "abx", "aby", "iny")  # windows may read through these (retro.optimize.search)
INDEX_OF_MODE = {"zpx": "X", "abx": "X", "inx": "X", "zpy": "Y", "aby": "Y", "iny": "Y"}


def known(instruction) -> bool:
    """Its effects are in the table (undocumented and stack opcodes are not: windows stop there)."""
    return instruction.mnemonic in REGISTER_EFFECTS


def effects(instruction) -> tuple[frozenset, frozenset, frozenset, frozenset]:
    """(registers read, registers written, addresses read, addresses certainly written); an
    address read of ALL_MEMORY: unknown (indexed, indirect). Unknown instructions read everything."""
    if not known(instruction):
        return EVERYTHING, frozenset(), frozenset({ALL_MEMORY}), frozenset()
    reads, writes = REGISTER_EFFECTS[instruction.mnemonic]
    mode = instruction.mode
    if instruction.mnemonic in ("ASL", "LSR", "ROL", "ROR") and mode == "acc":
        reads, writes = reads | {"A"}, writes | {"A"}
    if mode in INDEX_OF_MODE:
        reads = reads | {INDEX_OF_MODE[mode]}
    read_memory, written = frozenset(), frozenset()
    if mode in ("zpg", "abs") and instruction.target is None:
        if instruction.mnemonic not in STORES:
            read_memory = frozenset({instruction.operand})
        if instruction.mnemonic in STORES or instruction.mnemonic in READ_MODIFY_WRITE:
            written = frozenset({instruction.operand})
    elif mode not in ("imp", "acc", "imm", "rel"):
        if instruction.mnemonic not in STORES:
            read_memory = frozenset({ALL_MEMORY})
    return reads, writes, read_memory, written


def live_after(listing: Listing, at_return: frozenset) -> list[frozenset]:
    """Per instruction, what is live after it (registers and flags by letter, addresses as ints,
    ALL_MEMORY for every address): `at_return` is live at an RTS (the outputs, preserved places);
    everything is live at a JSR, JMP, RTI or an instruction the table does not know."""
    instructions = listing.instructions
    where = dict(listing.labels)
    everything = EVERYTHING | {ALL_MEMORY}
    live_in = [frozenset()] * (len(instructions) + 1)
    after = [frozenset()] * len(instructions)
    changed = True
    while changed:
        changed = False
        for i in reversed(range(len(instructions))):
            instruction = instructions[i]
            name = instruction.mnemonic
            local_jump = name == "JMP" and isinstance(instruction.target, str)  # to a label of the routine
            if name == "RTS":
                out = at_return
            elif local_jump:
                out = live_in[where[instruction.target]]
            elif name in ("JMP", "JSR", "RTI", "BRK") or not known(instruction):
                out = everything
            else:
                out = live_in[i + 1]
                if instruction.is_branch:
                    target = instruction.target
                    out = out | (live_in[where[target]] if isinstance(target, str) else everything)
            reads, writes, read_memory, written = effects(instruction)
            if name == "RTS" or local_jump:
                incoming = out
            elif name in ("RTI", "JMP", "JSR", "BRK") or not known(instruction):
                incoming = everything
            else:
                incoming = (out - writes - written) | reads | read_memory
            after[i] = out
            if incoming != live_in[i]:
                live_in[i] = incoming
                changed = True
    return after


def windowable(instruction, indexed: bool = False) -> bool:
    """An instruction a window may hold: known, straight-line, direct addressing; with `indexed`,
    also a read through an indexed or (zp),Y operand (never a write: its address is per case)."""
    if not known(instruction) or instruction.is_branch or instruction.target is not None:
        return False
    if instruction.mode in DIRECT_MODES:
        return True
    return (indexed and instruction.mode in INDEXED_READ_MODES and instruction.mnemonic not in STORES
            and instruction.mnemonic not in READ_MODIFY_WRITE)


def writes_through_index(instruction) -> bool:
    """A store or read-modify-write whose address depends on X, Y or a pointer."""
    return (instruction.mode not in DIRECT_MODES and instruction.mode != "rel"
            and (instruction.mnemonic in STORES or instruction.mnemonic in READ_MODIFY_WRITE))
