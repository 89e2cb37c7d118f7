"""A routine's code as plain data: instructions (mnemonic, mode, operand or branch label), read
from a loaded program and assembled back to bytes with the opcode table (retro.cpu.opcodes).

Branches name their target by label, so a window can be replaced by code of another length and the
routine assembled again at the same origin; a target outside the routine's code stays an address."""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

from retro.cpu.disassembly import decode_at, opcode_table
from retro.cpu.opcodes import DOCUMENTED, MODE_LENGTH, STABLE
from retro.errors import InputError
from retro.program import Program

ENDS = frozenset({"RTS", "RTI", "JMP", "BRK"})  # no way on to the next instruction
MAX_ROUTINE_BYTES = 4096  # a routine the search reads: its code from the entry, never a whole program


@dataclass(frozen=True)
class Instruction:
    """One instruction: `operand` is the byte or word of its mode (None for imp/acc and branches);
    a branch (mode rel) or JMP/JSR has `target`: a label of the routine, or an address outside it."""

    mnemonic: str
    mode: str
    operand: int | None = None
    target: str | int | None = None

    @property
    def length(self) -> int:
        return MODE_LENGTH[self.mode]

    @property
    def is_branch(self) -> bool:
        return self.mode == "rel"


@dataclass(frozen=True)
class Listing:
    """A routine's code: instructions in address order, the labels before instruction i
    (`labels[name] = i`; i = len(instructions) is the address just past the code), the origin."""

    origin: int
    instructions: tuple[Instruction, ...]
    labels: tuple[tuple[str, int], ...] = ()

    def label_at(self, index: int) -> list[str]:
        return [name for name, i in self.labels if i == index]

    @property
    def targets(self) -> frozenset[int]:
        """Indices some branch of the routine reaches (a window never spans one)."""
        where = dict(self.labels)
        return frozenset(where[i.target] for i in self.instructions if isinstance(i.target, str))

    def with_window(self, start: int, stop: int, replacement: tuple[Instruction, ...]) -> "Listing":
        """The listing with instructions [start, stop) replaced (labels after the window move)."""
        shift = len(replacement) - (stop - start)
        labels = tuple((name, i if i <= start else i + shift) for name, i in self.labels)
        return Listing(self.origin, self.instructions[:start] + tuple(replacement) + self.instructions[stop:], labels)


@functools.cache
def opcode_of(cpu: str) -> dict[tuple[str, str], int]:
    """(mnemonic, mode) -> opcode for a CPU; documented rows first, then stable undocumented ones."""
    found: dict[tuple[str, str], int] = {}
    for kind in (DOCUMENTED, STABLE):
        for opcode, op in sorted(opcode_table(cpu).items()):
            if op.kind == kind:
                found.setdefault((op.mnemonic, op.mode), opcode)
    return found


def assemble(listing: Listing, cpu: str = "6510") -> bytes | None:
    """The bytes of the listing at its origin; None when a branch cannot reach its target."""
    addresses = [listing.origin]
    for instruction in listing.instructions:
        addresses.append(addresses[-1] + instruction.length)
    label_address = {name: addresses[i] for name, i in listing.labels}
    table = opcode_of(cpu)
    out = bytearray()
    for instruction, address in zip(listing.instructions, addresses):
        out.append(table[(instruction.mnemonic, instruction.mode)])
        target = instruction.target
        if target is not None:
            where = label_address[target] if isinstance(target, str) else target
            if instruction.mode == "rel":
                offset = where - (address + 2)
                if not -128 <= offset <= 127:
                    return None
                out.append(offset & 0xFF)
            else:
                out += (where & 0xFFFF).to_bytes(2, "little")
        elif instruction.length == 2:
            out.append(instruction.operand & 0xFF)
        elif instruction.length == 3:
            out += (instruction.operand & 0xFFFF).to_bytes(2, "little")
    return bytes(out)


def code_bytes(listing: Listing) -> int:
    return sum(i.length for i in listing.instructions)


def _successors(decoded, address: int, entry: int, jumps: bool) -> list[int]:
    """Where the routine may go on after the instruction at `address` (branches back before the
    entry are left out: they are refused as a whole); with `jumps`, a JMP's target too."""
    following = []
    if decoded.mode == "rel" and decoded.target >= entry:
        following.append(decoded.target)
    if jumps and decoded.mnemonic == "JMP" and decoded.mode == "abs" and decoded.target >= entry:
        following.append(decoded.target)
    if decoded.mnemonic == "BRA":
        following.append(decoded.target)
    elif decoded.mnemonic not in ENDS:
        following.append(address + decoded.length)
    return following


