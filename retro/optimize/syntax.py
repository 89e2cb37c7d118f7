"""A listing as source text in the assembler syntax the user writes: ACME, 64tass, ca65, DASM, xa,
KickAssembler, Ophis. Labels end lines of their own; an operand address that has a label is written
by name, its value given as an equate first (the routine's data lives elsewhere in the program).

Sources for the syntax: the ACME manual (docs/QuickRef.txt: `* = ADDR`, `+2` forcing absolute), the
64tass manual (`* =`, `@w`), the ca65 users guide (`.org`, `label:`, `a:` address size), the DASM
manual (`processor`, `org`, `equ`, `.w`), the xa65 man page (`* =`, `!` before an operand forcing 16 bits), the Kick
Assembler manual (`.label`, `.abs`), the Ophis manual (`.org`, `.alias`)."""

from __future__ import annotations

from retro.cpu.disassembly import SHIFTS
from retro.optimize.code import Listing

SYNTAXES = ("acme", "64tass", "ca65", "dasm", "xa", "kickass", "ophis")


def _equate(syntax: str, name: str, value: int) -> str:
    text = f"${value:04X}" if value > 0xFF else f"${value:02X}"
    return {"dasm": f"{name} equ {text}", "kickass": f".label {name} = {text}",
            "ophis": f".alias {name} {text}"}.get(syntax, f"{name} = {text}")


def _origin(syntax: str, origin: int) -> list[str]:
    return {"ca65": [f"        .org ${origin:04X}"], "ophis": [f"        .org ${origin:04X}"],
            "dasm": ["        processor 6502", f"        org ${origin:04X}"]}.get(syntax, [f"        * = ${origin:04X}"])


def _label(syntax: str, name: str) -> str:
    return f"{name}:" if syntax in ("ca65", "kickass", "ophis") else name


def _absolute(syntax: str, mnemonic: str, operand: str) -> str:
    """An absolute operand below $100: forced to two bytes, as the routine's bytes have it."""
    return {"acme": f"{mnemonic}+2 {operand}", "64tass": f"{mnemonic} @w {operand}", "ca65": f"{mnemonic} a:{operand}",
            "dasm": f"{mnemonic}.w {operand}", "xa": f"{mnemonic} !{operand}", "kickass": f"{mnemonic}.abs {operand}",
            "ophis": f"{mnemonic} {operand}  ; absolute: the assembler may shorten it"}[syntax]


def format_source(listing: Listing, syntax: str, names: dict[int, str], title: str = "") -> str:
    """The listing in `syntax`; `names`: address -> label for operands (data, pointers)."""
    if syntax not in SYNTAXES:
        raise ValueError(syntax)
    lines = [f"; {title}"] if title else []
    used = {}
    for instruction in listing.instructions:
        if instruction.mode in ("zpg", "abs", "zpx", "zpy", "abx", "aby", "inx", "iny", "ind") and instruction.target is None:
            if instruction.operand in names:
                used[names[instruction.operand]] = instruction.operand
        elif isinstance(instruction.target, int) and instruction.target in names:
            used[names[instruction.target]] = instruction.target
    lines += [_equate(syntax, name, value) for name, value in sorted(used.items(), key=lambda kv: kv[1])]
    lines += _origin(syntax, listing.origin)
    labels = dict(listing.labels)
    for k, instruction in enumerate(listing.instructions):
        lines += [_label(syntax, name) for name, at in listing.labels if at == k]
        mnemonic, mode = instruction.mnemonic.lower(), instruction.mode
        target = instruction.target
        if target is not None:
            operand = target if isinstance(target, str) else names.get(target, f"${target:04X}")
            text = f"{mnemonic} {operand}"
        elif mode in ("imp", "acc"):
            text = mnemonic if mode == "imp" or instruction.mnemonic not in SHIFTS or syntax != "64tass" else f"{mnemonic} a"
        elif mode == "imm":
            text = f"{mnemonic} #${instruction.operand:02X}"
        else:
            value = instruction.operand
            name = names.get(value, f"${value:04X}" if mode in ("abs", "abx", "aby", "ind") else f"${value:02X}")
            suffix = {"zpx": ",x", "abx": ",x", "zpy": ",y", "aby": ",y"}.get(mode, "")
            if mode == "inx":
                text = f"{mnemonic} ({name},x)"
            elif mode == "iny":
                text = f"{mnemonic} ({name}),y"
            elif mode == "ind":
                text = f"{mnemonic} ({name})"
            elif mode in ("abs", "abx", "aby") and value < 0x100:
                text = _absolute(syntax, mnemonic, name + suffix)
            else:
                text = f"{mnemonic} {name}{suffix}"
        lines.append(f"        {text}")
    lines += [_label(syntax, name) for name, at in listing.labels if at == len(listing.instructions)]
    del labels
    return "\n".join(lines) + "\n"


def plain_lines(listing: Listing, names: dict[int, str]) -> list[str]:
    """The listing as a diff shows it: one instruction a line (Ophis-like, labels on their own lines)."""
    return format_source(listing, "ophis", names).splitlines()
