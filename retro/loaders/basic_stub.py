"""The tokenised BASIC line of a C64 program: where `RUN` would `SYS` to.

A C64 `.prg` that starts with `10 SYS 2061` is loaded at $0801 (BASIC's program start) and holds
tokenised BASIC lines [Mapping the Commodore 64, $0801 and $A000 token table; C64 Programmer's
Reference Guide, "BASIC tokens"]: each line is a 2-byte pointer to the next line (0: the end of the
program), a 2-byte line number, the text with keywords as tokens (SYS = $9E, REM = $8F), and a
$00 byte. `SYS` takes a number 0-65535; BASIC ignores spaces inside it. The expression ends at the first byte
that is not part of it: an operator is a token ($AA-$B3: + - * / ^ AND OR > = <), so untokenised text
after the number (`SYS2069 /T.L.R/`, as some test programs sign their line) is never read by BASIC
while the SYS'd code runs (a note says so).

`sys_line(program)` finds the first `SYS` that RUN would reach, without a BASIC interpreter:
statements before it are not run (a note says so); an expression retro cannot evaluate
(`SYS A`, `SYS 4096+12`) is a one-line error.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from retro.errors import InputError
from retro.program import Program

BASIC_START = 0x0801
TOKEN_SYS = 0x9E
TOKEN_REM = 0x8F
QUOTE = 0x22
SPACE = 0x20
COLON = 0x3A
OPEN_PAREN, CLOSE_PAREN = 0x28, 0x29
DIGITS = range(0x30, 0x3A)
NUMBER_PARTS = b".E("  # a decimal point, an exponent, a bracket: still the expression
OPERATOR_TOKENS = range(0xAA, 0xB4)  # + - * / ^ AND OR > = < [Mapping the Commodore 64, $A09E token table]
LINE_HEADER = 4  # next-line pointer + line number
MAX_LINES = 10_000  # a stub is a line or two; this bounds a walk over a malformed chain


@dataclass(frozen=True)
class SysLine:
    line_number: int
    address: int
    notes: tuple[str, ...] = field(default_factory=tuple)


def sys_line(program: Program) -> SysLine:
    """The first SYS of the program's BASIC lines (module docstring); InputError naming the file."""
    source = program.source or "program"
    if program.origin != BASIC_START:
        raise InputError(f"{source}: loads at ${program.origin:04X}, not at BASIC's ${BASIC_START:04X}: there is no "
                         f"BASIC SYS line to start from; give the start address with --entry")
    code = program.code
    at, skipped = 0, []
    for _ in range(MAX_LINES):
        if at + 2 > len(code):
            break
        link = code[at] | code[at + 1] << 8
        if link == 0 or at + LINE_HEADER > len(code):
            break
        number = code[at + 2] | code[at + 3] << 8
        end = code.find(0, at + LINE_HEADER)
        if end < 0:
            raise InputError(f"{source}: BASIC line {number} has no end byte ($00)")
        found = _sys_in(code[at + LINE_HEADER:end], number, source)
        if found is not None:
            address, before = found
            if before:
                skipped.append(f"line {number}")
            address, trailing = address
            notes = ((f"BASIC statements before the SYS ({', '.join(skipped)}) are not run: retro has no "
                      f"BASIC interpreter",) if skipped else ())
            if trailing:
                notes += (f"line {number}: the text after SYS {address} ({trailing!r}) ends BASIC's expression "
                          f"(it holds no operator token) and is not run",)
            return SysLine(number, address, notes)
        skipped.append(f"line {number}")
        following = link - BASIC_START
        if following <= at or following > len(code):
            raise InputError(f"{source}: BASIC line {number}'s link ${link:04X} does not point at a later line")
        at = following
    raise InputError(f"{source}: no BASIC line with a SYS (token $9E) to start from; give the start address "
                     f"with --entry")


def _sys_in(text: bytes, number: int, source: str) -> tuple[int, bool] | None:
    """(SYS address, whether statements come before it) of one line's text, or None without a SYS."""
    quoted = False
    for i, byte in enumerate(text):
        if byte == QUOTE:
            quoted = not quoted
        elif quoted:
            continue
        elif byte == TOKEN_REM:
            return None
        elif byte == TOKEN_SYS:
            before = any(b not in (SPACE, COLON) for b in text[:i])
            return _number_after(text[i + 1:], number, source), before
    return None


def _number_after(rest: bytes, number: int, source: str) -> tuple[int, str]:
    digits = ""
    i = 0
    while i < len(rest) and rest[i] in (SPACE, OPEN_PAREN):
        i += 1
    parenthesised = OPEN_PAREN in rest[:i]
    while i < len(rest) and (rest[i] in DIGITS or rest[i] == SPACE):
        if rest[i] != SPACE:
            digits += chr(rest[i])
        i += 1
    while i < len(rest) and rest[i] in (SPACE, CLOSE_PAREN) and parenthesised:
        i += 1
    trailing = ""
    if digits and i < len(rest) and rest[i] != COLON and rest[i] not in OPERATOR_TOKENS \
            and rest[i] not in NUMBER_PARTS:
        trailing = rest[i:].decode("latin-1")
        i = len(rest)
    if not digits or (i < len(rest) and rest[i] != COLON):
        raise InputError(f"{source}: BASIC line {number}: the SYS is not followed by a plain number retro can "
                         f"read (no BASIC interpreter); give the start address with --entry")
    address = int(digits)
    if address > 0xFFFF:
        raise InputError(f"{source}: BASIC line {number}: SYS {address} is not an address (0-65535)")
    return address, trailing