def _decode_reachable(program: Program, entry: int, cpu: str, jumps: bool) -> dict:
    """Address -> decoded instruction for every instruction reachable from the entry inside the program."""
    code = program.code

    def read(address: int) -> int:
        return code[address - program.origin] if program.origin <= address < program.end else 0

    if not program.origin <= entry < program.end:
        raise InputError(f"the routine's entry ${entry:04X} is outside its program")
    decoded, pending = {}, [entry]
    while pending:
        address = pending.pop()
        if address in decoded or not program.origin <= address < program.end:
            continue
        if address - entry > MAX_ROUTINE_BYTES:
            raise InputError(f"the routine's code from ${entry:04X} runs past {MAX_ROUTINE_BYTES} bytes")
        instruction = decoded[address] = decode_at(read, address, cpu)
        if instruction.mode == "zpr":
            raise InputError(f"${address:04X}: {instruction.text}: the 65C02's BBR/BBS are not optimised")
        pending += _successors(instruction, address, entry, jumps)
    return decoded


def _end_of_block(decoded: dict, entry: int) -> int:
    """The address just past the decoded instructions, which must tile one block from the entry."""
    ordered = sorted(decoded)
    if ordered[0] != entry:
        raise InputError(f"the routine branches before its entry ${entry:04X}: not one block of code")
    address = entry
    for start in ordered:
        if start != address:
            raise InputError(f"the routine's code from ${entry:04X} is not one block (${address:04X}: "
                             f"{'data or a gap' if start > address else 'an instruction inside another'})")
        address = start + decoded[start].length
    return address


def _operand(decoded) -> int | None:
    """The byte or little-endian word after the opcode."""
    if decoded.length == 1:
        return None
    return decoded.data[1] if decoded.length == 2 else decoded.data[1] | decoded.data[2] << 8


def _has_target(decoded) -> bool:
    return decoded.mode == "rel" or (decoded.mnemonic in ("JMP", "JSR") and decoded.mode == "abs")


def address_names(symbols: dict[str, int]) -> dict[int, str]:
    """Address -> the name a listing gives it: the first of its symbols in sorted order."""
    names: dict[int, str] = {}
    for name, value in sorted(symbols.items()):
        names.setdefault(value, name)
    return names


def read_listing(program: Program, entry: int, cpu: str = "6510") -> Listing:
    """The routine at `entry` as a listing: every instruction reachable from the entry (branches,
    JSR and the next instruction followed; RTS, RTI, JMP and BRK end a path), which must form one
    block of code from the entry (data inside it, or a jump into the middle of an instruction, is
    refused). Branch targets inside the block get the program's label for their address, else
    `L_XXXX`, and so do JMP targets inside the block: a JMP to a block after the routine's end
    (an out-of-line block) is followed when the whole still forms one block, else a JMP ends its
    path and keeps its address, as JSR targets and targets outside do."""
    try:
        decoded = _decode_reachable(program, entry, cpu, jumps=True)
        end = _end_of_block(decoded, entry)
    except InputError:
        decoded = _decode_reachable(program, entry, cpu, jumps=False)
        end = _end_of_block(decoded, entry)
    ordered = sorted(decoded)
    index_of = {address: k for k, address in enumerate(ordered)}
    index_of[end] = len(ordered)
    names = address_names(program.symbols)
    labels: dict[str, int] = {}
    instructions = []
    for d in (decoded[address] for address in ordered):
        target = d.target if _has_target(d) else None
        if (d.mode == "rel" or d.mnemonic == "JMP") and target in index_of:
            target, at = names.get(target) or f"L_{target:04X}", index_of[target]
            labels[target] = at
        instructions.append(Instruction(d.mnemonic, d.mode, None if _has_target(d) else _operand(d), target))
    if entry in names:
        labels.setdefault(names[entry], 0)
    return Listing(entry, tuple(instructions), tuple(sorted(labels.items(), key=lambda kv: (kv[1], kv[0]))))


def program_with(program: Program, listing: Listing, cpu: str, old_size: int) -> Program | None:
    """The program with the routine's code block replaced by the listing's bytes (the bytes it no
    longer fills become NOPs, so what follows keeps its addresses); None when the new code does not
    fit in the old block or a branch does not reach."""
    new = assemble(listing, cpu)
    if new is None or len(new) > old_size:
        return None
    start = listing.origin - program.origin
    nop = opcode_of(cpu)[("NOP", "imp")]
    code = bytearray(program.code)
    code[start:start + old_size] = new + bytes([nop]) * (old_size - len(new))
    return replace(program, code=bytes(code), listing="")
