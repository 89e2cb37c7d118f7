"""A listing as source text in the assembler syntax the user writes: ACME, 64tass, ca65, DASM, xa,
KickAssembler, Ophis. Labels end lines of their own; an operand address that has a label is written
by name, its value given as an equate first (the routine's data lives elsewhere in the program).

Sources for the syntax: the ACME manual (docs/QuickRef.txt: `* = ADDR`, `+2` forcing absolute), the
64tass manual (`* =`, `@w`), the ca65 users guide (`.org`, `label:`, `a:` address size), the DASM
manual (`processor`, `org`, `equ`, `.w`), the xa65 man page (`* =`, `!` before an operand forcing 16 bits), the Kick
Assembler manual (`.label`, `.abs`), the Ophis manual (`.org`, `.alias`)."""

from __future__ import annotations

from dataclasses import dataclass

from retro.cpu.disassembly import SHIFTS
from retro.optimize.code import Instruction, Listing

INDENT = "        "


@dataclass(frozen=True)
class Syntax:
    """How one assembler writes what a listing needs; format fields: {name}, {value}, {origin},
    {mnemonic}, {operand}."""

    absolute: str  # an absolute operand below $100, forced to two bytes as the routine's bytes have it
    origin: tuple[str, ...] = ("* = ${origin:04X}",)
    equate: str = "{name} = {value}"
    label: str = "{name}"
    shift_of_a: str = "{mnemonic}"  # ASL/LSR/ROL/ROR of the accumulator


RULES: dict[str, Syntax] = {
    "acme": Syntax(absolute="{mnemonic}+2 {operand}"),
    "64tass": Syntax(absolute="{mnemonic} @w {operand}", shift_of_a="{mnemonic} a"),
    "ca65": Syntax(absolute="{mnemonic} a:{operand}", origin=(".org ${origin:04X}",), label="{name}:"),
    "dasm": Syntax(absolute="{mnemonic}.w {operand}", origin=("processor 6502", "org ${origin:04X}"),
                   equate="{name} equ {value}"),
    "xa": Syntax(absolute="{mnemonic} !{operand}"),
    "kickass": Syntax(absolute="{mnemonic}.abs {operand}", equate=".label {name} = {value}", label="{name}:"),
    "ophis": Syntax(absolute="{mnemonic} {operand}  ; absolute: the assembler may shorten it",
                    origin=(".org ${origin:04X}",), equate=".alias {name} {value}", label="{name}:"),
}
SYNTAXES = tuple(RULES)

NAMED_MODES = ("zpg", "abs", "zpx", "zpy", "abx", "aby", "inx", "iny", "ind", "zpi", "iax")  # an operand that may be a label
WORD_MODES = ("abs", "abx", "aby", "ind", "iax")
FORCED_WORD_MODES = ("abs", "abx", "aby")  # the modes with a zero-page twin the assembler would pick
# mode -> its operand around the address or name (other modes: the address alone)
OPERAND_SHAPE = {"zpx": "{},x", "abx": "{},x", "zpy": "{},y", "aby": "{},y",
                 "inx": "({},x)", "iny": "({}),y", "ind": "({})",
                 "zpi": "({})", "iax": "({},x)"}  # the 65C02's (zp) and JMP (abs,X)


def _hex(value: int) -> str:
    return f"${value:04X}" if value > 0xFF else f"${value:02X}"


def _named_address(instruction: Instruction) -> int | None:
    """The address of the instruction's operand or target that a name may stand for."""
    if instruction.mode in NAMED_MODES and instruction.target is None:
        return instruction.operand
    return instruction.target if isinstance(instruction.target, int) else None


def _equates(listing: Listing, names: dict[int, str]) -> list[tuple[str, int]]:
    """The names the listing's operands use, by value."""
    used = {}
    for instruction in listing.instructions:
        address = _named_address(instruction)
        if address in names:
            used[names[address]] = address
    return sorted(used.items(), key=lambda kv: kv[1])


def _memory_operand(instruction: Instruction, syntax: Syntax, names: dict[int, str]) -> str:
    mnemonic, mode, value = instruction.mnemonic.lower(), instruction.mode, instruction.operand
    name = names.get(value, f"${value:04X}" if mode in WORD_MODES else f"${value:02X}")
    operand = OPERAND_SHAPE.get(mode, "{}").format(name)
    if mode in FORCED_WORD_MODES and value < 0x100:
        return syntax.absolute.format(mnemonic=mnemonic, operand=operand)
    return f"{mnemonic} {operand}"


def _instruction_text(instruction: Instruction, syntax: Syntax, names: dict[int, str]) -> str:
    mnemonic, mode, target = instruction.mnemonic.lower(), instruction.mode, instruction.target
    if target is not None:
        return f"{mnemonic} {target if isinstance(target, str) else names.get(target, f'${target:04X}')}"
    if mode == "acc" and instruction.mnemonic in SHIFTS:
        return syntax.shift_of_a.format(mnemonic=mnemonic)
    if mode in ("imp", "acc"):
        return mnemonic
    if mode == "imm":
        return f"{mnemonic} #${instruction.operand:02X}"
    return _memory_operand(instruction, syntax, names)


def format_source(listing: Listing, syntax: str, names: dict[int, str], title: str = "") -> str:
    """The listing in `syntax`; `names`: address -> label for operands (data, pointers)."""
    if syntax not in RULES:
        raise ValueError(syntax)
    rules = RULES[syntax]
    lines = [f"; {title}"] if title else []
    lines += [rules.equate.format(name=name, value=_hex(value)) for name, value in _equates(listing, names)]
    lines += [INDENT + line.format(origin=listing.origin) for line in rules.origin]
    for k, instruction in enumerate(listing.instructions):
        lines += [rules.label.format(name=name) for name in listing.label_at(k)]
        lines.append(INDENT + _instruction_text(instruction, rules, names))
    lines += [rules.label.format(name=name) for name in listing.label_at(len(listing.instructions))]
    return "\n".join(lines) + "\n"


def plain_lines(listing: Listing, names: dict[int, str]) -> list[str]:
    """The listing as a diff shows it: one instruction a line (Ophis-like, labels on their own lines)."""
    return format_source(listing, "ophis", names).splitlines()
